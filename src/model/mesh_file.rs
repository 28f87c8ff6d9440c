//! A mesh file a robot description names — STL, OBJ or COLLADA — read once into triangles in the
//! file's own frame, Z up, in metres (before the URDF's `scale`). `mesh-loader` (the loader of the
//! Rust URDF tools) parses the triangles. COLLADA's scene is placed here: each `<instance_geometry>`
//! of the visual scene under its nodes' transforms composed parent first, in the `<unit>`, turned
//! so that the `<up_axis>` is z as ROS's viewers draw it (mesh-loader 0.1 composes nested nodes
//! child first, leaves node translations out of the unit, and places a geometry instanced twice
//! once).

use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};
use std::collections::HashMap;
use std::path::Path;

/// One part of a mesh file (a placed COLLADA geometry, an OBJ object): triangles with their own
/// vertices.
#[derive(Clone, Debug, Default)]
pub struct MeshPart {
    pub vertices: Vec<[f32; 3]>,
    /// Per vertex, or empty when the file gives none.
    pub normals: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// The part's material colour (diffuse RGBA), when the file names one.
    pub colour: Option<[f32; 4]>,
}

/// The triangles of a mesh file.
#[derive(Clone, Debug, Default)]
pub struct MeshFile {
    pub parts: Vec<MeshPart>,
}

/// The formats [`read_mesh`] reads, by extension.
pub const MESH_EXTENSIONS: [&str; 3] = ["stl", "obj", "dae"];

/// Whether `path` names a COLLADA file.
pub fn is_collada(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("dae"))
}

/// Reads `path`. The error names the file and what is wrong with it.
pub fn read_mesh(path: &Path) -> Result<MeshFile, String> {
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if !MESH_EXTENSIONS.contains(&extension.as_str()) {
        return Err(format!("{}: a .{extension} mesh is not read (STL, OBJ and COLLADA are)", path.display()));
    }
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let out = if extension == "dae" {
        collada(&bytes).map_err(|e| format!("{}: {e}", path.display()))?
    } else {
        // the loader dispatches on the extension; its lower-case spelling is the one it knows
        let scene = mesh_loader::Loader::default()
            .load_from_slice(&bytes, path.with_extension(&extension))
            .map_err(|e| format!("{}: {e}", path.display()))?;
        let parts = scene
            .meshes
            .into_iter()
            .enumerate()
            .map(|(i, mesh)| {
                let colour = scene.materials.get(i).and_then(|m| m.color.diffuse);
                part(mesh, &Matrix4::identity(), colour)
            })
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{}: {e}", path.display()))?;
        MeshFile { parts }
    };
    if out.triangle_count() == 0 {
        return Err(format!("{}: no triangles", path.display()));
    }
    Ok(out)
}

impl MeshFile {
    pub fn triangle_count(&self) -> usize {
        self.parts.iter().map(|p| p.triangles.len()).sum()
    }

    /// Every part's triangles in one vertex list, scaled, with vertices at the same position
    /// merged: the surface the collision checks see (its connected parts are the ones the
    /// triangles share vertices in, which a file's per-corner vertices would hide).
    pub fn welded(&self, scale: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let mut index_of: HashMap<[u32; 3], u32> = HashMap::new();
        let (mut vertices, mut triangles) = (Vec::new(), Vec::with_capacity(self.triangle_count()));
        for part in &self.parts {
            let welded: Vec<u32> = part
                .vertices
                .iter()
                .map(|v| {
                    // -0.0 and 0.0 are one position
                    let key = v.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
                    *index_of.entry(key).or_insert_with(|| {
                        vertices.push([v[0] as f64 * scale[0], v[1] as f64 * scale[1], v[2] as f64 * scale[2]]);
                        vertices.len() as u32 - 1
                    })
                })
                .collect();
            triangles.extend(part.triangles.iter().map(|t| t.map(|v| welded[v as usize])));
        }
        (vertices, triangles)
    }
}

/// One loaded mesh placed by `placement` (a 4×4 affine map), its indices checked.
fn part(mesh: mesh_loader::Mesh, placement: &Matrix4<f64>, colour: Option<[f32; 4]>) -> Result<MeshPart, String> {
    let count = mesh.vertices.len() as u32;
    if let Some(bad) = mesh.faces.iter().find(|f| f.iter().any(|&v| v >= count)) {
        return Err(format!("geometry '{}': a triangle names vertex {} of {count}", mesh.name, bad.iter().max().unwrap_or(&0)));
    }
    let place = |v: &[f32; 3]| {
        let p = placement * Vector4::new(v[0] as f64, v[1] as f64, v[2] as f64, 1.0);
        [p.x as f32, p.y as f32, p.z as f32]
    };
    // normals turn by the inverse transpose (a non-uniform scale), then back to unit length
    let linear: Matrix3<f64> = placement.fixed_view::<3, 3>(0, 0).into_owned();
    let normal_map = linear.try_inverse().map(|m| m.transpose()).unwrap_or(linear);
    let turn = |n: &[f32; 3]| {
        let m = normal_map * Vector3::new(n[0] as f64, n[1] as f64, n[2] as f64);
        let m = m.try_normalize(0.0).unwrap_or(m);
        [m.x as f32, m.y as f32, m.z as f32]
    };
    let normals = if mesh.normals.len() == mesh.vertices.len() { mesh.normals.iter().map(turn).collect() } else { Vec::new() };
    Ok(MeshPart { vertices: mesh.vertices.iter().map(place).collect(), normals, triangles: mesh.faces, colour })
}

