//! A LeRobot range value's motor ticks, read from the values themselves: LeRobot normalises an
//! integer tick t of a motor calibrated over [lo, hi] to ((t − lo)/(hi − lo))·200 − 100
//! (RANGE_M100_100), so every value a joint records lies on a lattice of 200/(hi − lo) from −100.
//! The lattice's spacing gives the calibrated range's width in ticks, all a range value needs to
//! become the motor's angle from the range's middle (`lerobot-format.md`: deg = value/100 ·
//! (hi − lo)/2 · 360/4095) — the calibration file's numbers, without the file.

/// A motor's ticks in a turn (the STS3215's 12-bit encoder): no calibrated range is wider.
const TICKS_PER_TURN: u32 = 4096;
/// The narrowest calibrated range looked for, ticks (22°: a joint calibrated over less is no arm's).
const NARROWEST: u32 = 256;
/// Distinct values needed before a spacing is believed: a wrong width fits a value by chance with
/// probability ≈ 2·TOLERANCE, so 24 values leave ≈ 1e-34 per width tried.
const FEWEST_VALUES: usize = 24;
/// How far from a whole tick a value may land, ticks: a value stored as float32 near ±100 is
/// within 8e-6 of LeRobot's, 1e-4 ticks at the widest range.
const TOLERANCE: f64 = 0.01;
/// At most this many distinct values are tested (evenly taken): the fit's cost stays bounded.
const MOST_VALUES: usize = 512;

/// The calibrated range's width in ticks (hi − lo) of a joint whose RANGE_M100_100 values are
/// `values`, or None where they do not tell it (too few distinct values, or no width fits).
pub fn range_width(values: &[f64]) -> Option<u32> {
    let mut distinct: Vec<f64> = values.iter().copied().filter(|v| v.is_finite() && v.abs() <= 100.0).collect();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();
    if distinct.len() < FEWEST_VALUES {
        return None;
    }
    let stride = distinct.len().div_ceil(MOST_VALUES);
    let tested: Vec<f64> = distinct.iter().step_by(stride).map(|v| (v + 100.0) / 200.0).collect();
    // the smallest width every value fits: a multiple of the true width fits too
    (NARROWEST..=TICKS_PER_TURN).find(|&width| {
        let width = f64::from(width);
        tested.iter().all(|fraction| {
            let tick = fraction * width;
            (tick - tick.round()).abs() <= TOLERANCE
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// LeRobot's normalisation of tick `t` over [lo, hi], stored as float32 as its datasets store it.
    fn normalised(t: i32, lo: i32, hi: i32) -> f64 {
        f64::from((f64::from(t - lo) / f64::from(hi - lo) * 200.0 - 100.0) as f32)
    }

    #[test]
    fn the_values_spacing_gives_the_calibrated_ranges_width() {
        for (lo, hi) in [(758, 3292), (1000, 3303), (912, 3117), (0, 4095), (1500, 2000)] {
            // a joint's wanderings over part of its range, ticks in no order
            let values: Vec<f64> = (0..400).map(|k| normalised(lo + (k * 37 % (hi - lo) / 2 + (hi - lo) / 4), lo, hi)).collect();
            assert_eq!(range_width(&values), Some((hi - lo) as u32), "range {lo}..{hi}");
        }
    }

    #[test]
    fn too_few_values_or_values_off_any_lattice_tell_nothing() {
        let few: Vec<f64> = (0..10).map(|t| normalised(1000 + t, 758, 3292)).collect();
        assert_eq!(range_width(&few), None);
        // values on no lattice of whole ticks from −100
        let off: Vec<f64> = (0..200).map(|k| 0.123 + f64::from(k) * 0.3779).collect();
        assert_eq!(range_width(&off), None);
    }
}
