//! The collision checks in the `.rrd`: the scene's objects and the payload drawn in 3D, each link and
//! object turning red while in contact (only its colour is logged, at the changes), a `collisions`
//! series (pairs in contact, the smallest distance within 5 cm) and a `collisions/events` text log
//! naming the pairs as they touch and part.

use super::contacts::{Body, ContactTracker, pair_name};
use crate::collision::Collisions;
use crate::model::{Geometry, Model};
use crate::spatial::Pose;
use rerun::{Color, RecordingStream, RecordingStreamResult};
use std::sync::Arc;

/// The colour of a link or object in contact (0xRRGGBBAA).
pub const CONTACT: Color = Color(rerun::datatypes::Rgba32(0xEB1E1EFF));
const SCENE_GREY: Color = Color(rerun::datatypes::Rgba32(0x9696A596));

/// The archetype an entity's shape was logged as (its colour component differs).
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    Boxes,
    Cylinders,
    Capsules,
    Ellipsoids,
    Asset,
    Mesh,
}

/// An entity whose colour changes with contact, and its own colour.
#[derive(Clone, Debug)]
pub struct Recolour {
    pub path: String,
    pub kind: Kind,
    pub colour: Color,
}

/// Log `geometry` at `path` (its transform logged by the caller); its colour static when given,
/// else left to temporal colour updates. Returns the archetype used.
/// A floor drawn: a thin square plate `side` m wide about the world's z axis, its top at `height`.
pub fn floor_plate(height: f64, side: f64) -> (Geometry, Pose) {
    (Geometry::Box { size: [side, side, 0.002] }, Pose::new(nalgebra::Matrix3::identity(), nalgebra::Vector3::new(0.0, 0.0, height - 0.001)))
}

pub fn log_geometry(rec: &RecordingStream, path: &str, geometry: &Geometry, colour: Option<Color>) -> Result<Kind, String> {
    // (no colour at all when none is given: an empty static batch would hide the temporal one)
    let r = |x: RecordingStreamResult<()>| x.map_err(|e| e.to_string());
    Ok(match geometry {
        Geometry::Box { size } => {
            let a = rerun::Boxes3D::from_half_sizes([[size[0] as f32 / 2.0, size[1] as f32 / 2.0, size[2] as f32 / 2.0]]).with_fill_mode(rerun::FillMode::Solid);
            r(rec.log_static(path, &match colour {
                Some(c) => a.with_colors([c]),
                None => a,
            }))?;
            Kind::Boxes
        }
        Geometry::Cylinder { radius, length } => {
            let a = rerun::Cylinders3D::from_lengths_and_radii([*length as f32], [*radius as f32]).with_fill_mode(rerun::FillMode::Solid);
            r(rec.log_static(path, &match colour {
                Some(c) => a.with_colors([c]),
                None => a,
            }))?;
            Kind::Cylinders
        }
        Geometry::Capsule { radius, length } => {
            let a = rerun::Capsules3D::from_lengths_and_radii([*length as f32], [*radius as f32]);
            r(rec.log_static(path, &match colour {
                Some(c) => a.with_colors([c]),
                None => a,
            }))?;
            Kind::Capsules
        }
        Geometry::Sphere { radius } => {
            let a = rerun::Ellipsoids3D::from_radii([*radius as f32]).with_fill_mode(rerun::FillMode::Solid);
            r(rec.log_static(path, &match colour {
                Some(c) => a.with_colors([c]),
                None => a,
            }))?;
            Kind::Ellipsoids
        }
        // Rerun reads STL and OBJ itself; COLLADA goes as the triangles read here
        Geometry::Mesh { path: file, .. } if crate::model::mesh_file::is_collada(file) => {
            let mesh = crate::model::mesh_file::read_mesh(file)?;
            r(rec.log_static(path, &match colour {
                Some(c) => mesh3d(&mesh).with_albedo_factor(c.0),
                None => mesh3d(&mesh),
            }))?;
            Kind::Mesh
        }
        Geometry::Mesh { path: file, .. } => {
            let asset = rerun::Asset3D::from_file_path(file).map_err(|e| format!("{}: {e}", file.display()))?;
            r(rec.log_static(path, &match colour {
                Some(c) => asset.with_albedo_factor(c.0),
                None => asset,
            }))?;
            Kind::Asset
        }
    })
}

