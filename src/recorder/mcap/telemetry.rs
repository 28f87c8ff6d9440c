//! The per-step controller telemetry of the MCAP recording, as a protobuf message with an explicit
//! schema (`armscope.ControllerTelemetry`). Protobuf rather than JSON: formatting ~35 floats as
//! text and compressing the text cost more than everything else the MCAP recorder does per step;
//! binary doubles also keep every value exact. Foxglove decodes it through the schema embedded in
//! the file, so its Plot panel plots `/controller.torque[1]` as before.

use prost::Message;
use super::protobuf_schema::{Field, encode_as_protobuf, file_descriptor_set as file_descriptor_set_of};
use prost_types::field_descriptor_proto::Type;

pub const SCHEMA_NAME: &str = "armscope.ControllerTelemetry";

/// One control step, one array entry per joint in the model's joint order (the channel's
/// metadata names the joints and their torque limits).
#[derive(Clone, PartialEq, Message)]
pub struct ControllerTelemetry {
    /// Simulation time, s.
    #[prost(double, tag = "1")]
    pub time: f64,
    /// Commanded joint position, rad (or m).
    #[prost(double, repeated, tag = "2")]
    pub target: Vec<f64>,
    /// target − position.
    #[prost(double, repeated, tag = "3")]
    pub error: Vec<f64>,
    /// Applied (clipped) torque, N·m.
    #[prost(double, repeated, tag = "4")]
    pub torque: Vec<f64>,
    /// Generalized gravity force τ_g, N·m.
    #[prost(double, repeated, tag = "5")]
    pub tau_g: Vec<f64>,
    /// 1 when the controller asked for more than the limit.
    #[prost(uint32, repeated, tag = "6")]
    pub saturated: Vec<u32>,
    /// 1 when the torque flipped sign since the last step with one of the two saturated.
    #[prost(uint32, repeated, tag = "7")]
    pub chatter: Vec<u32>,
    /// Distance of the tool tip from where the command puts it, m.
    #[prost(double, tag = "8")]
    pub tool_error: f64,
    /// Tool tip position [x, y, z] in the world frame, m.
    #[prost(double, repeated, tag = "9")]
    pub tool_position: Vec<f64>,
    /// The torque the joint could get at this step, N·m: the URDF's effort, or with `--motors` what
    /// the motor gives at the joint's speed through its gearbox.
    #[prost(double, repeated, tag = "10")]
    pub torque_limit: Vec<f64>,
    /// Stepper mode: each joint's load angle, electrical degrees (0 where not a stepper; empty
    /// when no joint is driven open loop).
    #[prost(double, repeated, tag = "11")]
    pub load_angle: Vec<f64>,
    /// Stepper mode: full steps each joint has lost so far (empty when no joint is driven open loop).
    #[prost(int64, repeated, tag = "12")]
    pub lost_steps: Vec<i64>,
    /// With `--motors`: each motor's shaft speed N·q̇, rev/s (0 where no motor file entry; empty
    /// without `--motors`).
    #[prost(double, repeated, tag = "13")]
    pub motor_speed: Vec<f64>,
    /// Coulomb friction torque on each joint, N·m (empty when no joint has friction).
    #[prost(double, repeated, tag = "14")]
    pub friction: Vec<f64>,
    /// 1 where the joint is stuck, held still by its friction (empty when no joint has friction).
    #[prost(uint32, repeated, tag = "15")]
    pub stuck: Vec<u32>,
    /// Each joint's motor winding temperature, °C (NaN where its motor has no thermal data; empty
    /// when no motor of the run has).
    #[prost(double, repeated, tag = "16")]
    pub winding_temperature: Vec<f64>,
    /// Firmware mode: each servo's PWM duty, −1 … 1 (0 where not a servo; empty when no joint is
    /// driven by its servo's firmware).
    #[prost(double, repeated, tag = "17")]
    pub duty: Vec<f64>,
    /// Firmware mode: each servo motor's current, A.
    #[prost(double, repeated, tag = "18")]
    pub current: Vec<f64>,
    /// Firmware mode: the supply at each servo, V.
    #[prost(double, repeated, tag = "19")]
    pub supply: Vec<f64>,
    /// A replayed recording's measured effort per joint beside the model's torque, N·m (NaN where a
    /// joint has none; empty for a simulation).
    #[prost(double, repeated, tag = "20")]
    pub measured_effort: Vec<f64>,
    /// A forward replay's real follower: its position per joint beside the simulated one, rad (NaN
    /// where a joint has none; empty otherwise).
    #[prost(double, repeated, tag = "21")]
    pub observed_position: Vec<f64>,
}

