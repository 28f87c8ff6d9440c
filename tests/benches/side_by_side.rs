//! armscope's ABA, RNEA, CRBA and discrete step timed exactly as `.ci/bench-reference/pinocchio_step`
//! times Pinocchio's (each call repeated until 0.3 s have passed, best of 5 such rounds), with the
//! same output line, so the two can be run in turn on one machine and compared line by line:
//!   cargo bench --bench side_by_side -- URDF...   →   name nv aba_us rnea_us crba_us step_us
//! This machine's speed drifts by tens of percent within minutes; criterion's `dynamics` bench gives
//! distributions, this one the reference's own statistic.

use armscope::config::RunConfig;
use armscope::dynamics::{Data, aba, crba, forward_kinematics, gravity_and_bias_from_kinematics, rnea};
use armscope::experiment::Experiment;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

fn per_call_us(mut f: impl FnMut()) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let (mut n, started) = (0u64, Instant::now());
        let mut elapsed = 0.0;
        while elapsed < 0.3 {
            for _ in 0..100 {
                f();
            }
            n += 100;
            elapsed = started.elapsed().as_secs_f64();
        }
        best = best.min(elapsed / n as f64 * 1e6);
    }
    best
}

fn main() {
    armscope::allocator::return_freed_memory_soon();
    // cargo bench passes `--bench`; everything else is a URDF
    let urdfs: Vec<PathBuf> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).map(PathBuf::from).collect();
    for urdf in urdfs {
        let experiment = Experiment::prepare(RunConfig { urdf: urdf.clone(), ..RunConfig::default() }).unwrap_or_else(|e| panic!("{}: {e}", urdf.display()));
        let model = &*experiment.model;
        let n = model.dof();
        let mut data = Data::new(model);
        // as the reference: q within ±1 of 0 (here each joint at 0.3 of its range, or 0.3 rad),
        // v from −1 to 1, τ from 1 to −1
        let q: Vec<f64> = model.joints.iter().map(|j| if j.lower.is_finite() && j.upper.is_finite() { j.lower + 0.3 * (j.upper - j.lower) } else { 0.3 }).collect();
        let v: Vec<f64> = (0..n).map(|i| -1.0 + 2.0 * i as f64 / (n.max(2) - 1) as f64).collect();
        let tau: Vec<f64> = v.iter().map(|x| -x).collect();
        let t_aba = if model.has_mimic() { -1.0 } else { per_call_us(|| { black_box(aba(model, &mut data, black_box(&q), black_box(&v), black_box(&tau))[0]); }) };
        let t_rnea = per_call_us(|| { black_box(rnea(model, &mut data, black_box(&q), black_box(&v), black_box(&tau))[0]); });
        let t_crba = per_call_us(|| { black_box(crba(model, &mut data, black_box(&q))[(0, 0)]); });
        // one plant step from the same state each time (as the reference integrates from q, v)
        let mut plant = experiment.make_plant();
        let u = vec![0.0; n];
        let (mut q1, mut v1) = (q.clone(), v.clone());
        let t_step = per_call_us(|| {
            q1.copy_from_slice(&q);
            v1.copy_from_slice(&v);
            forward_kinematics(model, &mut data, &q1);
            gravity_and_bias_from_kinematics(model, &mut data, &v1);
            plant.advance(model, &mut data, &u, &mut q1, &mut v1);
            black_box(q1[0]);
        });
        println!("{} {n} {t_aba:.3} {t_rnea:.3} {t_crba:.3} {t_step:.3}", model.name);
    }
}