/// The grey of a mesh part whose file gives it no colour.
const MESH_GREY: [f32; 4] = [0.67, 0.67, 0.7, 1.0];

/// A mesh file's parts as one Rerun mesh, each part in its material's colour; corners with the
/// same position, normal and colour are one vertex (a file's per-corner vertices would make the
/// recording larger than the file).
fn mesh3d(mesh: &crate::model::mesh_file::MeshFile) -> rerun::Mesh3D {
    let with_normals = mesh.parts.iter().all(|p| p.normals.len() == p.vertices.len());
    let (mut positions, mut normals, mut colours, mut triangles) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut index_of: std::collections::HashMap<([u32; 3], [u32; 3], u32), u32> = std::collections::HashMap::new();
    for part in &mesh.parts {
        let [r, g, b, a] = part.colour.unwrap_or(MESH_GREY).map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        let colour = Color::from_unmultiplied_rgba(r, g, b, a);
        let corner: Vec<u32> = (0..part.vertices.len())
            .map(|k| {
                let normal = if with_normals { part.normals[k] } else { [0.0; 3] };
                let key = (part.vertices[k].map(f32::to_bits), normal.map(f32::to_bits), colour.0.0);
                *index_of.entry(key).or_insert_with(|| {
                    positions.push(part.vertices[k]);
                    if with_normals {
                        normals.push(normal);
                    }
                    colours.push(colour);
                    positions.len() as u32 - 1
                })
            })
            .collect();
        triangles.extend(part.triangles.iter().map(|t| t.map(|v| corner[v as usize])));
    }
    let out = rerun::Mesh3D::new(positions).with_triangle_indices(triangles).with_vertex_colors(colours);
    if with_normals { out.with_vertex_normals(normals) } else { out }
}

fn log_colour(rec: &RecordingStream, r: &Recolour, colour: Color) -> RecordingStreamResult<()> {
    let path = r.path.as_str();
    match r.kind {
        Kind::Boxes => rec.log(path, &rerun::Boxes3D::update_fields().with_colors([colour])),
        Kind::Cylinders => rec.log(path, &rerun::Cylinders3D::update_fields().with_colors([colour])),
        Kind::Capsules => rec.log(path, &rerun::Capsules3D::update_fields().with_colors([colour])),
        Kind::Ellipsoids => rec.log(path, &rerun::Ellipsoids3D::update_fields().with_colors([colour])),
        Kind::Asset => rec.log(path, &rerun::Asset3D::update_fields().with_albedo_factor(colour.0)),
        Kind::Mesh => rec.log(path, &rerun::Mesh3D::update_fields().with_albedo_factor(colour.0)),
    }
}

/// The recorder's collision state over a run.
pub struct RrdCollisions {
    model: Arc<Model>,
    collisions: Arc<Collisions>,
    tracker: ContactTracker,
    /// Per frame and per world shape: the entities recoloured in contact.
    link_visuals: Vec<Vec<Recolour>>,
    world_visuals: Vec<Vec<Recolour>>,
    /// Per step of the block: pairs in contact, the smallest distance within 5 cm (NaN: none).
    pub count: Vec<f64>,
    pub min_distance: Vec<f64>,
    /// Colour changes and event lines of the block, with their times.
    colour_changes: Vec<(f64, Body, bool)>,
    events: Vec<(f64, String)>,
    started: bool,
}

impl RrdCollisions {
    pub fn new(model: Arc<Model>, collisions: Arc<Collisions>) -> Self {
        let tracker = ContactTracker::new(&model, &collisions);
        let (frames, world) = (model.frames.len(), collisions.world.len());
        Self { model, collisions, tracker, link_visuals: vec![Vec::new(); frames], world_visuals: vec![Vec::new(); world], count: Vec::new(), min_distance: Vec::new(), colour_changes: Vec::new(), events: Vec::new(), started: false }
    }

    /// Whether link (frame) `f` is checked: its visuals' colours are then temporal.
    pub fn checked(&self, f: usize) -> bool {
        self.collisions.shapes.has_shapes(f)
    }

    /// A visual of link `f` logged without a static colour.
    pub fn register(&mut self, f: usize, recolour: Recolour) {
        self.link_visuals[f].push(recolour);
    }

