//! Recorded positions past a joint's URDF range. A real arm's calibrated range commonly passes its
//! URDF's limits by a few degrees: such positions are followed to the limit, and a recording's
//! largest excess per joint said in one notice (over all its episodes, commands and follower alike);
//! a position that cannot be the arm's is refused, naming the joint, episode, frame and value. A
//! revolute joint's position is an angle: a full-turn encoder (a wrist roll's) wraps at ±180°, so a
//! position closer to the range a turn round is read there, and the notice says so.

use crate::error::Error;
use crate::model::{JointKind, Model};
use crate::motion::Episode;

/// Past its URDF range by more than this a recorded position cannot be the arm's, rad (20°: a real
/// arm's calibrated range passes its URDF's by a few degrees; more is a wrong unit, sign or offset).
pub const REVOLUTE_EXCESS_MAX: f64 = 20.0 * std::f64::consts::PI / 180.0;
/// The same for a prismatic joint, m.
pub const PRISMATIC_EXCESS_MAX: f64 = 0.02;
/// Excesses below this are round-off, followed to the limit without a word, rad (m).
const ROUND_OFF: f64 = 1e-9;

/// One joint's largest excess past its URDF range in a series of recorded positions.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PastLimit {
    /// The model's coordinate.
    #[serde(skip)]
    pub joint: usize,
    #[serde(rename = "joint")]
    pub name: String,
    /// How far past, rad (m for a prismatic joint).
    pub excess: f64,
    /// Where: the episode's label, its frame and the frame's time, s.
    #[serde(skip)]
    pub episode: String,
    pub frame: usize,
    #[serde(rename = "time_s")]
    pub time: f64,
    /// Whether any of the joint's positions was read a turn round from where it was recorded.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub turned: bool,
}

/// A joint's range, [−∞, ∞] where the URDF gives none.
pub fn range_of(model: &Model, j: usize) -> (f64, f64) {
    let (lower, upper) = model.joints[j].range();
    if lower.is_finite() && upper.is_finite() { (lower, upper) } else { (f64::NEG_INFINITY, f64::INFINITY) }
}

/// (the refusal threshold, its unit, the unit's scale from SI) of joint `j`.
fn unit_of(model: &Model, j: usize) -> (f64, &'static str, f64) {
    if model.joints[j].kind == JointKind::Prismatic { (PRISMATIC_EXCESS_MAX, "mm", 1e3) } else { (REVOLUTE_EXCESS_MAX, "°", 180.0 / std::f64::consts::PI) }
}

/// How far `value` lies past [lower, upper] (≤ 0 within it).
fn excess_of(value: f64, lower: f64, upper: f64) -> f64 {
    (value - upper).max(lower - value)
}

/// The same angle as a revolute joint's `value`, past its range, a turn round, where that is closer
/// to the range (a full-turn encoder wraps at ±180°, and a range spanning most of a turn reaches past
/// it); None where `value` is the closer.
fn nearer_a_turn_round(value: f64, lower: f64, upper: f64) -> Option<f64> {
    let turn = std::f64::consts::TAU;
    let round = if value > upper { value - turn } else { value + turn };
    (excess_of(round, lower, upper) < excess_of(value, lower, upper)).then_some(round)
}

