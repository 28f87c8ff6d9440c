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

/// The coordinates that do not follow their commands in at least one of a recording's episodes,
/// each episode given by its [`sweeps`].
pub fn off_somewhere(episodes: &[Vec<Option<(f64, f64)>>]) -> Vec<usize> {
    let n = episodes.iter().map(Vec::len).max().unwrap_or(0);
    (0..n).filter(|&j| episodes.iter().any(|e| matches!(e.get(j), Some(Some((c, o))) if !follows(*c, *o, false)))).collect()
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
        let episodes = vec![vec![Some((0.5, 0.4)), Some((0.5, 0.0)), None], vec![Some((0.5, 0.45)), Some((0.02, 0.0)), Some((1.0, 0.9))]];
        assert_eq!(off_somewhere(&episodes), vec![1]);
    }
}
