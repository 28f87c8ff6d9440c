//! A floor under one point of the arm: a stiff, damped, frictionless one-sided contact. A real
//! follower whose leader asks its gripper into the table rests on the table; without the contact
//! the simulated arm reaches into it, and its joints end tens of mrad from the real ones.
//!
//! The contact pushes up along the floor's normal with f = K·d − C·ḋ at a depth d below the floor,
//! taken implicitly at the step's end (d₁ = d₀ − h·J_z·v₁), so that it adds h·(C + h·K)·J_zᵀJ_z to
//! the step's M + hD and h·K·d₀·J_zᵀ to its right-hand side: stable at any stiffness, solved with
//! the step's joint laws (limits, friction) in the same solve. A step whose contact would pull is
//! solved without it. Its work is booked with the friction's for the energy audit.

use super::stick_slip::{JointLaw, NotPositiveDefinite, StickSlipSolver};
use crate::dynamics::{Data, frame_pose, frame_vertical_jacobian};
use crate::model::Model;

/// Where the floor is: a frame whose origin rests on it at `height` (world z, m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloorContact {
    pub frame: usize,
    pub height: f64,
}

/// The floor's stiffness, N/m: not identified (the episodes show where the tool rests, not how far
/// it sinks); stiff enough that the 25 N a desktop arm's servos press with sink it half a
/// millimetre, about the encoder's resolution at the tool (2π/4096 over 0.3 m: 0.46 mm).
pub const STIFFNESS: f64 = 5e4;
/// Its damping, N·s/m: about critical for the half kilogram a desktop arm's tool weighs along the
/// normal (2·√(K·m) = 316), so that the tool lands without bouncing.
pub const DAMPING: f64 = 300.0;
/// A speed no arm's point reaches, m/s: a point farther above the floor than this for a step's
/// length cannot reach it within the step, and its Jacobian is not needed.
const FASTEST_POINT: f64 = 50.0;

/// The contact and its buffers (sized once: no allocation within a step).
pub struct FloorSolve {
    pub contact: FloorContact,
    /// The point's world-vertical velocity per coordinate (its Jacobian's z row).
    normal: Vec<f64>,
    /// M with the contact's h·(C + h·K)·JᵀJ, by columns as M is.
    pressed: Vec<f64>,
    rhs: Vec<f64>,
    v_pressed: Vec<f64>,
    residual: Vec<f64>,
    /// The contact's work over the last step, J.
    pub work: f64,
}

impl FloorSolve {
    pub fn new(contact: FloorContact, dof: usize) -> Self {
        Self {
            contact,
            normal: vec![0.0; dof],
            pressed: vec![0.0; dof * dof],
            rhs: vec![0.0; dof],
            v_pressed: vec![0.0; dof],
            residual: vec![0.0; dof],
            work: 0.0,
        }
    }

