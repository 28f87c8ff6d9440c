//! Stepper mode (`--motors` with steppers): open-loop steppers against the physics they must show.
//! The box model with the tutorial's motor file (a 17HS19-2004S1, 0.59 N·m, through 15:1 on J1–J3 and
//! a 17HS4401, 0.40 N·m, through 5:1 on J4–J6, 90 % efficient) and with the real SmallRobotArm's
//! reductions.

mod common;

use armscope::config::{DriveMode, RunConfig};
use armscope::dynamics::{Data, gravity_forces, rnea};
use armscope::experiment::Experiment;
use armscope::recorder::{Recorder, RunInfo};
use armscope::sample::Sample;
use armscope::sim::simulate;
use armscope::summary::{RunStatus, Summary};

fn config(motors: &str, extra: impl FnOnce(&mut RunConfig)) -> RunConfig {
    let mut c = RunConfig { urdf: common::box_urdf(), motors: Some(common::repo().join("assets/motors").join(motors)), ..RunConfig::default() };
    extra(&mut c);
    c
}

#[derive(Default)]
struct Positions {
    rows: Vec<(f64, Vec<f64>, Vec<i64>)>,
    /// The last sample's torques and stuck flags.
    last_u: Vec<f64>,
    last_stuck: Vec<bool>,
}

impl Recorder for Positions {
    fn start(&mut self, _: &RunInfo) -> Result<(), armscope::error::Error> {
        Ok(())
    }
    fn record(&mut self, s: &Sample) -> Result<(), armscope::error::Error> {
        self.rows.push((s.t, s.q.to_vec(), s.lost_steps.to_vec()));
        self.last_u = s.u.to_vec();
        self.last_stuck = s.stuck.to_vec();
        Ok(())
    }
    fn finish(&mut self, _: &RunInfo, _: &Summary) -> Result<(), armscope::error::Error> {
        Ok(())
    }
}

/// Holding the arm out horizontally (every joint commanded to 0): each stepper sags by a load angle
/// that carries its share of the weight and loses no step while the weight is within its holding
/// torque (J2 needs 4.43 of its 8.0 N·m). The rotor rings about that angle until the gearbox's
/// friction holds it: at rest each loaded joint is stuck with the motor's torque u (field and detent)
/// within the gear's holding band, η_b·G ≤ u ≤ G/η (G the weight's torque, η = η_b = 0.9: the
/// friction takes up to 10 % of u against a load it back-drives and helps hold one that pushes) —
/// to the solve's rounding, 1e-9 relative.
#[test]
fn a_stepper_holding_the_arm_sags_by_the_load_angle_that_carries_the_weight_and_loses_nothing() {
    let experiment = Experiment::prepare(config("tutorial.toml", |c| {
        c.hold = true;
        c.q0 = Some("0,0,0,0,0,0".into());
        c.duration = 6.0;
    }))
    .unwrap();
    let mut rec = Positions::default();
    let summary = simulate(&experiment, &mut [&mut rec], None).unwrap();
    assert_eq!(summary.lost_steps, [0, 0, 0, 0, 0, 0]);
    let last = &rec.rows.last().unwrap().1;
    let tau_g = gravity_forces(&experiment.model, &mut Data::new(&experiment.model), last).to_vec();
    for j in 1..5 {
        let weight = -tau_g[j];
        assert!(rec.last_stuck[j], "J{} rests, held by its gear's friction", j + 1);
        let share = rec.last_u[j] / weight;
        assert!((0.9 * (1.0 - 1e-9)..=(1.0 + 1e-9) / 0.9).contains(&share), "J{}: u = {} against the weight's {weight}: {share} of it", j + 1, rec.last_u[j]);
        assert!(last[j] * weight < 0.0, "J{} sags with the weight", j + 1);
    }
    assert!(last[1].abs() > 5e-4, "J2 sags visibly (asin(0.9·4.43/8.85)/750 = 0.62 mrad at least): {}", last[1]);
}

