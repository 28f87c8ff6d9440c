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
