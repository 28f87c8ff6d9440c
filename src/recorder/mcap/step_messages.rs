//! The two messages the MCAP carries at every control step, `/joint_states` and `/controller`,
//! encoded straight into the batch's bytes: the same bytes as their prost encoding (the tests
//! compare the two on varied messages), without prost's generic buffer calls per value and its
//! second walk over the message for the nested lengths — which were three quarters of the MCAP
//! recorder thread's time.
//!
//! Protocol buffers' wire format as prost writes it: fields in the order of their tags; a proto3
//! scalar left out when it is zero (an `optional` one only when absent); `repeated` numbers packed
//! (key, byte length, the values) and left out when empty; doubles as 8 little-endian bytes.

use super::telemetry::ControllerTelemetry;
use foxglove::messages::{JointState, JointStates, Timestamp};

const VARINT: u32 = 0;
const FIXED64: u32 = 1;
const LENGTH_DELIMITED: u32 = 2;

fn varint(mut value: u64, out: &mut Vec<u8>) {
    while value >= 0x80 {
        out.push((value as u8) | 0x80);
        value >>= 7;
    }
    out.push(value as u8);
}

fn varint_len(value: u64) -> usize {
    // 7 bits a byte; 0 still takes one
    ((64 - (value | 1).leading_zeros() as usize) + 6) / 7
}

fn key(tag: u32, wire_type: u32, out: &mut Vec<u8>) {
    varint(u64::from(tag << 3 | wire_type), out);
}

fn double(tag: u32, value: f64, out: &mut Vec<u8>) {
    key(tag, FIXED64, out);
    out.extend_from_slice(&value.to_le_bytes());
}

fn packed_doubles(tag: u32, values: &[f64], out: &mut Vec<u8>) {
    if values.is_empty() {
        return;
    }
    key(tag, LENGTH_DELIMITED, out);
    varint(8 * values.len() as u64, out);
    doubles_le(values, out);
}

/// The values as 8 little-endian bytes each, back to back: on a little-endian machine their bytes
/// as they are in memory, in one copy (value by value they were half of a message's encoding).
fn doubles_le(values: &[f64], out: &mut Vec<u8>) {
    #[cfg(target_endian = "little")]
    {
        // SAFETY: an f64 slice is initialized memory of 8·len bytes, readable as bytes (u8 has no
        // alignment or validity requirements); on a little-endian target each f64's bytes are its
        // to_le_bytes
        out.extend_from_slice(unsafe { std::slice::from_raw_parts(values.as_ptr().cast::<u8>(), std::mem::size_of_val(values)) });
    }
    #[cfg(not(target_endian = "little"))]
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
}

/// Packed varints (uint32, and int64 as its two's complement, as protobuf does).
fn packed_varints(tag: u32, values: impl Iterator<Item = u64> + Clone, out: &mut Vec<u8>) {
    let length: usize = values.clone().map(varint_len).sum();
    if length == 0 {
        return;
    }
    key(tag, LENGTH_DELIMITED, out);
    varint(length as u64, out);
    for v in values {
        varint(v, out);
    }
}

fn timestamp_len(t: &Timestamp) -> usize {
    let field = |v: u32| if v == 0 { 0 } else { 1 + varint_len(u64::from(v)) };
    field(t.sec()) + field(t.nsec())
}

fn timestamp_field(tag: u32, t: &Timestamp, out: &mut Vec<u8>) {
    key(tag, LENGTH_DELIMITED, out);
    varint(timestamp_len(t) as u64, out);
    for (field, v) in [(1, t.sec()), (2, t.nsec())] {
        if v != 0 {
            key(field, VARINT, out);
            varint(u64::from(v), out);
        }
    }
}

fn joint_state_len(j: &JointState) -> usize {
    let name = if j.name.is_empty() { 0 } else { 1 + varint_len(j.name.len() as u64) + j.name.len() };
    let doubles = [j.position, j.velocity, j.acceleration, j.effort].iter().filter(|v| v.is_some()).count();
    name + 9 * doubles
}

/// `message` as prost encodes it, appended to `out`.
pub fn joint_states(message: &JointStates, out: &mut Vec<u8>) {
    if let Some(t) = &message.timestamp {
        timestamp_field(1, t, out);
    }
    for joint in &message.joints {
        key(2, LENGTH_DELIMITED, out);
        varint(joint_state_len(joint) as u64, out);
        if !joint.name.is_empty() {
            key(1, LENGTH_DELIMITED, out);
            varint(joint.name.len() as u64, out);
            out.extend_from_slice(joint.name.as_bytes());
        }
        for (tag, value) in [(2, joint.position), (3, joint.velocity), (4, joint.acceleration), (5, joint.effort)] {
            if let Some(v) = value {
                double(tag, v, out);
            }
        }
    }
}