/// The same pose with the real SmallRobotArm's reductions: J2's stepper (4:1, 1.52 N·m) cannot
/// carry the 4.43 N·m: it slips and keeps slipping.
#[test]
fn a_stepper_slips_when_the_weight_is_beyond_its_holding_torque() {
    let experiment = Experiment::prepare(config("smallrobotarm.toml", |c| {
        c.hold = true;
        c.q0 = Some("0,0,0,0,0,0".into());
        c.duration = 2.0;
    }))
    .unwrap();
    let summary = simulate(&experiment, &mut [], None).unwrap();
    assert!(summary.lost_steps[1] >= 4, "J2 lost {} steps", summary.lost_steps[1]);
    assert!(summary.first_lost_step_time[1].unwrap() < 0.5);
    assert_eq!(summary.lost_steps[0], 0, "J1 (vertical axis) carries no weight");
}

/// Peak torque the commanded motion needs (inverse dynamics of cmd, cmd_dot and a numerical cmd_ddot)
/// against what the drive train gives at the commanded speed, per joint: the worst ratio.
fn demand_over_supply(experiment: &Experiment) -> Vec<f64> {
    let model = &experiment.model;
    let motors = experiment.motors.as_ref().unwrap();
    let mut data = Data::new(model);
    let (h, n) = (1e-4, model.dof());
    let mut worst = vec![0.0f64; n];
    let (mut c0, mut d0, mut c1, mut d1) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for k in 0..(experiment.config.duration / 0.002) as usize {
        let t = k as f64 * 0.002;
        experiment.trajectory.sample(t, &mut c0, &mut d0);
        experiment.trajectory.sample(t + h, &mut c1, &mut d1);
        let a: Vec<f64> = d0.iter().zip(&d1).map(|(x, y)| (y - x) / h).collect();
        let tau = rnea(model, &mut data, &c0, &d0, &a).to_vec();
        for j in 0..n {
            let supply = motors.joints[j].as_ref().unwrap().torque_limit(d0[j]);
            worst[j] = worst[j].max(tau[j].abs() / supply);
        }
    }
    worst
}

/// The energy audit books every plant step of stepper mode (the torque changes at each): the arm's
/// mechanical energy changes by the work of the steppers and the damping, to 0.1 % of that work
/// (measured: 5e-6 of it on the slow wave, the discrete plant's own error; the servo-mode default run
/// balances to 1.4e-4).
fn energy_balances(summary: &Summary) {
    let books = summary.energy_balance.expect("the discrete plant is audited");
    assert!(books.work > 1.0, "the steppers did work: {books:?}");
    assert!(books.created.abs() <= 1e-3 * books.work, "energy created {:.3e} J against {:.3} J of work", books.created, books.work);
}