/// A geometry to draw: its id, where it goes, the colour its instance binds.
type Placed = (String, Matrix4<f64>, Option<[f32; 4]>);

/// A COLLADA document's placed geometries.
fn collada(bytes: &[u8]) -> Result<MeshFile, String> {
    let text = std::str::from_utf8(bytes).map_err(|e| format!("not UTF-8 text: {e}"))?;
    let doc = roxmltree::Document::parse(text).map_err(|e| format!("not COLLADA: {e}"))?;
    let root = doc.root_element();
    if root.tag_name().name() != "COLLADA" {
        return Err(format!("not COLLADA: the document is a <{}>", root.tag_name().name()));
    }
    // the geometries as they are in the file: the loader given the document without its scene
    let mut unplaced = text.to_string();
    for element in ["library_visual_scenes", "scene"] {
        cut_element(&mut unplaced, element);
    }
    let scene = mesh_loader::collada::from_slice(unplaced.as_bytes()).map_err(|e| e.to_string())?;
    let geometries: HashMap<String, mesh_loader::Mesh> = scene.meshes.into_iter().map(|m| (m.name.clone(), m)).collect();
    let asset = child(root, "asset");
    let unit: f64 = asset.and_then(|a| child(a, "unit")).and_then(|u| u.attribute("meter")).map_or(Ok(1.0), |m| m.trim().parse().map_err(|_| format!("<unit meter=\"{m}\"> is not a number")))?;
    let up = match asset.and_then(|a| child(a, "up_axis")).and_then(|u| u.text()).map(|u| u.trim().to_ascii_uppercase()).as_deref() {
        Some("Z_UP") => Matrix4::identity(),
        // a quarter turn about x brings y onto z; about y, x onto z
        Some("X_UP") => Matrix4::new(0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
        _ => Matrix4::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0),
    };
    let top = up * Matrix4::new_scaling(unit);
    let by_id: HashMap<&str, roxmltree::Node> = doc.descendants().filter_map(|n| n.attribute("id").map(|id| (id, n))).collect();
    let visual_scene = child(root, "scene")
        .and_then(|s| child(s, "instance_visual_scene"))
        .and_then(|i| i.attribute("url"))
        .and_then(|url| by_id.get(url.trim_start_matches('#')).copied())
        .or_else(|| child(root, "library_visual_scenes").and_then(|l| child(l, "visual_scene")));
    let mut placed = Vec::new();
    match visual_scene {
        Some(scene) => {
            for node in scene.children().filter(|n| n.has_tag_name("node")) {
                place_node(node, &top, &by_id, &mut placed, 0)?;
            }
        }
        // no scene: every geometry where it is
        None => placed.extend(geometries.keys().map(|id| (id.clone(), top, None))),
    }
    let mut parts = Vec::with_capacity(placed.len());
    for (id, placement, colour) in placed {
        let mesh = geometries.get(&id).cloned().ok_or_else(|| format!("an <instance_geometry> names geometry '#{id}', which is not in the file"))?;
        parts.push(part(mesh, &placement, colour)?);
    }
    Ok(MeshFile { parts })
}

