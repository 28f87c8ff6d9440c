//! The world around the arm (`--scene FILE`): fixed boxes, cylinders, spheres, capsules and meshes in
//! the world frame — a table, a wall, a fixture — a floor, and the shape of the payload the tool
//! holds. TOML:
//!
//! ```toml
//! floor = 0.0                       # optional: a floor at this height (world z, m)
//!
//! [[object]]                        # any number of them
//! name = "table"
//! shape = "box"                     # box | cylinder | sphere | capsule | mesh
//! size = [0.6, 1.0, 0.04]           # box: full extents, m
//! xyz = [0.45, 0.0, -0.02]          # pose in the world frame, m and rad (URDF's rpy)
//! rpy = [0.0, 0.0, 0.0]
//!
//! [payload]                         # the payload's shape (its mass is --payload)
//! shape = "sphere"
//! radius = 0.03
//! xyz = [0.0, 0.0, 0.03]            # in the tool frame
//! ```
//!
//! Cylinders and capsules take `radius` and `length` (along their z axis, as in URDF), spheres
//! `radius`, meshes `file` (STL or OBJ, relative to the scene file) and an optional `scale`.

use crate::error::Error;
use crate::model::Geometry;
use crate::spatial::Pose;
use std::path::{Path, PathBuf};
use toml::Value;

/// A fixed shape of the scene.
#[derive(Clone, Debug)]
pub struct SceneObject {
    pub name: String,
    pub geometry: Geometry,
    /// In the world frame.
    pub pose: Pose,
}

/// A scene: its file, objects, floor and payload shape.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub source: Option<PathBuf>,
    pub objects: Vec<SceneObject>,
    /// A floor at this height (world z, m).
    pub floor: Option<f64>,
    /// The payload's shape and its pose in the tool frame.
    pub payload: Option<(Geometry, Pose)>,
}

const SHAPE_FIELDS: &[&str] = &["shape", "size", "radius", "length", "file", "scale", "xyz", "rpy"];

impl Scene {
    /// The scene of file `path`; every error is one line naming the file and the field.
    pub fn load(path: &Path) -> Result<Self, Error> {
        let text = std::fs::read_to_string(path).map_err(|e| fail(path, format!("cannot read: {e}")))?;
        Self::parse(&text, path)
    }

    /// The scene of `--scene FILE` if given (else an empty one) with `--floor Z` if given, which
    /// replaces the file's floor (said in the notice returned).
    pub fn from_flags(file: Option<&Path>, floor: Option<f64>) -> Result<(Self, Option<String>), Error> {
        let mut scene = match file {
            Some(path) => Self::load(path)?,
            None => Self::default(),
        };
        let notice = match (floor, scene.floor) {
            (Some(z), Some(own)) if z != own => Some(format!("--floor {z} m replaces the floor of the scene ({own} m)")),
            _ => None,
        };
        scene.floor = floor.or(scene.floor);
        Ok((scene, notice))
    }

    /// The scene in `text`, read from `path` (mesh files are found relative to it).
    pub fn parse(text: &str, path: &Path) -> Result<Self, Error> {
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| fail(path, one_line(&e)))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let mut scene = Scene { source: Some(path.to_path_buf()), ..Default::default() };
        for (key, value) in &table {
            match key.as_str() {
                "floor" => {
                    let z = value.as_float().or_else(|| value.as_integer().map(|i| i as f64)).filter(|z| z.is_finite());
                    scene.floor = Some(z.ok_or_else(|| fail(path, "field 'floor': must be a height in m (a number)".into()))?);
                }
                "object" => {
                    let Value::Array(objects) = value else { return Err(fail(path, "'object' must be a list of tables ([[object]])".into())) };
                    for (i, o) in objects.iter().enumerate() {
                        let Value::Table(t) = o else { return Err(fail(path, format!("object {}: expected a table", i + 1))) };
                        let name = match t.get("name") {
                            Some(Value::String(s)) if !s.is_empty() => s.clone(),
                            Some(_) => return Err(fail(path, format!("object {}: field 'name': must be a non-empty string", i + 1))),
                            None => return Err(fail(path, format!("object {}: field 'name' is missing", i + 1))),
                        };
                        if scene.objects.iter().any(|o| o.name == name) || name == "floor" {
                            return Err(fail(path, format!("object '{name}': field 'name': used twice (or 'floor', which names the floor)")));
                        }
                        let what = format!("object '{name}'");
                        let fields = Fields { file: path, what: &what, table: t };
                        fields.known(&[SHAPE_FIELDS, &["name"]].concat())?;
                        scene.objects.push(SceneObject { geometry: fields.geometry(dir)?, pose: fields.pose()?, name });
                    }
                }
                "payload" => {
                    let Value::Table(t) = value else { return Err(fail(path, "'payload' must be a table ([payload])".into())) };
                    let fields = Fields { file: path, what: "payload", table: t };
                    fields.known(SHAPE_FIELDS)?;
                    scene.payload = Some((fields.geometry(dir)?, fields.pose()?));
                }
                other => return Err(fail(path, format!("unknown field '{other}' (floor, object, payload are read)"))),
            }
        }
        Ok(scene)
    }
}

