//! A Feetech servo's firmware protections, as its memory table describes them: the overload
//! protection (a load above Overload_Torque held for Protection_Time limits the output to
//! Protective_Torque) and the overcurrent protection (a current above Protection_Current held for
//! the overcurrent protection time unloads the servo: torque off).
//!
//! Feetech's "load" is the PWM duty the firmware drives the motor with (its memory table's present
//! load: "the voltage duty cycle of the current control output driving motor"; torque settings are
//! in the same units, 1000 = 100 %), so both torque thresholds are duties here. The table gives no
//! condition under which a tripped protection releases: once tripped it holds for the rest of the
//! run (a real servo clears it when its torque is switched off and on, or it is powered again).
//! Dynamixel servos shut down on overload too, but their manuals give no threshold or time: none
//! is modelled for them.

use serde::{Deserialize, Serialize};

/// The overload protection: |duty| ≥ `threshold` for `time` s limits the duty to `protective`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Overload {
    pub threshold: f64,
    pub time: f64,
    pub protective: f64,
}

/// The overcurrent protection: |current| ≥ `current` A for `time` s switches the torque off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Overcurrent {
    pub current: f64,
    pub time: f64,
}

/// A servo's protections (none for a family whose thresholds are not published).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Protection {
    pub overload: Option<Overload>,
    pub overcurrent: Option<Overcurrent>,
}

/// The memory table's units: torques in % of the largest (duty 1), times in 10 ms, the current in
/// 6.5 mA.
pub const PERCENT: f64 = 0.01;
pub const TIME_UNIT: f64 = 0.010;
pub const CURRENT_UNIT: f64 = 0.0065;

/// A Feetech STS servo's protections out of the box.
pub const FEETECH_FACTORY: Protection = Protection {
    overload: Some(Overload { threshold: 80.0 * PERCENT, time: 200.0 * TIME_UNIT, protective: 20.0 * PERCENT }),
    overcurrent: Some(Overcurrent { current: 500.0 * CURRENT_UNIT, time: 200.0 * TIME_UNIT }),
};

/// Where [`FEETECH_FACTORY`]'s numbers were read.
pub const FEETECH_SOURCE: &str = "Feetech ST3215 memory table, initial values, as transcribed in Mickael-Roger/python-st3215 README.md \
    \"ST3215 registers\": Unloading conditions (0x13) 44 (bits Temperature, Current, Overload enabled), Protection current (0x1C) 500 \
    × 6.5 mA, Protection torque (0x22) 20 %, Protection time (0x23) 200 × 10 ms, Overload torque (0x24) 80 %, Overcurrent \
    protection time (0x26) 200 × 10 ms; present load (0x3C) is the output duty";

/// Which protection tripped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TripKind {
    Overload,
    Overcurrent,
}

impl TripKind {
    pub fn name(self) -> &'static str {
        match self {
            TripKind::Overload => "overload",
            TripKind::Overcurrent => "overcurrent",
        }
    }
}

/// A protection that tripped: which, when its condition began and when it tripped (s from the
/// start), its threshold (a duty, or A) and time, and the duty it leaves (0: torque off).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Trip {
    pub kind: TripKind,
    pub since: f64,
    pub time: f64,
    pub threshold: f64,
    pub hold: f64,
    pub leaves_duty: f64,
}

impl Trip {
    /// In words: what tripped, when, on what, and what the servo does after.
    pub fn describe(&self) -> String {
        match self.kind {
            TripKind::Overload => format!(
                "its overload protection trips at t = {:.2} s (duty at or above {:.0} % from t = {:.2} s, for {:.1} s): it then gives at most {:.0} % duty",
                self.time,
                100.0 * self.threshold,
                self.since,
                self.hold,
                100.0 * self.leaves_duty
            ),
            TripKind::Overcurrent => format!(
                "its overcurrent protection trips at t = {:.2} s (current at or above {:.2} A from t = {:.2} s, for {:.1} s): it then switches its torque off",
                self.time, self.threshold, self.since, self.hold
            ),
        }
    }
}

/// The protections' timers between firmware ticks.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProtectionState {
    /// Time since the first tick, s.
    clock: f64,
    overload_since: Option<f64>,
    overcurrent_since: Option<f64>,
    pub trip: Option<Trip>,
}

impl Protection {
    pub const NONE: Protection = Protection { overload: None, overcurrent: None };

    pub fn is_none(&self) -> bool {
        self.overload.is_none() && self.overcurrent.is_none()
    }

    /// The largest duty the firmware may give now: the protective duty once the overload
    /// protection has tripped, `max_duty` otherwise.
    #[inline]
    pub fn duty_limit(&self, state: &ProtectionState, max_duty: f64) -> f64 {
        match (state.trip, self.overload) {
            (Some(Trip { kind: TripKind::Overload, .. }), Some(o)) => o.protective.min(max_duty),
            _ => max_duty,
        }
    }