/// `node`'s geometries, and its children's, under `parent` and the node's own transforms (in
/// document order, each applied after the next: COLLADA's post-multiplication).
fn place_node(node: roxmltree::Node, parent: &Matrix4<f64>, by_id: &HashMap<&str, roxmltree::Node>, placed: &mut Vec<Placed>, depth: usize) -> Result<(), String> {
    if depth > 64 {
        return Err("nodes nest deeper than 64 (an <instance_node> loop?)".into());
    }
    let mut local = Matrix4::identity();
    for element in node.children().filter(|n| n.is_element()) {
        let name = element.tag_name().name();
        let numbers = || -> Result<Vec<f64>, String> {
            element.text().unwrap_or("").split_whitespace().map(|v| v.parse::<f64>().map_err(|_| format!("node '{}': <{name}> holds '{v}', not a number", node.attribute("id").unwrap_or("?")))).collect()
        };
        let wrong = |count: usize| format!("node '{}': <{name}> needs {count} numbers", node.attribute("id").unwrap_or("?"));
        local *= match name {
            "matrix" => {
                let m = numbers()?;
                if m.len() != 16 {
                    return Err(wrong(16));
                }
                Matrix4::from_row_slice(&m)
            }
            "translate" => match numbers()?[..] {
                [x, y, z] => Matrix4::new_translation(&Vector3::new(x, y, z)),
                _ => return Err(wrong(3)),
            },
            "scale" => match numbers()?[..] {
                [x, y, z] => Matrix4::new_nonuniform_scaling(&Vector3::new(x, y, z)),
                _ => return Err(wrong(3)),
            },
            "rotate" => match numbers()?[..] {
                [x, y, z, degrees] => nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(Vector3::new(x, y, z)), degrees.to_radians()).to_homogeneous(),
                _ => return Err(wrong(4)),
            },
            "lookat" | "skew" => return Err(format!("node '{}': a <{name}> transform is not read", node.attribute("id").unwrap_or("?"))),
            _ => continue,
        };
    }
    let here = parent * local;
    for element in node.children().filter(|n| n.is_element()) {
        match element.tag_name().name() {
            "instance_geometry" => {
                let url = element.attribute("url").unwrap_or("").trim_start_matches('#');
                placed.push((url.to_string(), here, bound_colour(element, by_id)));
            }
            "node" => place_node(element, &here, by_id, placed, depth + 1)?,
            "instance_node" => {
                let url = element.attribute("url").unwrap_or("").trim_start_matches('#');
                let target = by_id.get(url).ok_or_else(|| format!("an <instance_node> names node '#{url}', which is not in the file"))?;
                place_node(*target, &here, by_id, placed, depth + 1)?;
            }
            _ => {}
        }
    }
    Ok(())
}

/// The diffuse colour of the first material an `<instance_geometry>` binds, when it is a colour
/// (not a texture).
fn bound_colour(instance: roxmltree::Node, by_id: &HashMap<&str, roxmltree::Node>) -> Option<[f32; 4]> {
    let material = instance.descendants().find(|n| n.has_tag_name("instance_material"))?;
    let material = by_id.get(material.attribute("target")?.trim_start_matches('#'))?;
    let effect = child(*material, "instance_effect")?.attribute("url")?;
    let effect = by_id.get(effect.trim_start_matches('#'))?;
    let diffuse = effect.descendants().find(|n| n.has_tag_name("diffuse"))?;
    let colour: Vec<f32> = child(diffuse, "color")?.text()?.split_whitespace().filter_map(|v| v.parse().ok()).collect();
    match colour[..] {
        [r, g, b, a] => Some([r, g, b, a]),
        [r, g, b] => Some([r, g, b, 1.0]),
        _ => None,
    }
}

/// The up axis a COLLADA file declares (`Y_UP` when it declares none, the format's default), read
/// from its `<asset>` at the head of the file; `None` when the file cannot be read.
pub fn declared_up_axis(path: &Path) -> Option<String> {
    use std::io::Read;
    let mut head = Vec::with_capacity(16 * 1024);
    std::fs::File::open(path).ok()?.take(64 * 1024).read_to_end(&mut head).ok()?;
    let text = String::from_utf8_lossy(&head);
    let asset = &text[..text.find("</asset>")?];
    let up = asset.find("<up_axis>").map(|start| asset[start + "<up_axis>".len()..].split('<').next().unwrap_or("").trim().to_ascii_uppercase());
    Some(up.unwrap_or_else(|| "Y_UP".into()))
}

fn child<'a, 'input>(node: roxmltree::Node<'a, 'input>, name: &str) -> Option<roxmltree::Node<'a, 'input>> {
    node.children().find(|n| n.has_tag_name(name))
}