/// The default wave (0.5 rad/s) is within every joint's pull-out curve and loses nothing; at
/// `--freq 5.5` J2, whose demand reaches 82 % of its curve, loses steps — already below 100 %, and
/// early, as its step generator starts the wave from rest: the rotor rings about its mean load angle
/// whenever the motion's acceleration changes, which is why steppers are sized with ~30 % headroom
/// (J2 slips there from 3 rad/s, 57 % of its curve) — and the joints that need less than half their
/// torque lose none of their own accord after the start's catch-up (once J2 slips and the arm swings off its command, others can
/// be dragged out of step too).
#[test]
fn a_slow_wave_within_the_pull_out_curve_loses_nothing_a_fast_one_loses_steps_where_demand_exceeds_it() {
    let slow = Experiment::prepare(config("tutorial.toml", |c| c.duration = 10.0)).unwrap();
    assert!(demand_over_supply(&slow).iter().all(|&r| r < 1.0), "{:?}", demand_over_supply(&slow));
    let summary = simulate(&slow, &mut [], None).unwrap();
    assert_eq!(summary.lost_steps, [0, 0, 0, 0, 0, 0], "slow wave");
    assert!(matches!(summary.status, RunStatus::Completed));
    energy_balances(&summary);

    let fast = Experiment::prepare(config("tutorial.toml", |c| {
        c.duration = 10.0;
        c.freq = 5.5;
    }))
    .unwrap();
    let ratio = demand_over_supply(&fast);
    let summary = simulate(&fast, &mut [], None).unwrap();
    energy_balances(&summary);
    for j in 0..6 {
        if ratio[j] > 0.8 {
            assert!(summary.lost_steps[j] > 0, "J{} needs {:.2}× its curve and loses nothing", j + 1, ratio[j]);
        }
        if ratio[j] < 0.5 {
            // a joint within its curve loses nothing of its own accord: only once J2 slips and the
            // arm swings off its command can it be dragged out of step — or in the start's catch-up
            // (the wave starts at 2.9 rad/s, the arm at rest: not in the ratio), where J4, at 0.46 of
            // its curve, slips once (4 full steps) at 27 ms with its gearbox's friction and not
            // without it
            if summary.first_lost_step_time[j].is_some_and(|t| t < 0.1) && summary.lost_steps[j] <= 4 {
                continue;
            }
            if let Some(t) = summary.first_lost_step_time[j] {
                let j2 = summary.first_lost_step_time[1].expect("J2 slips");
                assert!(t > j2 + 1.0, "J{} needs only {:.2}× its curve yet lost steps at {t} s, J2 first at {j2} s", j + 1, ratio[j]);
            }
        }
    }
    assert!(ratio[1] > 0.8 && ratio.iter().enumerate().all(|(j, &r)| j == 1 || r < 0.5), "{ratio:?}");
}

/// `--drive pd` runs the tutorial's PD controller on the steppers' pull-out limit instead: no open
/// loop, no lost steps counted; the run completes and the energy books balance with the motors'
/// rotors and limits.
#[test]
fn drive_pd_runs_the_pd_loop_on_the_pull_out_limit_and_the_energy_audit_balances() {
    let experiment = Experiment::prepare(config("tutorial.toml", |c| {
        c.drive = DriveMode::Pd;
        c.duration = 10.0;
    }))
    .unwrap();
    assert!(!experiment.stepper_mode());
    assert!(experiment.open_loop_steppers().is_none());
    let summary = simulate(&experiment, &mut [], None).unwrap();
    assert!(matches!(summary.status, RunStatus::Completed), "{:?}", summary.status);
    assert_eq!(summary.lost_steps, [0, 0, 0, 0, 0, 0]);
    energy_balances(&summary);
}

