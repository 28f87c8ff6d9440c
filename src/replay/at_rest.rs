//! Where a follower's gap is made at rest: the stretches in which the commands and the real joint
//! both stood still. A real arm rests short of a still command by whatever holds it (friction, a
//! stop, a contact, a load); a gap made there says the model rests otherwise, not that it moves
//! otherwise.

/// The part of a joint's gap made where its commands and the real joint both stood still for at
/// least [`REST_SECONDS`] (each within [`REST_BAND`] of where the stretch began): where a real arm
/// rests short of its command by what holds it — friction, a stop, a contact, a load — and not by
/// its dynamics. A gap made mostly there is no error in how the model moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct AtRest {
    /// How long the commands and the real joint stood still, s.
    pub seconds: f64,
    /// Over those frames, the mean |observed − commanded| and |simulated − commanded|, rad (m).
    pub real_offset: f64,
    pub sim_offset: f64,
    /// Those frames' part of [`JointGap::gap_mae`](super::forward::JointGap::gap_mae): the sum of
    /// their |simulated − observed| divided by the episode's frame count, rad (m).
    pub gap_part: f64,
}

/// A stretch shorter than this is a pause, not a rest, s.
pub const REST_SECONDS: f64 = 1.0;
/// How far commands and the real joint may wander in a still stretch, rad (0.3°: three ticks of a
/// 4096-tick encoder, a resting leader's jitter).
pub const REST_BAND: f64 = 0.005;

impl AtRest {
    /// The still frames ([`still_frames`]) of a joint's `commanded` and `observed` positions at
    /// `time`, and what the real and the `simulated` follower did there.
    pub fn of(time: &[f64], commanded: &[f64], observed: &[f64], simulated: &[f64]) -> Self {
        let (c, o, s) = (commanded, observed, simulated);
        let frames = time.len();
        let period = if frames > 1 { (time[frames - 1] - time[0]) / (frames - 1) as f64 } else { 0.0 };
        let mut rest = Self::default();
        let mut count = 0usize;
        for (k, _) in still_frames(period, commanded, observed).iter().enumerate().filter(|(_, still)| **still) {
            rest.real_offset += (o[k] - c[k]).abs();
            rest.sim_offset += (s[k] - c[k]).abs();
            rest.gap_part += (s[k] - o[k]).abs();
            count += 1;
        }
        rest.seconds = count as f64 * period;
        if count > 0 {
            rest.real_offset /= count as f64;
            rest.sim_offset /= count as f64;
            rest.gap_part /= frames as f64;
        }
        rest
    }
}

/// Per frame (`period` s apart), whether it lies in a stretch of at least [`REST_SECONDS`] in which
/// `commanded` and `observed` both stayed within [`REST_BAND`] of their values at the stretch's
/// first frame (greedy, from the episode's start).
fn still_frames(period: f64, commanded: &[f64], observed: &[f64]) -> Vec<bool> {
    let (c, o) = (commanded, observed);
    let frames = c.len();
    let mut still = vec![false; frames];
    let mut start = 0;
    while start < frames {
        let mut end = start + 1;
        while end < frames && (c[end] - c[start]).abs() <= REST_BAND && (o[end] - o[start]).abs() <= REST_BAND {
            end += 1;
        }
        if (end - start) as f64 * period >= REST_SECONDS {
            still[start..end].fill(true);
        }
        start = end;
    }
    still
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_stretches_still_for_a_second_count_and_their_part_of_the_gap_adds_up() {
        // 30 fps, 6 s: commands still at 0 for 2 s, a ramp to 1 rad over 2 s, still at 1 for 2 s;
        // the real joint rests 40 mrad short in the first stretch (with a tick of jitter), follows
        // the ramp 30 mrad behind, and rests on target in the last; the model rests 10 mrad short
        // and follows the ramp 20 mrad behind
        let frames = 181;
        let time: Vec<f64> = (0..frames).map(|k| k as f64 / 30.0).collect();
        let commanded: Vec<f64> = time.iter().map(|&t| ((t - 2.0) / 2.0).clamp(0.0, 1.0)).collect();
        let moving = |t: f64| (2.0..4.0).contains(&t);
        let observed: Vec<f64> = time.iter().zip(&commanded).enumerate().map(|(k, (&t, &c))| if t < 2.0 { c - 0.040 + 0.0015 * (k % 2) as f64 } else if moving(t) { c - 0.030 } else { c }).collect();
        let simulated: Vec<f64> = time.iter().zip(&commanded).map(|(&t, &c)| if t < 2.0 { c - 0.010 } else if moving(t) { c - 0.020 } else { c }).collect();
        let rest = AtRest::of(&time, &commanded, &observed, &simulated);
        // frames 0–59 still (the ramp starts moving after 2 s), 120–180 still: 60 + 61 frames
        let still_frames = 60.0 + 61.0;
        assert!((rest.seconds - still_frames / 30.0).abs() < 1e-9, "{rest:?}");
        // the first stretch: real 40 or 38.5 mrad off, model 10; the last: both on target
        let first_real = (30.0 * 0.040 + 30.0 * 0.0385) / 60.0;
        assert!((rest.real_offset - first_real * 60.0 / still_frames).abs() < 1e-12, "{rest:?}");
        assert!((rest.sim_offset - 0.010 * 60.0 / still_frames).abs() < 1e-12, "{rest:?}");
        assert!((rest.gap_part - (first_real - 0.010) * 60.0 / frames as f64).abs() < 1e-12, "{rest:?}");
        // a pause shorter than a second is motion, not rest
        let paused: Vec<f64> = time.iter().map(|&t| if (1.0..1.9).contains(&t) { 0.5 } else { t }).collect();
        assert_eq!(AtRest::of(&time, &paused, &paused, &paused).seconds, 0.0);
    }
}
