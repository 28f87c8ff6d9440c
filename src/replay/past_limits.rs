//! Recorded positions past a joint's URDF range. A real arm's calibrated range commonly passes its
//! URDF's limits by a few degrees: such positions are followed to the limit, and a recording's
//! largest excess per joint said in one notice (over all its episodes, commands and follower alike);
//! a position that cannot be the arm's is refused, naming the joint, episode, frame and value.

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

/// `episode`'s positions `mapped` onto the model's coordinates, followed to each joint's limit where
/// they pass it, and per joint that passed it the largest excess; a position past it by more than
/// [`REVOLUTE_EXCESS_MAX`] ([`PRISMATIC_EXCESS_MAX`]) refused in one line.
pub fn follow_to_limits(model: &Model, episode: &Episode, mut mapped: Vec<Option<Vec<f64>>>) -> Result<(Vec<Option<Vec<f64>>>, Vec<PastLimit>), Error> {
    let mut past = Vec::new();
    for (j, series) in mapped.iter_mut().enumerate() {
        let Some(values) = series else { continue };
        let (lower, upper) = range_of(model, j);
        let (refused_past, unit, scale) = unit_of(model, j);
        let mut worst = (0.0, 0usize);
        for (k, v) in values.iter_mut().enumerate() {
            let excess = (*v - upper).max(lower - *v);
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
        if worst.0 > ROUND_OFF {
            past.push(PastLimit { joint: j, name: model.joints[j].name.clone(), excess: worst.0, episode: episode.label.clone(), frame: worst.1, time: episode.time[worst.1] });
        }
    }
    Ok((mapped, past))
}

/// Of `past`, the largest excess of each joint, by joint.
pub fn largest_per_joint<'a>(past: impl IntoIterator<Item = &'a PastLimit>) -> Vec<PastLimit> {
    let mut largest: Vec<PastLimit> = Vec::new();
    for p in past {
        match largest.iter_mut().find(|l| l.joint == p.joint) {
            Some(l) if p.excess > l.excess => *l = p.clone(),
            Some(_) => {}
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
            // an excess that rounds to nothing is still said
            let by = if p.excess * scale < 0.05 { format!("less than 0.1{unit}") } else { format!("up to {:.1}{unit}", p.excess * scale) };
            format!("{} by {by} ({at}frame {}, {:.2} s)", model.joints[p.joint].name, p.frame, p.time)
        })
        .collect::<Vec<_>>()
        .join(", ");
    Some(if lone { format!("{}: past the URDF's limits, followed to the limit: {each}", largest[0].episode) } else { format!("past the URDF's limits in {passed} of {count} episodes, followed to the limit: {each}") })
}