/// `episode`'s positions `mapped` onto the model's coordinates, followed to each joint's limit where
/// they pass it (a revolute joint's read a turn round where that is nearer its range), and per joint
/// that passed it the largest excess; a position past it by more than [`REVOLUTE_EXCESS_MAX`]
/// ([`PRISMATIC_EXCESS_MAX`]) refused in one line.
pub fn follow_to_limits(model: &Model, episode: &Episode, mut mapped: Vec<Option<Vec<f64>>>) -> Result<(Vec<Option<Vec<f64>>>, Vec<PastLimit>), Error> {
    let mut past = Vec::new();
    for (j, series) in mapped.iter_mut().enumerate() {
        let Some(values) = series else { continue };
        let (lower, upper) = range_of(model, j);
        let (refused_past, unit, scale) = unit_of(model, j);
        // a range of a turn or more holds every angle: a position past it is the joint's own
        let wraps = model.joints[j].kind == JointKind::Revolute && upper - lower < std::f64::consts::TAU;
        let (mut worst, mut first_turned) = ((0.0, 0usize), None);
        for (k, v) in values.iter_mut().enumerate() {
            let mut excess = excess_of(*v, lower, upper);
            if wraps && excess > ROUND_OFF {
                if let Some(round) = nearer_a_turn_round(*v, lower, upper) {
                    *v = round;
                    excess = excess_of(round, lower, upper);
                    first_turned.get_or_insert(k);
                }
            }
            if excess > refused_past {
                return Err(Error::flag(
                    episode.label.clone(),
                    format!("joint '{}': frame {k} ({:.2} s) at {:.4} is {:.1}{unit} past its URDF range [{lower}, {upper}], more than the {:.0}{unit} a real arm's calibration passes it by: not a pose of this arm (a wrong unit, sign or offset in the joint map?)", model.joints[j].name, episode.time[k], *v, excess * scale, refused_past * scale),
                ));
            }
            if excess > worst.0 {
                worst = (excess, k);
            }
            *v = v.clamp(lower, upper);
        }
        // positions read a turn round into the range are said too, where the first was
        let frame = if worst.0 > ROUND_OFF { Some(worst.1) } else { first_turned };
        if let Some(frame) = frame {
            past.push(PastLimit { joint: j, name: model.joints[j].name.clone(), excess: worst.0, episode: episode.label.clone(), frame, time: episode.time[frame], turned: first_turned.is_some() });
        }
    }
    Ok((mapped, past))
}

/// Of `past`, the largest excess of each joint (read a turn round if any was), by joint.
pub fn largest_per_joint<'a>(past: impl IntoIterator<Item = &'a PastLimit>) -> Vec<PastLimit> {
    let mut largest: Vec<PastLimit> = Vec::new();
    for p in past {
        match largest.iter_mut().find(|l| l.joint == p.joint) {
            Some(l) if p.excess > l.excess => *l = PastLimit { turned: l.turned || p.turned, ..p.clone() },
            Some(l) => l.turned |= p.turned,
            None => largest.push(p.clone()),
        }
    }
    largest.sort_by_key(|p| p.joint);
    largest
}