/// `/joint_states` laid out once for a run: every message is the same bytes but for its timestamp
/// and its values, since each joint's name and the values it carries (position, velocity, effort…)
/// stay the same. A message is then one copy of the layout and a store per value, instead of being
/// built field by field (the MCAP recorder's largest encoding).
pub struct JointStatesLayout {
    /// The joints' part of a message (its values are overwritten by every `encode`).
    body: Vec<u8>,
    /// Where each value's 8 bytes are in `body`: per joint, its position, velocity, acceleration
    /// and effort, those it has.
    slots: Vec<usize>,
}

impl JointStatesLayout {
    /// The layout of messages with `joints`' names and fields (their values are not used).
    pub fn new(joints: &[JointState]) -> Self {
        // a message without its timestamp is its joints' entries back to back, each ending with its
        // values: a key's byte, then 8 bytes, in the order `joint_states` writes them
        let (mut body, mut slots) = (Vec::new(), Vec::new());
        for joint in joints {
            let present = [joint.position, joint.velocity, joint.acceleration, joint.effort].iter().filter(|v| v.is_some()).count();
            joint_states(&JointStates { timestamp: None, joints: vec![joint.clone()] }, &mut body);
            let values_start = body.len() - 9 * present;
            slots.extend((0..present).map(|i| values_start + 9 * i + 1));
        }
        Self { body, slots }
    }

    /// Values a message carries, in order (see `slots`).
    pub fn values(&self) -> usize {
        self.slots.len()
    }

    /// The message with `values` (one per slot) and `timestamp`, as `joint_states` encodes it.
    pub fn encode(&self, timestamp: Option<&Timestamp>, values: &[f64], out: &mut Vec<u8>) {
        assert_eq!(values.len(), self.slots.len(), "one value per slot");
        if let Some(t) = timestamp {
            timestamp_field(1, t, out);
        }
        let start = out.len();
        out.extend_from_slice(&self.body);
        let body = &mut out[start..];
        for (&slot, value) in self.slots.iter().zip(values) {
            body[slot..slot + 8].copy_from_slice(&value.to_le_bytes());
        }
    }
}

