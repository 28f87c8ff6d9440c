//! MoveIt's SRDF: the link pairs its setup assistant found never (or always) in collision, which the
//! checks skip (`<disable_collisions link1="…" link2="…" reason="…"/>`).

use crate::error::Error;
use std::path::Path;

/// The disabled pairs of an SRDF file, by link name. Errors name the file and the element.
pub fn disabled_pairs(path: &Path) -> Result<Vec<(String, String)>, Error> {
    let fail = |m: String| Error::flag("--srdf", format!("{}: {m}", path.display()));
    let text = std::fs::read_to_string(path).map_err(|e| fail(format!("cannot read: {e}")))?;
    let doc = roxmltree::Document::parse(&text).map_err(|e| fail(e.to_string()))?;
    let mut out = Vec::new();
    for node in doc.descendants().filter(|n| n.has_tag_name("disable_collisions")) {
        let line = doc.text_pos_at(node.range().start).row;
        let (Some(a), Some(b)) = (node.attribute("link1"), node.attribute("link2")) else {
            return Err(fail(format!("line {line}: <disable_collisions> needs link1 and link2")));
        };
        out.push((a.to_string(), b.to_string()));
    }
    Ok(out)
}

/// The SRDF beside a URDF: the same name with `.srdf`, or in a sibling `srdf/` folder (as
/// example-robot-data and ROS packages keep it).
pub fn beside(urdf: &Path) -> Option<std::path::PathBuf> {
    let stem = urdf.file_stem()?;
    let dir = urdf.parent()?;
    let name = Path::new(stem).with_extension("srdf");
    [dir.join(&name), dir.join("..").join("srdf").join(&name)].into_iter().find(|p| p.is_file())
}

/// What MoveIt's setup assistant computes for a robot without an SRDF: the active pairs that never
/// touch over `samples` random states within the joint limits (reason "Never"), that always do
/// (reason "Always"), and the adjacent ones (reason "Adjacent"), as an SRDF. Deterministic: the
/// states come from a fixed seed.
pub fn sampled(model: &crate::model::Model, collisions: &super::Collisions, samples: usize) -> String {
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut uniform = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut contacts = vec![0usize; collisions.pairs.len()];
    let mut checker = collisions.checker(model);
    for _ in 0..samples {
        let q: Vec<f64> = model.joints.iter().map(|j| {
            let (lo, hi) = (j.lower.max(-std::f64::consts::PI), j.upper.min(std::f64::consts::PI));
            lo + (hi - lo) * uniform()
        }).collect();
        // (a band of 1 nm: touching counts as contact, and nothing farther is measured)
        for p in checker.check(&q, 1e-9).colliding() {
            if let super::Against::Link(b) = p.b && let Some(i) = collisions.pairs.iter().position(|&x| x == (p.a, b)) {
                contacts[i] += 1;
            }
        }
    }
    let mut out = format!("<?xml version=\"1.0\"?>\n<!-- Written by armscope model (srdf-out): {samples} random states within the limits -->\n<robot name=\"{}\">\n", model.name);
    for (&(a, b), &n) in collisions.pairs.iter().zip(&contacts) {
        let reason = match n {
            0 => "Never",
            n if n == samples => "Always",
            _ => continue,
        };
        out += &format!("  <disable_collisions link1=\"{}\" link2=\"{}\" reason=\"{reason}\"/>\n", model.frames[a].name, model.frames[b].name);
    }
    // the pairs the checks skip as adjacent, said as MoveIt says them
    let shapes = &collisions.shapes;
    for a in 0..model.frames.len() {
        for b in a + 1..model.frames.len() {
            let (fa, fb) = (&model.frames[a], &model.frames[b]);
            if shapes.has_shapes(a) && shapes.has_shapes(b) && super::pairs::joined(model, fa.body, fb.body) {
                out += &format!("  <disable_collisions link1=\"{}\" link2=\"{}\" reason=\"Adjacent\"/>\n", fa.name, fb.name);
            }
        }
    }
    out + "</robot>\n"
}