fn fail(file: &Path, message: String) -> Error {
    Error::flag("--scene", format!("{}: {message}", file.display()))
}

/// toml's message on one line (it spans several: the message, then the source line it points at).
fn one_line(e: &toml::de::Error) -> String {
    let at = e.span().map_or(String::new(), |s| format!(" (at byte {})", s.start));
    format!("{}{at}", e.message().trim().replace('\n', " "))
}

struct Fields<'a> {
    file: &'a Path,
    what: &'a str,
    table: &'a toml::Table,
}

impl Fields<'_> {
    fn err(&self, field: &str, message: &str) -> Error {
        fail(self.file, format!("{}: field '{field}': {message}", self.what))
    }

    fn known(&self, fields: &[&str]) -> Result<(), Error> {
        match self.table.keys().find(|k| !fields.contains(&k.as_str())) {
            Some(k) => Err(self.err(k, &format!("unknown (known: {})", fields.join(", ")))),
            None => Ok(()),
        }
    }

    fn number(value: &Value) -> Option<f64> {
        value.as_float().or_else(|| value.as_integer().map(|i| i as f64)).filter(|x| x.is_finite())
    }

    fn positive(&self, field: &str) -> Result<f64, Error> {
        match self.table.get(field) {
            None => Err(self.err(field, "is missing")),
            Some(v) => Self::number(v).filter(|x| *x > 0.0).ok_or_else(|| self.err(field, "must be a positive number (m)")),
        }
    }

    fn triple(&self, field: &str, default: [f64; 3], positive: bool) -> Result<[f64; 3], Error> {
        let Some(v) = self.table.get(field) else { return Ok(default) };
        let what = if positive { "must be three positive numbers" } else { "must be three numbers" };
        let Value::Array(a) = v else { return Err(self.err(field, what)) };
        let xs: Vec<f64> = a.iter().filter_map(Self::number).filter(|x| !positive || *x > 0.0).collect();
        if a.len() != 3 || xs.len() != 3 {
            return Err(self.err(field, what));
        }
        Ok([xs[0], xs[1], xs[2]])
    }

    fn pose(&self) -> Result<Pose, Error> {
        Ok(Pose::from_xyz_rpy(self.triple("xyz", [0.0; 3], false)?, self.triple("rpy", [0.0; 3], false)?))
    }

    fn geometry(&self, dir: &Path) -> Result<Geometry, Error> {
        let shape = match self.table.get("shape") {
            Some(Value::String(s)) => s.as_str(),
            Some(_) => return Err(self.err("shape", "must be a string: box, cylinder, sphere, capsule or mesh")),
            None => return Err(self.err("shape", "is missing (box, cylinder, sphere, capsule or mesh)")),
        };
        let used: &[&str] = match shape {
            "box" => &["size"],
            "cylinder" | "capsule" => &["radius", "length"],
            "sphere" => &["radius"],
            "mesh" => &["file", "scale"],
            other => return Err(self.err("shape", &format!("'{other}' is no shape (box, cylinder, sphere, capsule or mesh)"))),
        };
        if let Some(k) = ["size", "radius", "length", "file", "scale"].into_iter().find(|k| self.table.contains_key(*k) && !used.contains(k)) {
            return Err(self.err(k, &format!("is not a field of a {shape} ({})", used.join(", "))));
        }
        Ok(match shape {
            "box" => {
                if !self.table.contains_key("size") {
                    return Err(self.err("size", "is missing (three full extents, m)"));
                }
                Geometry::Box { size: self.triple("size", [0.0; 3], true)? }
            }
            "cylinder" => Geometry::Cylinder { radius: self.positive("radius")?, length: self.positive("length")? },
            "capsule" => Geometry::Capsule { radius: self.positive("radius")?, length: self.positive("length")? },
            "sphere" => Geometry::Sphere { radius: self.positive("radius")? },
            _ => {
                let file = match self.table.get("file") {
                    Some(Value::String(s)) => dir.join(s),
                    Some(_) => return Err(self.err("file", "must be a path (a string)")),
                    None => return Err(self.err("file", "is missing (an STL or OBJ file)")),
                };
                if !file.is_file() {
                    return Err(self.err("file", &format!("{} does not exist", file.display())));
                }
                Geometry::Mesh { path: file, scale: self.triple("scale", [1.0; 3], true)? }
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(text: &str) -> String {
        Scene::parse(text, Path::new("scene.toml")).unwrap_err().to_string()
    }

    #[test]
    fn a_table_a_floor_and_a_payload_are_read() {
        let s = Scene::parse("floor = -0.1\n[[object]]\nname = \"table\"\nshape = \"box\"\nsize = [0.6, 1, 0.04]\nxyz = [0.4, 0, -0.02]\n[payload]\nshape = \"sphere\"\nradius = 0.03\n", Path::new("s.toml")).unwrap();
        assert_eq!(s.floor, Some(-0.1));
        assert_eq!(s.objects.len(), 1);
        assert!(matches!(s.objects[0].geometry, Geometry::Box { size } if size == [0.6, 1.0, 0.04]));
        assert_eq!(s.objects[0].pose.translation, nalgebra::Vector3::new(0.4, 0.0, -0.02));
        assert!(matches!(s.payload, Some((Geometry::Sphere { radius }, _)) if radius == 0.03));
    }

    #[test]
    fn bad_scenes_get_one_line_naming_file_and_field() {
        for (text, says) in [
            ("[[object]]\nshape = \"box\"\nsize = [1, 1, 1]\n", "object 1: field 'name' is missing"),
            ("[[object]]\nname = \"t\"\nshape = \"cube\"\n", "object 't': field 'shape': 'cube' is no shape"),
            ("[[object]]\nname = \"t\"\nshape = \"box\"\nsize = [1, -1, 1]\n", "object 't': field 'size': must be three positive numbers"),
            ("[[object]]\nname = \"t\"\nshape = \"box\"\n", "object 't': field 'size': is missing"),
            ("[[object]]\nname = \"t\"\nshape = \"sphere\"\nradius = 0.1\nsize = [1, 1, 1]\n", "object 't': field 'size': is not a field of a sphere"),
            ("[[object]]\nname = \"t\"\nshape = \"box\"\nsize = [1, 1, 1]\ncolour = 3\n", "object 't': field 'colour': unknown"),
            ("[[object]]\nname = \"t\"\nshape = \"mesh\"\nfile = \"nowhere.stl\"\n", "object 't': field 'file': nowhere.stl does not exist"),
            ("[[object]]\nname = \"t\"\nshape = \"box\"\nsize = [1, 1, 1]\nxyz = [0, 0]\n", "object 't': field 'xyz': must be three numbers"),
            ("[payload]\nshape = \"cylinder\"\nradius = 0.1\n", "payload: field 'length': is missing"),
            ("floor = \"low\"\n", "field 'floor'"),
            ("walls = 3\n", "unknown field 'walls'"),
            ("[[object]\n", "scene.toml"),
        ] {
            let e = error(text);
            assert!(e.starts_with("--scene: scene.toml: "), "{e}");
            assert!(e.contains(says), "{e} should say {says}");
            assert!(!e.contains('\n'), "one line: {e}");
        }
    }
}