/// The one notice of a recording's positions past the URDF's limits, each episode's [`PastLimit`]s
/// given (its commands' and its follower's together): the largest excess per joint and where, and
/// in how many of the episodes (None: no position passed a limit).
pub fn notice<'a>(model: &Model, episodes: impl IntoIterator<Item = &'a [PastLimit]>) -> Option<String> {
    let (mut count, mut passed, mut all) = (0, 0, Vec::new());
    for past in episodes {
        count += 1;
        passed += usize::from(!past.is_empty());
        all.extend(past);
    }
    let largest = largest_per_joint(all);
    if largest.is_empty() {
        return None;
    }
    let lone = count == 1;
    let each = largest
        .iter()
        .map(|p| {
            let (_, unit, scale) = unit_of(model, p.joint);
            let at = if lone { String::new() } else { format!("{}, ", p.episode) };
            let name = &model.joints[p.joint].name;
            if p.excess <= ROUND_OFF {
                return format!("{name} read a turn round into its range (360° from where it was recorded; {at}frame {}, {:.2} s)", p.frame, p.time);
            }
            // an excess that rounds to nothing is still said
            let by = if p.excess * scale < 0.05 { format!("less than 0.1{unit}") } else { format!("up to {:.1}{unit}", p.excess * scale) };
            let turned = if p.turned { ", some of it read a turn round (360° from where it was recorded, nearer the range)" } else { "" };
            format!("{name} by {by} ({at}frame {}, {:.2} s{turned})", p.frame, p.time)
        })
        .collect::<Vec<_>>()
        .join(", ");
    Some(if lone { format!("{}: past the URDF's limits, followed to the limit: {each}", largest[0].episode) } else { format!("past the URDF's limits in {passed} of {count} episodes, followed to the limit: {each}") })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn so101() -> Model {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/robots/so101.urdf");
        crate::model::load_urdf(&path).expect("the fixture loads")
    }

    /// An episode of `frames` frames at 30 fps; only its label and times are read here.
    fn episode(frames: usize) -> Episode {
        Episode { label: "episode 0".into(), index: Some(0), time: (0..frames).map(|k| k as f64 / 30.0).collect(), columns: vec![], effort: vec![], notices: vec![] }
    }

    /// The model's positions with joint `j`'s series (given in degrees) and the others absent.
    fn one_joint(model: &Model, j: usize, degrees: &[f64]) -> Vec<Option<Vec<f64>>> {
        (0..model.dof()).map(|i| (i == j).then(|| degrees.iter().map(|d| d.to_radians()).collect())).collect()
    }

    #[test]
    fn a_wrist_roll_past_its_wrap_is_read_a_turn_round_and_followed_to_the_nearer_limit() {
        // the SO-101's wrist roll spans −157.2°…162.8°; its full-turn encoder reads ±180°: −179° is
        // +181°, 18.2° past the upper limit (21.8° past the lower read as recorded, which would be
        // refused); −175° is nearer the lower limit as recorded (17.8° against 22.2°)
        let model = so101();
        let roll = model.joint_index("wrist_roll").unwrap();
        let (lower, upper) = range_of(&model, roll);
        let (mapped, past) = follow_to_limits(&model, &episode(4), one_joint(&model, roll, &[0.0, 179.0, -179.0, -175.0])).unwrap();
        let followed = mapped[roll].as_ref().unwrap();
        assert_eq!(followed[0], 0.0);
        assert_eq!(&followed[1..], &[upper, upper, lower]);
        assert_eq!(past.len(), 1);
        let want = (181f64 - upper.to_degrees()).to_radians();
        assert!((past[0].excess - want).abs() < 1e-12 && past[0].frame == 2 && past[0].turned, "{past:?}");
        let said = notice(&model, [past.as_slice()]).unwrap();
        assert!(said.contains("wrist_roll by up to 18.2° (frame 2, 0.07 s, some of it read a turn round"), "{said}");
    }

    #[test]
    fn a_joint_whose_range_is_far_from_a_turn_is_read_as_recorded_and_refused_past_the_excess_allowed() {
        // the elbow spans ±96.8°: a turn round is never nearer its range, and 25° past it is refused
        let model = so101();
        let elbow = model.joint_index("elbow_flex").unwrap();
        let upper = range_of(&model, elbow).1.to_degrees();
        let (mapped, past) = follow_to_limits(&model, &episode(2), one_joint(&model, elbow, &[0.0, upper + 3.0])).unwrap();
        assert_eq!(mapped[elbow].as_ref().unwrap()[1], range_of(&model, elbow).1);
        assert!(!past[0].turned && (past[0].excess.to_degrees() - 3.0).abs() < 1e-9, "{past:?}");
        let refused = follow_to_limits(&model, &episode(2), one_joint(&model, elbow, &[0.0, upper + 25.0])).unwrap_err().to_string();
        assert!(refused.contains("episode 0") && refused.contains("joint 'elbow_flex': frame 1") && refused.contains("past its URDF range"), "{refused}");
    }

    #[test]
    fn a_position_read_a_turn_round_into_the_range_is_said() {
        // 210° is −150°, inside the wrist roll's range: followed there, and the notice says why
        let model = so101();
        let roll = model.joint_index("wrist_roll").unwrap();
        let (mapped, past) = follow_to_limits(&model, &episode(3), one_joint(&model, roll, &[0.0, 0.0, 210.0])).unwrap();
        assert!((mapped[roll].as_ref().unwrap()[2] - (-150f64).to_radians()).abs() < 1e-12);
        assert!(past.len() == 1 && past[0].excess == 0.0 && past[0].frame == 2 && past[0].turned, "{past:?}");
        let said = notice(&model, [past.as_slice()]).unwrap();
        assert!(said.contains("wrist_roll read a turn round into its range (360° from where it was recorded; frame 2, 0.07 s)"), "{said}");
    }
}