/// `message` as prost encodes it, appended to `out`.
pub fn controller_telemetry(message: &ControllerTelemetry, out: &mut Vec<u8>) {
    let m = message;
    // proto3 leaves a scalar out when it is zero (−0.0 included, as prost compares with 0.0)
    if m.time != 0.0 {
        double(1, m.time, out);
    }
    packed_doubles(2, &m.target, out);
    packed_doubles(3, &m.error, out);
    packed_doubles(4, &m.torque, out);
    packed_doubles(5, &m.tau_g, out);
    packed_varints(6, m.saturated.iter().map(|&v| u64::from(v)), out);
    packed_varints(7, m.chatter.iter().map(|&v| u64::from(v)), out);
    if m.tool_error != 0.0 {
        double(8, m.tool_error, out);
    }
    packed_doubles(9, &m.tool_position, out);
    packed_doubles(10, &m.torque_limit, out);
    packed_doubles(11, &m.load_angle, out);
    packed_varints(12, m.lost_steps.iter().map(|&v| v as u64), out);
    packed_doubles(13, &m.motor_speed, out);
    packed_doubles(14, &m.friction, out);
    packed_varints(15, m.stuck.iter().map(|&v| u64::from(v)), out);
    packed_doubles(16, &m.winding_temperature, out);
    packed_doubles(17, &m.duty, out);
    packed_doubles(18, &m.current, out);
    packed_doubles(19, &m.supply, out);
    packed_doubles(20, &m.measured_effort, out);
    packed_doubles(21, &m.observed_position, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prost(message: &impl foxglove::Encode) -> Vec<u8> {
        let mut bytes = Vec::new();
        message.encode(&mut bytes).unwrap();
        bytes
    }

    /// Values that take every branch of the format: zeros (left out or not), −0.0, NaN, infinities,
    /// varints of one to ten bytes.
    const DOUBLES: [f64; 9] = [0.0, -0.0, 1.5, -2.25e-300, f64::NAN, f64::INFINITY, 3.0e8, -7.0, 1e-9];

    #[test]
    fn joint_states_are_prost_s_bytes() {
        let long = "x".repeat(200);
        let names = ["", "j", "shoulder_pan_joint", long.as_str()];
        for (k, sec) in [0u32, 1, 127, 128, 1_764_000_000, u32::MAX].into_iter().enumerate() {
            for nsec in [0u32, 5, 999_999_999] {
                let joints: Vec<JointState> = (0..k + 1)
                    .map(|i| JointState {
                        name: names[i % names.len()].to_string(),
                        position: Some(DOUBLES[i % 9]),
                        velocity: (i % 3 != 1).then_some(DOUBLES[(i + 4) % 9]),
                        acceleration: (i % 4 == 2).then_some(DOUBLES[(i + 2) % 9]),
                        effort: (i % 2 == 0).then_some(DOUBLES[(i + 7) % 9]),
                    })
                    .collect();
                for timestamp in [None, Some(Timestamp::new(sec, nsec))] {
                    let message = JointStates { timestamp, joints: joints.clone() };
                    let mut ours = vec![0xAB]; // appended, not overwritten
                    joint_states(&message, &mut ours);
                    assert_eq!(ours[1..], prost(&message)[..], "{message:?}");
                }
            }
        }
    }

    /// The layout's messages are `joint_states`' (so prost's) for any names, fields, values and stamp.
    #[test]
    fn joint_states_from_their_layout_are_the_same_bytes() {
        let long = "y".repeat(150);
        let names = ["", "J1", "shoulder_pan_joint", long.as_str()];
        for count in [0usize, 1, 6, 9] {
            let joints: Vec<JointState> = (0..count)
                .map(|i| JointState {
                    name: names[i % names.len()].to_string(),
                    position: Some(0.0),
                    velocity: (i % 3 != 2).then_some(0.0),
                    acceleration: (i % 4 == 1).then_some(0.0),
                    effort: (i % 5 != 4).then_some(0.0),
                })
                .collect();
            let layout = JointStatesLayout::new(&joints);
            for shift in 0..9 {
                let values: Vec<f64> = (0..layout.values()).map(|i| DOUBLES[(i + shift) % 9]).collect();
                let mut next = values.iter().copied();
                let filled: Vec<JointState> = joints
                    .iter()
                    .map(|j| {
                        let mut take = |present: Option<f64>| present.map(|_| next.next().unwrap());
                        JointState { name: j.name.clone(), position: take(j.position), velocity: take(j.velocity), acceleration: take(j.acceleration), effort: take(j.effort) }
                    })
                    .collect();
                for timestamp in [None, Some(Timestamp::new(1_764_000_000 + shift as u32, 999_999_999 / (shift as u32 + 1)))] {
                    let message = JointStates { timestamp, joints: filled.clone() };
                    let mut ours = vec![0xEF];
                    layout.encode(timestamp.as_ref(), &values, &mut ours);
                    assert_eq!(ours[1..], prost(&message)[..], "{message:?}");
                }
            }
        }
    }

    #[test]
    fn controller_telemetry_is_prost_s_bytes() {
        for n in [0usize, 1, 6, 17] {
            for shift in 0..9 {
                let d = |k: usize| (0..n).map(|i| DOUBLES[(i + k + shift) % 9]).collect::<Vec<f64>>();
                let flags = |k: usize| (0..n).map(|i| ((i + k + shift) % 3 == 0) as u32 * if shift == 4 { 300 } else { 1 }).collect::<Vec<u32>>();
                let message = ControllerTelemetry {
                    time: DOUBLES[shift],
                    target: d(1),
                    error: d(2),
                    torque: d(3),
                    tau_g: d(4),
                    saturated: flags(0),
                    chatter: flags(1),
                    tool_error: DOUBLES[(shift + 1) % 9],
                    tool_position: if n == 0 { vec![] } else { d(5)[..n.min(3)].to_vec() },
                    torque_limit: d(6),
                    load_angle: d(7),
                    lost_steps: (0..n).map(|i| [0i64, 3, -1, 1 << 40, i64::MIN][(i + shift) % 5]).collect(),
                    motor_speed: d(8),
                    friction: if shift % 2 == 0 { d(0) } else { vec![] },
                    stuck: if shift % 2 == 0 { flags(2) } else { vec![] },
                    winding_temperature: if shift % 3 == 0 { d(3) } else { vec![] },
                    duty: if shift % 4 == 1 { d(4) } else { vec![] },
                    current: if shift % 4 == 1 { d(5) } else { vec![] },
                    supply: if shift % 4 == 1 { d(6) } else { vec![] },
                    measured_effort: if shift % 3 == 2 { d(7) } else { vec![] },
                    observed_position: if shift % 3 == 1 { d(8) } else { vec![] },
                };
                let mut ours = vec![0xCD];
                controller_telemetry(&message, &mut ours);
                assert_eq!(ours[1..], prost(&message)[..], "{message:?}");
            }
        }
    }

    #[test]
    fn varint_lengths_match_the_encoding() {
        for v in [0u64, 1, 127, 128, 16_383, 16_384, u64::from(u32::MAX), 1 << 62, u64::MAX] {
            let mut bytes = Vec::new();
            varint(v, &mut bytes);
            assert_eq!(bytes.len(), varint_len(v), "{v}");
        }
    }
}
