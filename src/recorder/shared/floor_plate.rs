//! The floors both outputs draw, each a thin square plate about the world's z axis with its top at
//! the floor's height: a collision scene's floor, and the table a motor file's `[floor]` puts under
//! the tool.

use crate::collision::WorldShape;
use crate::model::Geometry;
use crate::spatial::Pose;

/// A collision scene's floor, m: wider than any arm armscope draws.
const SCENE_FLOOR_SIDE: f64 = 2.0;

/// A motor file's floor, m: a desk under a desktop arm.
pub const TABLE_SIDE: f64 = 0.8;

/// A motor file's floor's colour, RGBA: a light grey, half transparent (the tool shows through).
pub const TABLE_RGBA: [u8; 4] = [150, 150, 150, 120];

/// The plate's thickness, m: thin enough to read as a surface, thick enough to be drawn.
const THICKNESS: f64 = 0.002;

/// What the recordings draw of a collision scene's shape, in the world: an object's own geometry at
/// its pose, the floor (a half-space) a plate at its height.
pub fn drawn(shape: &WorldShape) -> (Geometry, Pose) {
    match &shape.drawn {
        Some((geometry, pose)) => (geometry.clone(), *pose),
        None => floor_plate(shape.pose.translation.z, SCENE_FLOOR_SIDE),
    }
}

/// A plate `side` m wide, its top at `height`.
pub fn floor_plate(height: f64, side: f64) -> (Geometry, Pose) {
    (Geometry::Box { size: [side, side, THICKNESS] }, Pose::new(nalgebra::Matrix3::identity(), nalgebra::Vector3::new(0.0, 0.0, height - THICKNESS / 2.0)))
}
