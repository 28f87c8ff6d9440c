//! The table a real follower's tool rested on, read from its episodes: where the leader asked the
//! tool lower than the follower's tool went in that episode, and the follower's tool stayed at its
//! lowest, something held it there. Such stays, enough of them, put a floor at the lowest of those
//! heights: the table is where the tool could go no lower. (The heights at rest differ by
//! millimetres from episode to episode: the contact is a jaw's surface, not the tool frame's
//! origin, and a calibration's errors move the computed tool. Fitting the height instead let the
//! fit prop the arm up on the table and weaken its servos: worse on held-out episodes.)

use crate::model::Model;
use crate::replay::forward::ForwardCase;
use crate::replay::tool_height::recorded_heights;

/// How near its lowest the real tool must be to rest there, m: a few encoder ticks at the tool
/// (1.5 mrad a tick of a 12-bit encoder, 0.3 m of arm: 0.5 mm a tick).
const AT_LOWEST: f64 = 1e-3;
/// How much lower than that the command must ask, m: more than the follower's own sag.
const ASKED_BELOW: f64 = 2e-3;
/// The frames that must show it: half a second at LeRobot's 30 fps.
const FEWEST_FRAMES: usize = 15;
/// The shortest stay counted, frames (a third of a second at 30 fps): a tool swinging through its
/// lowest point behind a command that swung lower passes within AT_LOWEST of it for a few frames.
const SHORTEST_STAY: usize = 10;

/// What the episodes show of a floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Touch {
    /// The lowest of the touching episodes' lowest real tool heights, world z, m.
    pub height: f64,
    /// The highest of them, m.
    pub highest: f64,
    /// The frames where the tool rested there while its commands asked lower.
    pub frames: usize,
    /// The commands' lowest tool height, m.
    pub commanded_lowest: f64,
}

/// The floor the real tool rested on in `cases` (its origin `frame`), if the episodes show one.
pub fn touched(model: &Model, frame: usize, cases: &[ForwardCase]) -> Option<Touch> {
    // the positions as recorded: smoothing rounds the corner where the tool lands
    let heights = |motion: &crate::replay::Motion| recorded_heights(model, frame, motion);
    let (mut frames, mut height, mut highest, mut commanded_lowest) = (0, f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY);
    for case in cases {
        let (real, asked) = (heights(case.real()), heights(case.commanded()));
        let lowest = real.iter().copied().fold(f64::INFINITY, f64::min);
        let resting = stays(real.iter().zip(&asked).map(|(&r, &a)| r <= lowest + AT_LOWEST && a < lowest - ASKED_BELOW));
        if resting > 0 && lowest.is_finite() {
            frames += resting;
            height = height.min(lowest);
            highest = highest.max(lowest);
            commanded_lowest = asked.iter().copied().fold(commanded_lowest, f64::min);
        }
    }
    (frames >= FEWEST_FRAMES).then_some(Touch { height, highest, frames, commanded_lowest })
}

/// The frames in runs of at least SHORTEST_STAY consecutive `true`s.
fn stays(frames: impl Iterator<Item = bool>) -> usize {
    let (mut total, mut run) = (0, 0);
    for resting in frames.chain(std::iter::once(false)) {
        if resting {
            run += 1;
        } else {
            if run >= SHORTEST_STAY {
                total += run;
            }
            run = 0;
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_stays_of_a_third_of_a_second_count() {
        let frames = |pattern: &[(bool, usize)]| pattern.iter().flat_map(|&(b, n)| std::iter::repeat_n(b, n)).collect::<Vec<_>>();
        assert_eq!(stays(frames(&[(true, 9), (false, 3), (true, 9)]).into_iter()), 0);
        assert_eq!(stays(frames(&[(false, 2), (true, 10), (false, 1), (true, 14)]).into_iter()), 24);
    }
}