    /// After the step's solve of (M + hD)·v₁ = rhs under `laws` gave `v_next` (and `residual`)
    /// from `v`: if the point ends the step below the floor, the step solved again with the
    /// contact, and `v_next` and `residual` replaced by that solution where the contact pushes.
    /// `data` holds the step's start kinematics.
    #[allow(clippy::too_many_arguments)]
    pub fn impose(&mut self, model: &Model, data: &Data, h: f64, v: &[f64], solver: &mut StickSlipSolver, mass: &[f64], damping: &[f64], rhs: &[f64], laws: &[JointLaw], v_next: &mut [f64], residual: &mut [f64]) -> Result<(), NotPositiveDefinite> {
        self.work = 0.0;
        let point = frame_pose(model, data, self.contact.frame).translation;
        let height = point.z;
        if height - self.contact.height > FASTEST_POINT * h {
            return Ok(());
        }
        frame_vertical_jacobian(model, data, self.contact.frame, &point, &mut self.normal);
        let speed = |x: &[f64], normal: &[f64]| normal.iter().zip(x).map(|(n, x)| n * x).sum::<f64>();
        let depth = self.contact.height - height;
        if depth - h * speed(v_next, &self.normal) <= 0.0 {
            // above the floor at the step's end without it
            return Ok(());
        }
        let n = self.normal.len();
        let coupling = h * (DAMPING + h * STIFFNESS);
        for (i, column) in self.pressed.chunks_exact_mut(n).enumerate() {
            for (j, entry) in column.iter_mut().enumerate() {
                *entry = mass[i * n + j] + coupling * self.normal[i] * self.normal[j];
            }
        }
        let push = h * STIFFNESS * depth;
        for ((r, base), normal) in self.rhs.iter_mut().zip(rhs).zip(&self.normal) {
            *r = base + push * normal;
        }
        solver.solve(&self.pressed, damping, &self.rhs, laws, &mut self.v_pressed, &mut self.residual)?;
        let normal_speed = speed(&self.v_pressed, &self.normal);
        let force = STIFFNESS * (depth - h * normal_speed) - DAMPING * normal_speed;
        if force <= 0.0 {
            // it would pull the point down: leaving the floor this step (solved again without it,
            // so that the solver's limits are those of the step taken)
            return solver.solve(mass, damping, rhs, laws, v_next, residual);
        }
        v_next.copy_from_slice(&self.v_pressed);
        residual.copy_from_slice(&self.residual);
        // at the step's mean normal speed, as the audit books the torques
        self.work = h * force * 0.5 * (speed(v, &self.normal) + normal_speed);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::{DAMPING, FloorContact, STIFFNESS};
    use crate::dynamics::{Data, forward_kinematics, frame_pose, gravity_and_bias_from_kinematics};
    use crate::plant::{DiscretePlant, Plant};

    /// A half-kilogram block on a vertical slider, dropped 1 cm onto a floor, comes to rest sunk by
    /// its weight over the floor's stiffness, m·g/K = 98.1 µm: at rest the implicit contact's force
    /// is K·d exactly, so the block's height is the floor's less m·g/K to the solve's round-off.
    /// Damped about critically (C = 300 against 2·√(K·m) = 316 N·s/m), it is at rest within a second.
    /// Landing at √(2·g·1 cm) = 0.44 m/s it sinks deeper first, but no deeper than the continuous
    /// spring–damper would (its peak for that speed and damping ratio, 0.53 mm, plus the resting
    /// depth): the implicit step adds no energy on impact.
    #[test]
    fn a_block_resting_on_the_floor_sinks_by_its_weight_over_the_stiffness() {
        let mass = 0.5;
        let urdf = format!(
            r#"<robot name="slider"><link name="base"/><link name="block"><inertial><mass value="{mass}"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
            <joint name="lift" type="prismatic"><parent link="base"/><child link="block"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="100" velocity="10"/></joint></robot>"#
        );
        let model = crate::model::load_urdf_str(&urdf, std::path::Path::new("slider.urdf")).unwrap();
        let block = model.frame_index("block").unwrap();
        let floor = -0.01;
        let h = 1e-3;
        let mut plant = DiscretePlant::new(&model, h, 1).with_floor(FloorContact { frame: block, height: floor }, model.dof());
        let mut data = Data::new(&model);
        let (mut q, mut v) = (vec![0.0], vec![0.0]);
        let weight = mass * -model.gravity.z;
        let resting = floor - weight / STIFFNESS;
        let mut lowest = f64::INFINITY;
        for _ in 0..2000 {
            forward_kinematics(&model, &mut data, &q);
            gravity_and_bias_from_kinematics(&model, &mut data, &v);
            lowest = lowest.min(frame_pose(&model, &data, block).translation.z);
            plant.advance(&model, &mut data, &[0.0], &mut q, &mut v);
        }
        forward_kinematics(&model, &mut data, &q);
        let height = frame_pose(&model, &data, block).translation.z;
        assert!((height - resting).abs() < 1e-9, "at rest at {height} m, m·g/K puts it at {resting} m");
        assert!(v[0].abs() < 1e-9, "at rest: {} m/s", v[0]);
        let (omega, zeta) = ((STIFFNESS / mass).sqrt(), DAMPING / (2.0 * (STIFFNESS * mass).sqrt()));
        let landing_speed = (2.0 * weight / mass * (0.0 - floor)).sqrt();
        let spread = (1.0 - zeta * zeta).sqrt();
        let peak = landing_speed / omega * (-zeta / spread * (spread / zeta).atan()).exp() + weight / STIFFNESS;
        let landed = floor - lowest;
        assert!(landed > weight / STIFFNESS && landed <= peak, "landed {} µm deep: between the resting {} µm and the continuous contact's peak {} µm", landed * 1e6, weight / STIFFNESS * 1e6, peak * 1e6);
    }
}