/// The lost steps and load angles are in both recordings, the summary JSON names them, and the
/// console says in words which joint lost steps and when.
#[test]
fn lost_steps_and_load_angles_are_in_both_recordings_and_the_summary() {
    let dir = tempfile::tempdir().unwrap();
    let (rrd, mcap, json) = (dir.path().join("s.rrd"), dir.path().join("s.mcap"), dir.path().join("s.json"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
        .args(["run", "--motors", common::repo().join("assets/motors/smallrobotarm.toml").to_str().unwrap(), "--urdf", common::box_urdf().to_str().unwrap(), "--duration", "1"])
        .args(["--rrd", rrd.to_str().unwrap(), "--mcap", mcap.to_str().unwrap(), "--summary-json", json.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("lost steps (full)") && stdout.contains("J2: its stepper lost"), "{stdout}");
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let lost_j2 = summary["summary"]["lost_steps"][1].as_u64().unwrap();
    assert!(lost_j2 > 0);
    let rrd = common::rrd::Rrd::open(&rrd);
    let lost = rrd.series("/joints/J2/lost_steps");
    let angle = rrd.series("/joints/J2/load_angle");
    assert_eq!((lost.len(), angle.len()), (1001, 1001), "one row per step");
    assert!(angle.iter().all(|(_, a)| a[0].abs() <= 180.0));
    assert!(lost.last().unwrap().1[0].abs() > 0.0, "the count reached the end of the run");
    let bytes = std::fs::read(&mcap).unwrap();
    let last = mcap::MessageStream::new(&bytes).unwrap().map(|m| m.unwrap()).filter(|m| m.channel.topic == "/controller").last().unwrap();
    let schema = last.channel.schema.clone().unwrap();
    let pool = prost_reflect::DescriptorPool::decode(&schema.data[..]).unwrap();
    let v = prost_reflect::DynamicMessage::decode(pool.get_message_by_name(&schema.name).unwrap(), &last.data[..]).unwrap();
    let steps = v.get_field_by_name("lost_steps").unwrap().as_list().unwrap().to_vec();
    assert_eq!(steps[1].as_i64().unwrap(), lost.last().unwrap().1[0] as i64, "the MCAP's count is the .rrd's");
}

/// The bar from the command line: `--static` loses no steps; `--freq 8 --amp-deg 60` loses
/// steps and the summary says on which joint and when.
#[test]
fn static_loses_nothing_and_a_fast_wide_wave_is_reported_where_and_when() {
    let motors = common::repo().join("assets/motors/tutorial.toml");
    let run = |extra: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_armscope"))
            .args(["run", "--urdf", common::box_urdf().to_str().unwrap(), "--motors", motors.to_str().unwrap(), "--duration", "5", "--no-rrd", "--no-mcap"])
            .args(extra)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).to_string()
    };
    let held = run(&["--static"]);
    assert!(!held.contains("lost steps (full)") && !held.contains("its stepper lost"), "{held}");
    let fast = run(&["--freq", "8", "--amp-deg", "60"]);
    assert!(fast.contains("lost steps (full)"), "{fast}");
    let said = fast.lines().find(|l| l.contains("its stepper lost")).unwrap_or_else(|| panic!("{fast}"));
    assert!(said.contains("full steps, the first at t = "), "{said}");
}

/// A plant step too long for the steppers' oscillation is allowed but said: at 1 ms the slow default
/// wave, which loses nothing when resolved, would report lost steps.
#[test]
fn a_plant_step_too_long_for_the_steppers_is_a_notice() {
    let experiment = Experiment::prepare(config("tutorial.toml", |c| c.time_step = Some(0.001))).unwrap();
    assert!(experiment.model.notices.iter().any(|n| n.contains("--time-step 1 ms is longer than") && n.contains("not to be trusted")), "{:?}", experiment.model.notices);
    let resolved = Experiment::prepare(config("tutorial.toml", |_| {})).unwrap();
    assert!(matches!(resolved.plant, armscope::experiment::PlantSpec::Discrete { substeps, .. } if substeps > 1));
    assert!(!resolved.model.notices.iter().any(|n| n.contains("not to be trusted")));
}



/// A command that accelerates faster than a joint's step generator may is said in a notice naming
/// the joint (the joint then trails its command without losing steps): `--freq 6` asks J2 for
/// 0.52·36 = 18.8 rad/s², its generator allows 12.3; the default wave (0.13 rad/s²) is within every one.
#[test]
fn a_command_faster_than_the_step_generator_is_a_notice() {
    let fast = Experiment::prepare(config("tutorial.toml", |c| c.freq = 6.0)).unwrap();
    let said: Vec<&String> = fast.model.notices.iter().filter(|n| n.contains("the joint will lag its command")).collect();
    assert_eq!(said.len(), 1, "{:?}", fast.model.notices);
    assert!(said[0].contains("joint 'J2'") && said[0].contains("`acceleration`"), "{}", said[0]);
    let slow = Experiment::prepare(config("tutorial.toml", |_| {})).unwrap();
    assert!(!slow.model.notices.iter().any(|n| n.contains("lag its command")), "{:?}", slow.model.notices);
}