/// Removes the first `<name …>…</name>` (or `<name …/>`) from `text`.
fn cut_element(text: &mut String, name: &str) {
    let open = [format!("<{name}>"), format!("<{name} "), format!("<{name}/")];
    let Some(start) = open.iter().filter_map(|o| text.find(o.as_str())).min() else { return };
    let close = format!("</{name}>");
    let tag_end = text[start..].find('>').map(|e| start + e + 1);
    let end = match tag_end {
        Some(e) if text[..e].ends_with("/>") => e,
        _ => match text[start..].find(&close) {
            Some(c) => start + c + close.len(),
            None => return,
        },
    };
    text.replace_range(start..end, "");
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A COLLADA unit square (two triangles) in the xy plane of its file, with a node transform
    /// and a unit, under `up`.
    fn square(up: &str, unit: f64, node_matrix: &str) -> String {
        format!(
            r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="u" meter="{unit}"/><up_axis>{up}</up_axis></asset>
  <library_geometries>
    <geometry id="sq" name="sq"><mesh>
      <source id="sq-pos"><float_array id="sq-pos-a" count="12">0 0 0 1 0 0 1 1 0 0 1 0</float_array>
        <technique_common><accessor source="#sq-pos-a" count="4" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
      <vertices id="sq-v"><input semantic="POSITION" source="#sq-pos"/></vertices>
      <triangles count="2"><input semantic="VERTEX" source="#sq-v" offset="0"/><p>0 1 2 0 2 3</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="Scene" name="Scene">
    <node id="n" name="n"><matrix sid="transform">{node_matrix}</matrix><instance_geometry url="#sq"/></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>"##
        )
    }

    fn read_str(text: &str) -> MeshFile {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("square.dae");
        std::fs::write(&path, text).unwrap();
        read_mesh(&path).unwrap()
    }

    const IDENTITY: &str = "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1";

    #[test]
    fn collada_square_is_welded_into_four_vertices_and_two_triangles() {
        let mesh = read_str(&square("Z_UP", 1.0, IDENTITY));
        assert_eq!(mesh.triangle_count(), 2);
        let (vertices, triangles) = mesh.welded([1.0; 3]);
        assert_eq!(vertices.len(), 4, "{vertices:?}");
        assert_eq!(triangles.len(), 2);
        assert!(vertices.contains(&[1.0, 1.0, 0.0]));
    }

    #[test]
    fn collada_unit_node_transform_and_up_axis_place_the_vertices() {
        // centimetres, shifted 2 units along the file's x, Y up: the corner (1, 1, 0) of the
        // file is 0.01 m · (1 + 2, 1, 0) in the file's frame, then y → z
        let shifted = "1 0 0 2 0 1 0 0 0 0 1 0 0 0 0 1";
        let (vertices, _) = read_str(&square("Y_UP", 0.01, shifted)).welded([1.0; 3]);
        let expect = [0.03, 0.0, 0.01];
        assert!(vertices.iter().any(|v| (0..3).all(|i| (v[i] - expect[i]).abs() < 1e-7)), "{vertices:?}");
        let (vertices, _) = read_str(&square("X_UP", 1.0, IDENTITY)).welded([2.0, 1.0, 1.0]);
        // (1, 1, 0) with x up: x → z, z → -x, then the URDF scale
        assert!(vertices.contains(&[0.0, 1.0, 1.0]), "{vertices:?}");
    }

    #[test]
    fn collada_nested_nodes_compose_parent_first_and_a_geometry_instanced_twice_is_placed_twice() {
        // parent: a quarter turn about z; child: 1 along x. Parent first puts the child's square
        // 1 along y (child first would leave it 1 along x)
        let text = square("Z_UP", 1.0, IDENTITY).replace(
            r##"<node id="n" name="n"><matrix sid="transform">1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</matrix><instance_geometry url="#sq"/></node>"##,
            r##"<node id="p"><rotate>0 0 1 90</rotate><node id="c"><translate>1 0 0</translate><instance_geometry url="#sq"/></node></node><node id="twice"><translate>0 0 5</translate><instance_geometry url="#sq"/></node>"##,
        );
        let mesh = read_str(&text);
        assert_eq!(mesh.parts.len(), 2);
        let near = |v: &[f32; 3], e: [f32; 3]| (0..3).all(|i| (v[i] - e[i]).abs() < 1e-6);
        // the square's corner (1, 0, 0): turned to (0, 1, 0) after the child's shift to (2, 0, 0) → (0, 2, 0)
        assert!(mesh.parts[0].vertices.iter().any(|v| near(v, [0.0, 2.0, 0.0])), "{:?}", mesh.parts[0].vertices);
        assert!(mesh.parts[1].vertices.iter().all(|v| v[2] == 5.0), "{:?}", mesh.parts[1].vertices);
    }

    #[test]
    fn a_mesh_in_an_unread_format_or_with_nothing_in_it_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let ply = dir.path().join("part.ply");
        std::fs::write(&ply, "ply\n").unwrap();
        let e = read_mesh(&ply).unwrap_err();
        assert!(e.contains("part.ply") && e.contains(".ply mesh is not read"), "{e}");
        let empty = dir.path().join("empty.stl");
        std::fs::write(&empty, "solid empty\nendsolid empty\n").unwrap();
        let e = read_mesh(&empty).unwrap_err();
        assert!(e.contains("empty.stl"), "{e}");
        let broken = dir.path().join("broken.dae");
        std::fs::write(&broken, "<COLLADA><library_geometries>").unwrap();
        let e = read_mesh(&broken).unwrap_err();
        assert!(e.contains("broken.dae"), "{e}");
    }
}
