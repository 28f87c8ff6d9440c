//! Which link pairs the checks look at: every pair of links with shapes, except links on the same
//! body (welded by fixed joints), adjacent ones (the two bodies a joint connects; a root body and the
//! world's links), and the pairs an SRDF disables.

use super::CollisionModel;
use crate::model::Model;

/// Whether bodies `a` and `b` (None: the world) are two bodies one joint connects.
pub fn joined(model: &Model, a: Option<usize>, b: Option<usize>) -> bool {
    let parent_body = |body: Option<usize>| body.and_then(|x| model.bodies[x].parent);
    a != b && ((a.is_some() && parent_body(a) == b) || (b.is_some() && parent_body(b) == a))
}

/// The active pairs of links (frame indices, the smaller first), and the names in `disabled` that
/// are no link of the model (for a notice).
pub fn active_pairs(model: &Model, shapes: &CollisionModel, disabled: &[(String, String)]) -> (Vec<(usize, usize)>, Vec<String>) {
    let adjacent = |a: Option<usize>, b: Option<usize>| a == b || joined(model, a, b);
    let unknown: Vec<String> = disabled.iter().flat_map(|(a, b)| [a, b]).filter(|n| model.frame_index(n).is_none()).cloned().collect();
    let is_disabled = |a: &str, b: &str| disabled.iter().any(|(x, y)| (x == a && y == b) || (x == b && y == a));
    let mut out = Vec::new();
    for a in 0..model.frames.len() {
        for b in a + 1..model.frames.len() {
            let (fa, fb) = (&model.frames[a], &model.frames[b]);
            if !shapes.has_shapes(a) || !shapes.has_shapes(b) || adjacent(fa.body, fb.body) || is_disabled(&fa.name, &fb.name) {
                continue;
            }
            out.push((a, b));
        }
    }
    (out, unknown)
}