    /// The scene's objects (under `world/scene`) and the payload (under the tool's entity, `tool`)
    /// drawn, statically; their colours temporal.
    pub fn log_world(&mut self, rec: &RecordingStream, tool: &str) -> Result<(), String> {
        let transform = |pose: &Pose, scale: Option<[f64; 3]>| {
            let t = super::rrd::transform(pose);
            match scale {
                Some(s) => t.with_scale([s[0] as f32, s[1] as f32, s[2] as f32]),
                None => t,
            }
        };
        let scale_of = |g: &Geometry| if let Geometry::Mesh { scale, .. } = g { Some(*scale) } else { None };
        for (w, shape) in self.collisions.world.iter().enumerate() {
            let path = format!("world/scene/{}", shape.name);
            let (geometry, pose) = match &shape.drawn {
                Some((g, p)) => (g.clone(), *p),
                None => floor_plate(shape.pose.translation.z, 2.0),
            };
            rec.log_static(path.as_str(), &transform(&pose, scale_of(&geometry))).map_err(|e| e.to_string())?;
            let kind = log_geometry(rec, &path, &geometry, None)?;
            self.world_visuals[w].push(Recolour { path, kind, colour: SCENE_GREY });
        }
        if let Some((geometry, origin)) = self.collisions.payload.clone() {
            let path = format!("{tool}/payload");
            rec.log_static(path.as_str(), &transform(&origin, scale_of(&geometry))).map_err(|e| e.to_string())?;
            let kind = log_geometry(rec, &path, &geometry, None)?;
            self.link_visuals[self.model.tool_frame].push(Recolour { path, kind, colour: Color::from_rgb(200, 160, 60) });
        }
        Ok(())
    }

    pub fn record(&mut self, s: &crate::sample::Sample) {
        if !self.started {
            self.started = true;
            // every recoloured entity's own colour, from the first step
            for f in 0..self.link_visuals.len() {
                self.colour_changes.push((s.t, Body::Link(f), false));
            }
            for w in 0..self.world_visuals.len() {
                self.colour_changes.push((s.t, Body::World(w), false));
            }
        }
        self.count.push(s.collisions.iter().filter(|p| p.distance <= 0.0).count() as f64);
        self.min_distance.push(s.collisions.first().map_or(f64::NAN, |p| p.distance));
        if self.tracker.update(s.collisions) {
            self.colour_changes.extend(self.tracker.changed.iter().map(|&(b, now)| (s.t, b, now)));
            let (model, collisions) = (&self.model, &self.collisions);
            let deepest = |pair: (usize, crate::collision::Against)| s.collisions.iter().find(|p| (p.a, p.b) == pair).map_or(0.0, |p| -p.distance);
            for &pair in &self.tracker.began {
                self.events.push((s.t, format!("contact: {} ({:.1} mm deep)", pair_name(model, collisions, pair), 1e3 * deepest(pair))));
            }
            for &pair in &self.tracker.ended {
                self.events.push((s.t, format!("apart: {}", pair_name(model, collisions, pair))));
            }
        }
    }

    /// Send the block's colour changes and event lines (the series go with the other columns).
    pub fn flush(&mut self, rec: &RecordingStream) -> RecordingStreamResult<()> {
        for &(t, body, in_contact) in &self.colour_changes {
            rec.set_duration_secs(super::rrd::TIMELINE, t);
            let visuals = match body {
                Body::Link(f) => &self.link_visuals[f],
                Body::World(w) => &self.world_visuals[w],
            };
            for r in visuals {
                log_colour(rec, r, if in_contact { CONTACT } else { r.colour })?;
            }
        }
        for (t, line) in &self.events {
            rec.set_duration_secs(super::rrd::TIMELINE, *t);
            let level = if line.starts_with("contact") { rerun::TextLogLevel::WARN } else { rerun::TextLogLevel::INFO };
            rec.log("collisions/events", &rerun::TextLog::new(line.as_str()).with_level(level))?;
        }
        if !self.colour_changes.is_empty() || !self.events.is_empty() {
            rec.reset_time();
        }
        self.colour_changes.clear();
        self.events.clear();
        self.count.clear();
        self.min_distance.clear();
        Ok(())
    }
}
