//! The supply on which each of the catalogue's servos of a family would hold as stiff as a fitted
//! one: what a user holds against the supply on their desk. A servo's position loop pushes
//! e_g·k_p·(k_t/R)·V per rad of error; at one firmware (the same e_g and k_p) servos differ by
//! their motor's k_t/R, which the datasheet gives as the stall torque per volt at its rating point
//! (the stall current is V/R). So servo B holds as stiff as ×s of servo A on V_A on the supply
//! V_B = s·V_A·(τ_A/V_A,rated)/(τ_B/V_B,rated).

use crate::actuator::Catalogue;
use crate::actuator::catalogue::number;

/// One catalogue servo and the supply on which it would hold as the fitted servo does, V.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct EquivalentSupply {
    pub servo: String,
    pub supply_v: f64,
}

/// A catalogue entry's firmware family and its datasheet's stall torque per volt, N·m/V (None: no
/// firmware model, a variant of another entry, or no stall torque and voltage).
fn torque_per_volt(entry: &toml::Table) -> Option<(&str, f64)> {
    if entry.contains_key("variant_of") {
        return None;
    }
    let family = entry.get("firmware")?.as_table()?.get("family")?.as_str()?;
    let (stall, volts) = (number(entry, "stall_torque")?, number(entry, "voltage")?);
    (stall > 0.0 && volts > 0.0).then_some((family, stall / volts))
}

/// For each of `catalogue`'s servos of the family of `start` (a catalogue name, run on `supply` V),
/// the supply on which it holds `holding_stiffness` × as stiff as `start` on `supply` does, by
/// name; empty where the catalogue has no datasheet point for `start`.
pub fn equivalent_supplies(catalogue: &Catalogue, start: &str, supply: f64, holding_stiffness: f64) -> Vec<EquivalentSupply> {
    let Some((family, start_per_volt)) = catalogue.entries.get(start).and_then(torque_per_volt) else { return Vec::new() };
    catalogue
        .entries
        .iter()
        .filter_map(|(name, entry)| {
            let (f, per_volt) = torque_per_volt(entry)?;
            (f == family).then(|| EquivalentSupply { servo: name.clone(), supply_v: holding_stiffness * supply * start_per_volt / per_volt })
        })
        .collect()
}

/// The supplies in words: "STS3215-C001 on 3.3 V, STS3215-C018 on 4.4 V".
pub fn text(supplies: &[EquivalentSupply]) -> String {
    supplies.iter().map(|s| format!("{} on {:.1} V", s.servo, s.supply_v)).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_servo_held_at_a_fraction_of_its_stiffness_is_matched_by_the_datasheets_torque_per_volt() {
        let catalogue = Catalogue::load(std::path::Path::new(crate::actuator::catalogue::DEFAULT_CATALOGUE)).unwrap();
        let supplies = equivalent_supplies(&catalogue, "STS3215-C018", 12.0, 0.5);
        let on = |name: &str| supplies.iter().find(|s| s.servo == name).map(|s| s.supply_v);
        // the same servo at half the stiffness: half the supply
        assert!((on("STS3215-C018").unwrap() - 6.0).abs() < 1e-12, "{supplies:?}");
        // the 7.4 V C001 (1.91 N·m at 6 V) against the 12 V C018 (2.94 N·m at 12 V), catalogue-sources.md §2
        assert!((on("STS3215-C001").unwrap() - 0.5 * 12.0 * (2.94 / 12.0) / (1.91 / 6.0)).abs() < 1e-12, "{supplies:?}");
        // a variant of the C018 (the same motor, BAM's parameters) is not another servo; other families are not listed
        assert!(supplies.iter().all(|s| s.servo.starts_with("STS3215-") && catalogue.variant_of(&s.servo).is_none()), "{supplies:?}");
        assert_eq!(text(&supplies[..1]), format!("{} on {:.1} V", supplies[0].servo, supplies[0].supply_v));
        // a servo the catalogue has no datasheet point for: nothing to say
        assert!(equivalent_supplies(&catalogue, "no such servo", 12.0, 0.5).is_empty());
    }
}