    /// Whether the overcurrent protection has unloaded the servo.
    #[inline]
    pub fn torque_off(&self, state: &ProtectionState) -> bool {
        matches!(state.trip, Some(Trip { kind: TripKind::Overcurrent, .. }))
    }

    /// Advance the timers by `dt` s over which the servo gives `duty` and draws `current` A; the
    /// trip when one happens in it (at the instant its condition has lasted its time).
    #[inline]
    pub fn update(&self, state: &mut ProtectionState, duty: f64, current: f64, dt: f64) -> Option<Trip> {
        let start = state.clock;
        state.clock += dt;
        if state.trip.is_some() {
            return None;
        }
        let end = state.clock;
        let overload = self.overload.and_then(|o| {
            let (since, time) = timer(&mut state.overload_since, duty.abs() >= o.threshold, start, end, o.time)?;
            Some(Trip { kind: TripKind::Overload, since, time, threshold: o.threshold, hold: o.time, leaves_duty: o.protective })
        });
        let overcurrent = self.overcurrent.and_then(|o| {
            let (since, time) = timer(&mut state.overcurrent_since, current.abs() >= o.current, start, end, o.time)?;
            Some(Trip { kind: TripKind::Overcurrent, since, time, threshold: o.current, hold: o.time, leaves_duty: 0.0 })
        });
        // both in one tick: the first to trip
        let trip = match (overload, overcurrent) {
            (Some(a), Some(b)) => Some(if b.time < a.time { b } else { a }),
            (a, b) => a.or(b),
        };
        state.trip = trip;
        trip
    }

    /// The first trip over a series: `duty[k]` and `current[k]` held from `time[k]` to `time[k+1]`.
    pub fn first_trip(&self, time: &[f64], duty: &[f64], current: &[f64]) -> Option<Trip> {
        let mut state = ProtectionState { clock: time.first().copied().unwrap_or(0.0), ..Default::default() };
        (0..time.len().saturating_sub(1)).find_map(|k| self.update(&mut state, duty[k], current[k], time[k + 1] - time[k]))
    }
}

/// One protection's timer over [start, end]: its condition held since `since`; Some((since, when))
/// once it has held for `hold` s.
#[inline]
fn timer(since: &mut Option<f64>, condition: bool, start: f64, end: f64, hold: f64) -> Option<(f64, f64)> {
    if !condition {
        *since = None;
        return None;
    }
    let began = *since.get_or_insert(start);
    // within a rounding of the clock's sum the hold is reached
    (end - began >= hold - 1e-9 * hold.max(1.0)).then_some((began, began + hold))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overload_trips_after_its_time_above_the_threshold_and_limits_the_duty() {
        let p = FEETECH_FACTORY;
        let mut state = ProtectionState::default();
        let dt = 0.001;
        let mut tripped = None;
        for k in 0..5000 {
            // under the threshold for the first second, then at 90 %
            let duty = if k < 1000 { 0.7 } else { 0.9 };
            if let Some(t) = p.update(&mut state, duty, 1.0, dt) {
                tripped = Some(t);
                break;
            }
        }
        let trip = tripped.expect("tripped");
        assert_eq!(trip.kind, TripKind::Overload);
        assert!((trip.since - 1.0).abs() < 1e-9 && (trip.time - 3.0).abs() < 1e-9, "{trip:?}");
        assert!((p.duty_limit(&state, 0.97) - 0.2).abs() < 1e-15);
        assert!(!p.torque_off(&state));
    }

    #[test]
    fn a_dip_below_the_threshold_restarts_the_timer() {
        let p = FEETECH_FACTORY;
        let time: Vec<f64> = (0..=400).map(|k| k as f64 * 0.01).collect();
        // 1.5 s over, one sample under, then over again
        let duty: Vec<f64> = (0..=400).map(|k| if k == 150 { 0.5 } else { 0.85 }).collect();
        let current = vec![0.5; time.len()];
        let trip = p.first_trip(&time, &duty, &current).unwrap();
        assert!((trip.since - 1.51).abs() < 1e-9 && (trip.time - 3.51).abs() < 1e-9, "{trip:?}");
    }

    #[test]
    fn overcurrent_unloads_the_servo() {
        let p = FEETECH_FACTORY;
        let mut state = ProtectionState::default();
        let trip = (0..300).find_map(|_| p.update(&mut state, 0.5, 3.3, 0.01)).unwrap();
        assert_eq!(trip.kind, TripKind::Overcurrent);
        assert!((trip.time - 2.0).abs() < 1e-9);
        assert!(p.torque_off(&state));
        assert!(Protection::NONE.first_trip(&[0.0, 5.0], &[1.0, 1.0], &[9.0, 9.0]).is_none());
    }
}
