//! A control step (kinematics, τ_g and C·q̇, controller, plant) allocates nothing, for the discrete
//! and the continuous plant, and with motors (PD on the drive trains, open-loop steppers). Counted
//! with a global allocator that tallies every allocation made on the test's own thread (the test
//! harness's threads allocate when they like).

mod common;

use armscope::config::RunConfig;
use armscope::actuator::StepperOutput;
use armscope::control::controller::ControlOutput;
use armscope::dynamics::{Data, forward_kinematics, frame_pose, gravity_and_bias_from_kinematics};
use armscope::experiment::Experiment;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    /// Allocations on this thread (a const-initialized Cell: reading it does not allocate).
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn allocations() -> usize {
    ALLOCATIONS.with(|a| a.get())
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // try_with: the thread-local may already be gone while a thread shuts down
        let _ = ALLOCATIONS.try_with(|a| a.set(a.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_in_steps(config: RunConfig) -> usize {
    let experiment = Experiment::prepare(config).unwrap();
    let model = &*experiment.model;
    let n = model.dof();
    let mut data = Data::new(model);
    let mut plant = experiment.make_plant();
    let controller = experiment.controller();
    // stepper mode: the open-loop steppers as the loop drives them
    let mut steppers = experiment.open_loop_steppers();
    let (mut q, mut v) = experiment.initial_state();
    let (mut cmd, mut cmd_dot, mut u, mut sat, mut limit) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![false; n], vec![0.0; n]);
    let (mut load_angle, mut lost, mut events) = (vec![0.0; n], vec![0i64; n], Vec::with_capacity(n));
    let mut step = |k: usize, q: &mut Vec<f64>, v: &mut Vec<f64>| {
        forward_kinematics(model, &mut data, q);
        gravity_and_bias_from_kinematics(model, &mut data, v);
        experiment.trajectory.sample(k as f64 * 0.001, &mut cmd, &mut cmd_dot);
        controller.compute(q, v, &cmd, &cmd_dot, &data.gravity, ControlOutput { u: &mut u, saturated: &mut sat, limit: &mut limit });
        std::hint::black_box(frame_pose(model, &data, model.tool_frame));
        match steppers.as_mut() {
            Some(s) => {
                s.control_step(&cmd, &cmd_dot, 0.001, q, v, StepperOutput { u: &mut u, limit: &mut limit, saturated: &mut sat, load_angle: &mut load_angle, lost_steps: &mut lost });
                plant.advance_driven(model, &mut data, &mut u, &mut |h, q, v, u| s.plant_step(h, q, v, u), q, v);
                s.update(q, k as f64 * 0.001, &mut events);
                events.clear();
            }
            None => plant.advance(model, &mut data, &u, q, v),
        }
    };
    step(0, &mut q, &mut v); // warm-up: nothing lazy left
    let before = allocations();
    for k in 1..500 {
        step(k, &mut q, &mut v);
    }
    allocations() - before
}

#[test]
fn discrete_and_continuous_steps_do_not_allocate() {
    let urdf = common::box_urdf();
    let discrete = allocations_in_steps(RunConfig { urdf: urdf.clone(), ..RunConfig::default() });
    let continuous = allocations_in_steps(RunConfig { urdf: urdf.clone(), time_step: Some(0.0), ..RunConfig::default() });
    // a step that passes a joint limit takes the active-set path
    let limited = allocations_in_steps(RunConfig { urdf, test_joint: Some("2".into()), test_angle: 3.0, ..RunConfig::default() });
    assert_eq!((discrete, continuous, limited), (0, 0, 0), "allocations in 499 steps: discrete, continuous, at a limit");
}

/// With motors too: the drive trains on the PD loop (their gear friction through the exact
/// stick–slip solve at every step) and the open-loop steppers (their torque at every plant step).
#[test]
fn steps_with_motors_do_not_allocate() {
    let motors = common::repo().join("assets/motors/tutorial.toml");
    let pd = allocations_in_steps(RunConfig { urdf: common::box_urdf(), motors: Some(motors.clone()), drive: armscope::config::DriveMode::Pd, ..RunConfig::default() });
    let steppers = allocations_in_steps(RunConfig { urdf: common::box_urdf(), motors: Some(motors), ..RunConfig::default() });
    assert_eq!((pd, steppers), (0, 0), "allocations in 499 steps: --drive pd, steppers");
}
