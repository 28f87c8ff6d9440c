//! The plots' colours, shared by the Rerun recording and the Foxglove layout: each joint's own, and
//! the colours that carry a meaning beside it in its plots (the target, τ_g, the limits, the flags),
//! chosen so that no series in a joint's plot takes the colour of another.

/// The joints' colours, in order: matplotlib's tab10 and lighter shades from its tab20, without
/// the colours the plots give a meaning (red: limits and saturation; grey: the target).
pub const JOINT_PALETTE: [(u8, u8, u8); 16] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (23, 190, 207),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (188, 189, 34),
    (174, 199, 232),
    (255, 187, 120),
    (152, 223, 138),
    (197, 176, 213),
    (255, 152, 150),
    (247, 182, 210),
    (219, 219, 141),
    (158, 218, 229),
];

/// The target in each angle plot.
pub const TARGET_RGB: (u8, u8, u8) = (140, 140, 140);
/// τ_g in each torque plot: near-white, which no joint's colour is.
pub const GRAVITY_TORQUE_RGB: (u8, u8, u8) = (235, 235, 235);
/// The ±limit lines, the saturated flag in the status plot and a stepper's lost steps in its plot.
pub const LIMIT_RGB: (u8, u8, u8) = (220, 50, 50);
/// The saturated steps' markers in each torque plot.
pub const SATURATED_RGB: (u8, u8, u8) = (230, 40, 40);
/// The chatter flag in the status plot.
pub const CHATTER_RGB: (u8, u8, u8) = (250, 210, 40);
/// Joint friction's torque in each torque plot (magenta: it was the fifth joint's purple).
pub const FRICTION_RGB: (u8, u8, u8) = (200, 0, 200);
/// The stuck flag (0/1) in each torque plot.
pub const STUCK_RGB: (u8, u8, u8) = (120, 120, 120);
/// A motor's shaft speed in its joint's stepper plot, beside the load angle in the joint's colour.
pub const MOTOR_SPEED_RGB: (u8, u8, u8) = (235, 235, 235);

/// A recording's measured effort in each torque plot (a replayed bag's), and its difference from
/// the model's torque (the friction and model error the arm really has).
pub const MEASURED_RGB: (u8, u8, u8) = (255, 160, 40);
pub const MEASURED_GAP_RGB: (u8, u8, u8) = (90, 200, 250);

/// A servo motor's current in its joint's servo plot, beside the duty in the joint's colour.
pub const CURRENT_RGB: (u8, u8, u8) = (235, 235, 235);

/// Joint `j`'s colour.
pub fn joint_rgb(j: usize) -> (u8, u8, u8) {
    JOINT_PALETTE[j % JOINT_PALETTE.len()]
}

/// A real follower's position beside joint `j`'s simulated one (a forward replay): the joint's
/// colour halfway to white (halfway to black for the palette's light ones), so it is told apart
/// from the joint's angle and still reads as that joint among the others.
pub fn observed_rgb(j: usize) -> (u8, u8, u8) {
    let (r, g, b) = joint_rgb(j);
    let light = (r as u16 + g as u16 + b as u16) / 3 > 160;
    let shift = |c: u8| if light { c / 2 } else { ((c as u16 + 255) / 2) as u8 };
    (shift(r), shift(g), shift(b))
}

/// "#rrggbb", as Foxglove's layouts write a colour.
pub fn hex((r, g, b): (u8, u8, u8)) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every series in a joint's plot is told apart from the others by its colour, for any of the
    /// 16 joint colours: at least 55 apart in RGB (Euclidean, 0–255 a channel). The colours this
    /// replaced were 16 apart (the fourth joint's torque and its red ±limits and saturated markers),
    /// 23 (the tenth joint's angle and its grey target), 45 (the second joint's error and the orange
    /// chatter flag), 12 (the fifth joint's torque and the purple friction), 0 (a stepper's load
    /// angle and its motor speed, both in the joint's colour) and green τ_g beside the third joint's
    /// green torque.
    #[test]
    fn each_series_in_a_joint_plot_has_a_colour_of_its_own() {
        let distance = |a: (u8, u8, u8), b: (u8, u8, u8)| ((a.0 as f64 - b.0 as f64).powi(2) + (a.1 as f64 - b.1 as f64).powi(2) + (a.2 as f64 - b.2 as f64).powi(2)).sqrt();
        for (j, &joint) in JOINT_PALETTE.iter().enumerate() {
            // angle vs target; torque, τ_g, ±limits, saturated markers, friction and stuck; error,
            // saturated, chatter; a stepper's load angle, lost steps (red) and motor speed; a servo's
            // duty and current
            let plots = [
                ("angle", vec![joint, TARGET_RGB, observed_rgb(j)]),
                ("torque", vec![joint, GRAVITY_TORQUE_RGB, LIMIT_RGB, SATURATED_RGB, FRICTION_RGB, STUCK_RGB]),
                ("status", vec![joint, LIMIT_RGB, CHATTER_RGB]),
                ("stepper", vec![joint, LIMIT_RGB, MOTOR_SPEED_RGB]),
                ("servo", vec![joint, CURRENT_RGB]),
            ];
            for (plot, colours) in plots {
                for (a, &first) in colours.iter().enumerate() {
                    // (the limits and the saturated markers are the same signal: red)
                    for &second in colours[a + 1..].iter().filter(|&&c| !(first == LIMIT_RGB && c == SATURATED_RGB)) {
                        let apart = distance(first, second);
                        assert!(apart >= 55.0, "joint {j}'s {plot} plot: {first:?} and {second:?} are {apart:.0} apart");
                    }
                }
            }
        }
    }

    #[test]
    fn a_colour_in_hex_is_foxgloves_form() {
        assert_eq!(hex((31, 119, 180)), "#1f77b4");
        assert_eq!(hex((0, 10, 255)), "#000aff");
    }
}
