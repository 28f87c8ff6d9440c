//! sin x and cos x together, for the angles a stepper's field turns through: its rotor's electrical
//! angle (50 periods a turn of the motor, hundreds to thousands of radians at a joint's travel),
//! worked out for every stepper joint at every plant step. One evaluation gives both, the second
//! for four more products, so the field's pull (the sine of the command's phase less the rotor's) and
//! the detent's (four periods to the rotor's one) cost one evaluation between them, not two sines.
//!
//! x = n·π/32 + r with |r| ≤ π/64 (π/32 in three parts, so that n·π/32 is exact to far below an ulp
//! of r); sin r and cos r − 1 are their Taylor series to r⁹ and r⁸, whose next terms are below
//! 10⁻¹⁹ there; the tabled sine and cosine of n·π/32 turn them by the angle addition formulas.
//! Within 2 ulp of 1 of `f64::sin_cos`.

/// 32/π.
const PER_STEP: f64 = 10.185916357881302;
/// π/32 in three parts of 27 significant bits or fewer: n·STEP_HIGH and n·STEP_MIDDLE are exact for
/// |n| < 2²⁶.
const STEP_HIGH: f64 = f64::from_bits(0x3fb9_21fb_5400_0000);
const STEP_MIDDLE: f64 = f64::from_bits(0x3dd1_0b46_1000_0000);
const STEP_LOW: f64 = f64::from_bits(0x3c1a_6263_3145_c06e);
/// 2²⁶·π/32, rounded down: beyond, the library takes over (and NaN and ∞).
const REDUCED_EXACTLY_BELOW: f64 = 6_588_397.0;
/// Adding and taking away 1.5·2⁵² rounds a double below 2⁵¹ to the nearest whole number, ties to
/// even; the sum's lowest mantissa bits are that number's, modulo their power of two.
const ROUNDING: f64 = 6_755_399_441_055_744.0;

/// sin(jπ/32) for j = 0…16, correctly rounded (worked out to 80 digits).
const QUARTER: [f64; 17] = [
    0.0,
    0.0980171403295606,
    0.19509032201612828,
    0.2902846772544624,
    0.3826834323650898,
    0.47139673682599764,
    0.5555702330196022,
    0.6343932841636455,
    std::f64::consts::FRAC_1_SQRT_2,
    0.773010453362737,
    0.8314696123025452,
    0.881921264348355,
    0.9238795325112867,
    0.9569403357322088,
    0.9807852804032304,
    0.9951847266721969,
    1.0,
];

/// [sin, cos] of jπ/32, j = 0…63: the quarter turned by each quadrant.
static CIRCLE: [[f64; 2]; 64] = circle();

const fn circle() -> [[f64; 2]; 64] {
    let mut table = [[0.0; 2]; 64];
    let mut j = 0;
    while j < 64 {
        let i = j % 16;
        let (sin, cos) = (QUARTER[i], QUARTER[16 - i]);
        table[j] = match j / 16 {
            0 => [sin, cos],
            1 => [cos, -sin],
            2 => [-sin, -cos],
            _ => [-cos, sin],
        };
        j += 1;
    }
    table
}

/// (sin x, cos x), each within 2 ulp of 1 of the library's.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if !(x.abs() < REDUCED_EXACTLY_BELOW) {
        return x.sin_cos();
    }
    let shifted = x * PER_STEP + ROUNDING;
    let [sin_n, cos_n] = CIRCLE[(shifted.to_bits() & 63) as usize];
    let n = shifted - ROUNDING;
    let r = ((x - n * STEP_HIGH) - n * STEP_MIDDLE) - n * STEP_LOW;
    let r2 = r * r;
    let sin_r = r + r * r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0 + r2 * (1.0 / 362_880.0))));
    let cos_r_less_1 = r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 * (1.0 / 40_320.0))));
    // the tabled values plus small corrections, summed last
    (sin_n + (sin_n * cos_r_less_1 + cos_n * sin_r), cos_n + (cos_n * cos_r_less_1 - sin_n * sin_r))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two ulp of 1: the library is within one of the true values, this within one more (the
    /// rounding of its series and sums).
    const WITHIN: f64 = 2.0 * f64::EPSILON;

    fn worst_difference(angles: impl Iterator<Item = f64>) -> f64 {
        angles.fold(0.0, |worst: f64, x| {
            let ((sin, cos), (library_sin, library_cos)) = (sin_cos(x), x.sin_cos());
            worst.max((sin - library_sin).abs()).max((cos - library_cos).abs())
        })
    }

    #[test]
    fn agrees_with_the_library_over_the_angles_a_stepper_sees() {
        // a 50-tooth rotor through a 100:1 gear turning a joint ±10 rad: |x| up to 50 000, and the
        // many angles near zero where the lag lives
        let wide = worst_difference((-3_650_000..3_650_000).map(|k| k as f64 * 0.0137));
        let near = worst_difference((-200_000..200_000).map(|k| k as f64 * 1.3e-5));
        assert!(wide <= WITHIN && near <= WITHIN, "largest differences {wide:e}, {near:e}");
    }

    #[test]
    fn its_table_is_the_sine_and_cosine_of_each_32nd_of_a_half_turn() {
        for (j, [sin, cos]) in CIRCLE.iter().enumerate() {
            let (library_sin, library_cos) = (j as f64 * std::f64::consts::PI / 32.0).sin_cos();
            // the library's angle j·π/32 is rounded to a double: within 2 ulp of 6.2 of the true one
            assert!((sin - library_sin).abs() <= 2e-15 && (cos - library_cos).abs() <= 2e-15, "j = {j}");
            assert!((sin * sin + cos * cos - 1.0).abs() <= WITHIN, "j = {j}");
        }
    }

    #[test]
    fn is_exact_where_the_values_are_known() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        assert!(sin_cos(std::f64::consts::FRAC_PI_2).1.abs() < 1e-16);
        assert_eq!(sin_cos(std::f64::consts::FRAC_PI_2).0, 1.0);
        assert_eq!(sin_cos(-std::f64::consts::FRAC_PI_2).0, -1.0);
        let tiny = 1e-200;
        assert_eq!(sin_cos(tiny), (tiny, 1.0));
    }

    #[test]
    fn hands_angles_it_cannot_reduce_to_the_library() {
        for x in [6.6e6, -3e9, 1e300] {
            assert_eq!(sin_cos(x), x.sin_cos());
        }
        assert!(sin_cos(f64::NAN).0.is_nan() && sin_cos(f64::INFINITY).1.is_nan());
    }
}
