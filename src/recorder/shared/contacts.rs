//! What the recordings show of the collision checks: which links and world shapes are in contact,
//! step by step, and when that changes (both recorders highlight on the changes only).

use crate::collision::{Against, Collisions, PairDistance};
use crate::model::Model;

/// Something that can be in contact: a link (frame index) or a world shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Body {
    Link(usize),
    World(usize),
}

/// Tracks what is in contact from one sample to the next.
pub struct ContactTracker {
    links: Vec<bool>,
    world: Vec<bool>,
    /// The pairs in contact at the last sample, sorted.
    pairs: Vec<(usize, Against)>,
    now_links: Vec<bool>,
    now_world: Vec<bool>,
    now_pairs: Vec<(usize, Against)>,
    /// The bodies whose contact changed at the last update, and whether they are in contact now.
    pub changed: Vec<(Body, bool)>,
    /// The pairs that came into contact and out of it at the last update.
    pub began: Vec<(usize, Against)>,
    pub ended: Vec<(usize, Against)>,
}

impl ContactTracker {
    pub fn new(model: &Model, collisions: &Collisions) -> Self {
        let (f, w) = (model.frames.len(), collisions.world.len());
        Self { links: vec![false; f], world: vec![false; w], pairs: Vec::new(), now_links: vec![false; f], now_world: vec![false; w], now_pairs: Vec::new(), changed: Vec::new(), began: Vec::new(), ended: Vec::new() }
    }

    /// Reads one sample's close pairs; true when anything changed (see `changed`, `began`, `ended`).
    pub fn update(&mut self, close: &[PairDistance]) -> bool {
        self.now_links.fill(false);
        self.now_world.fill(false);
        self.now_pairs.clear();
        for p in close.iter().filter(|p| p.distance <= 0.0) {
            self.now_links[p.a] = true;
            match p.b {
                Against::Link(b) => self.now_links[b] = true,
                Against::World(w) => self.now_world[w] = true,
            }
            self.now_pairs.push((p.a, p.b));
        }
        self.now_pairs.sort_by_key(|&(a, b)| (a, key(b)));
        self.changed.clear();
        self.began.clear();
        self.ended.clear();
        if self.now_pairs == self.pairs {
            return false;
        }
        for (f, (was, now)) in self.links.iter_mut().zip(&self.now_links).enumerate() {
            if *was != *now {
                self.changed.push((Body::Link(f), *now));
                *was = *now;
            }
        }
        for (w, (was, now)) in self.world.iter_mut().zip(&self.now_world).enumerate() {
            if *was != *now {
                self.changed.push((Body::World(w), *now));
                *was = *now;
            }
        }
        self.began.extend(self.now_pairs.iter().filter(|p| !self.pairs.contains(p)));
        self.ended.extend(self.pairs.iter().filter(|p| !self.now_pairs.contains(p)));
        std::mem::swap(&mut self.pairs, &mut self.now_pairs);
        true
    }

    /// The pairs in contact now.
    pub fn pairs(&self) -> &[(usize, Against)] {
        &self.pairs
    }
}

fn key(b: Against) -> (u8, usize) {
    match b {
        Against::Link(f) => (0, f),
        Against::World(w) => (1, w),
    }
}

/// "link — other" for a pair.
pub fn pair_name(model: &Model, collisions: &Collisions, (a, b): (usize, Against)) -> String {
    format!("{} — {}", model.frames[a].name, collisions.name(model, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn changes_are_reported_once_each() {
        let model = crate::model::load_urdf(std::path::Path::new(crate::builtin::DEFAULT_URDF)).unwrap();
        let scene = crate::collision::Scene { floor: Some(0.0), ..Default::default() };
        let c = Collisions::new(&model, None, &scene).unwrap();
        let mut t = ContactTracker::new(&model, &c);
        let touch = PairDistance { a: 3, b: Against::World(0), distance: -0.01 };
        let near = PairDistance { a: 3, b: Against::World(0), distance: 0.01 };
        assert!(!t.update(&[near]), "a near miss is no contact");
        assert!(t.update(&[touch]));
        assert_eq!(t.changed, vec![(Body::Link(3), true), (Body::World(0), true)]);
        assert_eq!(t.began, vec![(3, Against::World(0))]);
        assert!(!t.update(&[touch]), "still in contact: no change");
        assert!(t.update(&[]));
        assert_eq!(t.changed, vec![(Body::Link(3), false), (Body::World(0), false)]);
        assert_eq!(t.ended, vec![(3, Against::World(0))]);
    }
}