impl ControllerTelemetry {
    /// This step's values from a sample, into the vectors sized for the run when it started (both
    /// MCAP encodings send the same message).
    pub fn fill(&mut self, s: &crate::sample::Sample, motors: Option<&crate::actuator::MotorSet>) {
        let tel = self;
        tel.time = s.t;
        tel.tool_error = s.tool_error();
        tel.tool_position.clear();
        tel.tool_position.extend_from_slice(s.tool_position.as_slice());
        for j in 0..s.q.len() {
            tel.target[j] = s.cmd[j];
            tel.error[j] = s.tracking_error(j);
            tel.torque[j] = s.u[j];
            tel.tau_g[j] = s.tau_g[j];
            tel.saturated[j] = s.saturated[j] as u32;
            tel.chatter[j] = s.chatter[j] as u32;
            tel.torque_limit[j] = s.torque_limit[j];
        }
        if !tel.load_angle.is_empty() {
            tel.load_angle.copy_from_slice(s.load_angle);
            tel.lost_steps.copy_from_slice(s.lost_steps);
        }
        if let Some(motors) = motors {
            for (j, speed) in tel.motor_speed.iter_mut().enumerate() {
                *speed = motors.motor_speed(j, s.v[j]).unwrap_or(0.0);
            }
        }
        tel.winding_temperature.clear();
        tel.winding_temperature.extend_from_slice(s.winding_temperature);
        tel.measured_effort.clear();
        tel.measured_effort.extend_from_slice(s.measured_effort);
        tel.observed_position.clear();
        tel.observed_position.extend_from_slice(s.observed_position);
        if !s.duty.is_empty() {
            tel.duty.copy_from_slice(s.duty);
            tel.current.copy_from_slice(s.current);
            tel.supply.copy_from_slice(s.supply);
        }
        if !s.friction.is_empty() {
            tel.friction.copy_from_slice(s.friction);
            for (flag, &stuck) in tel.stuck.iter_mut().zip(s.stuck) {
                *flag = stuck as u32;
            }
        }
    }
}

/// The schema as MCAP's protobuf profile wants it: a serialized FileDescriptorSet. Kept next to
/// the struct above; tests/recordings.rs decodes recorded messages through it (prost-reflect).
pub fn file_descriptor_set() -> Vec<u8> {
    file_descriptor_set_of(
        "controller_telemetry",
        "ControllerTelemetry",
        &[
            Field("time", 1, false, Type::Double),
            Field("target", 2, true, Type::Double),
            Field("error", 3, true, Type::Double),
            Field("torque", 4, true, Type::Double),
            Field("tau_g", 5, true, Type::Double),
            Field("saturated", 6, true, Type::Uint32),
            Field("chatter", 7, true, Type::Uint32),
            Field("tool_error", 8, false, Type::Double),
            Field("tool_position", 9, true, Type::Double),
            Field("torque_limit", 10, true, Type::Double),
            Field("load_angle", 11, true, Type::Double),
            Field("lost_steps", 12, true, Type::Int64),
            Field("motor_speed", 13, true, Type::Double),
            Field("friction", 14, true, Type::Double),
            Field("stuck", 15, true, Type::Uint32),
            Field("winding_temperature", 16, true, Type::Double),
            Field("duty", 17, true, Type::Double),
            Field("current", 18, true, Type::Double),
            Field("supply", 19, true, Type::Double),
            Field("measured_effort", 20, true, Type::Double),
            Field("observed_position", 21, true, Type::Double),
        ],
    )
}

encode_as_protobuf!(ControllerTelemetry);
