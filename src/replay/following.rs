//! Whether a real joint followed its commands at all: one whose real follower stayed put while its
//! commands swept (a servo off, a cable loose) is held where the real joint was and left out of the
//! comparison. Within an episode its commands must sweep far enough to tell; across a recording a
//! joint that did not follow in one episode and stayed put in another whose commands did not sweep
//! that far is taken as still off there.

/// A joint whose commands sweep at least this far (rad, 5°) is expected to move: an STS3215 at
/// LeRobot's P gain of 16 pushes 5° from its goal with several times its gearbox's static friction,
/// even at the 0.37 of the catalogue's stiffness found on the weaker real SO-101.
pub const SWEEP_EXPECTED: f64 = 0.087;
/// A joint that moves less than this fraction of its commands' sweep does not follow them (a servo
/// off, a cable loose): a real follower lags and sags, but covers most of the way.
pub const FOLLOWS_FRACTION: f64 = 0.1;
/// A joint that moved less than this (rad, 0.5°: a tenth of [`SWEEP_EXPECTED`]) stayed put.
const STAYED_PUT: f64 = FOLLOWS_FRACTION * SWEEP_EXPECTED;

/// How far a series spans, max − min.
pub fn sweep(x: &[f64]) -> f64 {
    let (lo, hi) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    if hi >= lo { hi - lo } else { 0.0 }
}

/// Whether a joint that swept `observed_sweep` followed its commands, which swept
/// `commanded_sweep`, at all; `off_elsewhere`: it did not follow them in another episode of the
/// recording.
pub fn follows(commanded_sweep: f64, observed_sweep: f64, off_elsewhere: bool) -> bool {
    let tested = commanded_sweep >= SWEEP_EXPECTED;
    if tested {
        observed_sweep >= FOLLOWS_FRACTION * commanded_sweep
    } else {
        !(off_elsewhere && observed_sweep < STAYED_PUT)
    }
}

/// Per coordinate, the sweeps (commanded, observed) of an episode's recorded positions (None where
/// either is not recorded).
pub fn sweeps(commanded: &[Option<Vec<f64>>], observed: &[Option<Vec<f64>>]) -> Vec<Option<(f64, f64)>> {
    commanded.iter().zip(observed).map(|(c, o)| Some((sweep(c.as_ref()?), sweep(o.as_ref()?)))).collect()
}

/// A joint that does not follow its commands in some of a recording's episodes.
#[derive(Clone, Debug, PartialEq)]
pub struct OffJoint {
    /// The model's coordinate.
    pub joint: usize,
    /// The episodes where it does not follow its commands (they swept at least 5°).
    pub off_in: Vec<i64>,
    /// The episodes where its commands swept less and it stayed put: taken as off there too.
    pub taken_off_in: Vec<i64>,
}

/// The joints that do not follow their commands in at least one of a recording's episodes, each
/// episode given by its index and its [`sweeps`].
pub fn off_joints(episodes: &[(i64, Vec<Option<(f64, f64)>>)]) -> Vec<OffJoint> {
    let n = episodes.iter().map(|(_, s)| s.len()).max().unwrap_or(0);
    (0..n)
        .filter_map(|joint| {
            let (mut off_in, mut taken_off_in) = (Vec::new(), Vec::new());
            for (index, sweeps) in episodes {
                if let Some(Some((c, o))) = sweeps.get(joint) {
                    if !follows(*c, *o, false) {
                        off_in.push(*index);
                    } else if !follows(*c, *o, true) {
                        taken_off_in.push(*index);
                    }
                }
            }
            // taken as off only where another episode shows it off
            (!off_in.is_empty()).then_some(OffJoint { joint, off_in, taken_off_in })
        })
        .collect()
}

impl OffJoint {
    /// The one notice of the episodes where the joint is taken as off without their telling (None:
    /// none).
    pub fn notice(&self, model: &crate::model::Model) -> Option<String> {
        if self.taken_off_in.is_empty() {
            return None;
        }
        Some(format!(
            "{} does not follow its commands in {}; in {} its commands sweep less than {:.0}° and it stayed within {:.1}°: taken as not following there too (held where the real one was, left out of the ranking)",
            model.joints[self.joint].name,
            episode_list(&self.off_in),
            episode_list(&self.taken_off_in),
            SWEEP_EXPECTED.to_degrees(),
            STAYED_PUT.to_degrees()
        ))
    }
}

/// "episode 3", "episodes 3, 5 and 7", "episodes 3, 5, 7, 9, 11, 13 and 20 more".
fn episode_list(episodes: &[i64]) -> String {
    const NAMED: usize = 6;
    let named: Vec<String> = episodes.iter().take(NAMED).map(|e| e.to_string()).collect();
    match episodes.len() {
        0 => "no episode".into(),
        1 => format!("episode {}", named[0]),
        n if n <= NAMED => format!("episodes {} and {}", named[..n - 1].join(", "), named[n - 1]),
        n => format!("episodes {} and {} more", named.join(", "), n - NAMED),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_joint_is_off_where_tested_and_taken_as_off_where_it_stayed_put_untested() {
        // tested: commands over 5°, the joint under a tenth of them
        assert!(!follows(0.5, 0.04, false));
        assert!(follows(0.5, 0.06, false));
        // untested: commands under 5°; off only if off elsewhere and it stayed within 0.5°
        assert!(follows(0.05, 0.0, false));
        assert!(!follows(0.05, 0.008, true));
        assert!(follows(0.05, 0.01, true));
        // tested and following: off elsewhere does not matter (the cable put back)
        assert!(follows(0.5, 0.4, true));
        let episodes = vec![(0, vec![Some((0.5, 0.4)), Some((0.5, 0.0)), None]), (1, vec![Some((0.5, 0.45)), Some((0.02, 0.0)), Some((1.0, 0.9))])];
        assert_eq!(off_joints(&episodes), vec![OffJoint { joint: 1, off_in: vec![0], taken_off_in: vec![1] }]);
    }
}
