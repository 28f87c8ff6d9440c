use super::shared::worker::{BatchWorker, Reusable};
use super::{Recorder, RunInfo};
use crate::error::Error;
use crate::sample::Sample;
use crate::spatial::Pose;
use crate::summary::Summary;
use nalgebra::Vector3;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A recorder that can run on a thread of its own.
type SendRecorder = Box<dyn Recorder + Send>;

/// Runs recorders each on a thread of its own: the simulation loop only copies each sample into
/// a block, once for all of them, and every recorder encodes and writes that block on its own
/// thread. `start` and `finish` run on the caller's side (they need the run's configuration), the
/// recorders' side by side; `record` runs on the workers, in order.
pub struct Threaded {
    /// Each recorder with its thread's name, here before `start` and after `finish`.
    recorders: Vec<(String, SendRecorder)>,
    block: SampleBlock,
    workers: Vec<(String, BatchWorker<SendRecorder, Arc<SampleBlock>, Error>)>,
    /// The blocks handed over, each taken back for reuse once every worker is done with it.
    handed: Vec<Arc<SampleBlock>>,
    last_send: Instant,
    block_samples: usize,
    max_latency: Duration,
}

/// Samples copied out of the loop's buffers, stored flat.
struct SampleBlock {
    n: usize,
    bodies: usize,
    k: Vec<usize>,
    t: Vec<f64>,
    is_final: Vec<bool>,
    q: Vec<f64>,
    v: Vec<f64>,
    cmd: Vec<f64>,
    cmd_dot: Vec<f64>,
    u: Vec<f64>,
    tau_g: Vec<f64>,
    torque_limit: Vec<f64>,
    load_angle: Vec<f64>,
    lost_steps: Vec<i64>,
    saturated: Vec<bool>,
    chatter: Vec<bool>,
    at_limit: Vec<bool>,
    friction: Vec<f64>,
    stuck: Vec<bool>,
    winding_temperature: Vec<f64>,
    duty: Vec<f64>,
    current: Vec<f64>,
    supply: Vec<f64>,
    measured_effort: Vec<f64>,
    observed_position: Vec<f64>,
    /// Every sample's close pairs back to back, and where each sample's end.
    collisions: Vec<crate::collision::PairDistance>,
    collisions_end: Vec<usize>,
    tool: Vec<Vector3<f64>>,
    tool_target: Vec<Vector3<f64>>,
    body_pose: Vec<Pose>,
}

impl SampleBlock {
    fn new(n: usize, bodies: usize, capacity: usize) -> Self {
        let f = || Vec::with_capacity(capacity * n);
        Self {
            n,
            bodies,
            k: Vec::with_capacity(capacity),
            t: Vec::with_capacity(capacity),
            is_final: Vec::with_capacity(capacity),
            q: f(),
            v: f(),
            cmd: f(),
            cmd_dot: f(),
            u: f(),
            tau_g: f(),
            torque_limit: f(),
            load_angle: f(),
            lost_steps: Vec::with_capacity(capacity * n),
            saturated: Vec::with_capacity(capacity * n),
            chatter: Vec::with_capacity(capacity * n),
            at_limit: Vec::with_capacity(capacity * n),
            friction: Vec::new(),
            stuck: Vec::new(),
            winding_temperature: Vec::new(),
            duty: Vec::new(),
            current: Vec::new(),
            supply: Vec::new(),
            measured_effort: Vec::new(),
            observed_position: Vec::new(),
            collisions: Vec::new(),
            collisions_end: Vec::with_capacity(capacity),
            tool: Vec::with_capacity(capacity),
            tool_target: Vec::with_capacity(capacity),
            body_pose: Vec::with_capacity(capacity * bodies),
        }
    }

    fn len(&self) -> usize {
        self.k.len()
    }

    fn push(&mut self, s: &Sample) {
        self.k.push(s.k);
        self.t.push(s.t);
        self.is_final.push(s.is_final);
        self.q.extend_from_slice(s.q);
        self.v.extend_from_slice(s.v);
        self.cmd.extend_from_slice(s.cmd);
        self.cmd_dot.extend_from_slice(s.cmd_dot);
        self.u.extend_from_slice(s.u);
        self.tau_g.extend_from_slice(s.tau_g);
        self.torque_limit.extend_from_slice(s.torque_limit);
        self.load_angle.extend_from_slice(s.load_angle);
        self.lost_steps.extend_from_slice(s.lost_steps);
        self.saturated.extend_from_slice(s.saturated);
        self.chatter.extend_from_slice(s.chatter);
        self.at_limit.extend_from_slice(s.at_limit);
        self.friction.extend_from_slice(s.friction);
        self.stuck.extend_from_slice(s.stuck);
        self.winding_temperature.extend_from_slice(s.winding_temperature);
        self.duty.extend_from_slice(s.duty);
        self.current.extend_from_slice(s.current);
        self.supply.extend_from_slice(s.supply);
        self.measured_effort.extend_from_slice(s.measured_effort);
        self.observed_position.extend_from_slice(s.observed_position);
        self.collisions.extend_from_slice(s.collisions);
        self.collisions_end.push(self.collisions.len());
        self.tool.push(s.tool_position);
        self.tool_target.push(s.tool_target);
        self.body_pose.extend_from_slice(s.body_pose);
    }

    fn sample(&self, i: usize) -> Sample<'_> {
        let (a, b) = (i * self.n, (i + 1) * self.n);
        Sample {
            k: self.k[i],
            t: self.t[i],
            is_final: self.is_final[i],
            q: &self.q[a..b],
            v: &self.v[a..b],
            cmd: &self.cmd[a..b],
            cmd_dot: &self.cmd_dot[a..b],
            u: &self.u[a..b],
            tau_g: &self.tau_g[a..b],
            torque_limit: &self.torque_limit[a..b],
            load_angle: &self.load_angle[a..b],
            lost_steps: &self.lost_steps[a..b],
            saturated: &self.saturated[a..b],
            chatter: &self.chatter[a..b],
            at_limit: &self.at_limit[a..b],
            // (all samples of a run have friction, or none has)
            friction: if self.friction.is_empty() { &[] } else { &self.friction[a..b] },
            stuck: if self.stuck.is_empty() { &[] } else { &self.stuck[a..b] },
            winding_temperature: if self.winding_temperature.is_empty() { &[] } else { &self.winding_temperature[a..b] },
            duty: if self.duty.is_empty() { &[] } else { &self.duty[a..b] },
            current: if self.current.is_empty() { &[] } else { &self.current[a..b] },
            supply: if self.supply.is_empty() { &[] } else { &self.supply[a..b] },
            measured_effort: if self.measured_effort.is_empty() { &[] } else { &self.measured_effort[a..b] },
            observed_position: if self.observed_position.is_empty() { &[] } else { &self.observed_position[a..b] },
            collisions: &self.collisions[if i == 0 { 0 } else { self.collisions_end[i - 1] }..self.collisions_end[i]],
            tool_position: self.tool[i],
            tool_target: self.tool_target[i],
            body_pose: &self.body_pose[i * self.bodies..(i + 1) * self.bodies],
        }
    }
}

impl Reusable for SampleBlock {
    fn clear(&mut self) {
        self.k.clear();
        self.t.clear();
        self.is_final.clear();
        for v in [&mut self.q, &mut self.v, &mut self.cmd, &mut self.cmd_dot, &mut self.u, &mut self.tau_g, &mut self.torque_limit, &mut self.load_angle, &mut self.winding_temperature, &mut self.duty, &mut self.current, &mut self.supply, &mut self.measured_effort, &mut self.observed_position] {
            v.clear();
        }
        self.lost_steps.clear();
        self.saturated.clear();
        self.chatter.clear();
        self.at_limit.clear();
        self.friction.clear();
        self.stuck.clear();
        self.collisions.clear();
        self.collisions_end.clear();
        self.tool.clear();
        self.tool_target.clear();
        self.body_pose.clear();
    }
}

/// Blocks handed over and kept for reuse at most (each worker's queue holds a few).
const BLOCKS_KEPT: usize = 8;

impl Threaded {
    /// `max_latency`: a block is handed over at least this often (for live viewers).
    pub fn new(max_latency: Duration) -> Self {
        Self {
            recorders: Vec::new(),
            block: SampleBlock::new(0, 0, 0),
            workers: Vec::new(),
            handed: Vec::new(),
            last_send: Instant::now(),
            block_samples: 250,
            max_latency,
        }
    }

    /// Adds a recorder, on a thread named after it (so profiles and debuggers tell them apart).
    pub fn with<R: Recorder + Send + 'static>(mut self, recorder: R) -> Self {
        let name = std::any::type_name::<R>().rsplit("::").next().unwrap_or("recorder").to_string();
        self.recorders.push((name, Box::new(recorder)));
        self
    }

    pub fn is_empty(&self) -> bool {
        self.recorders.is_empty() && self.workers.is_empty()
    }

    /// An emptied block every worker is done with, or a new one.
    fn empty_block(&mut self) -> SampleBlock {
        let done = self.handed.iter().position(|b| Arc::strong_count(b) == 1);
        if let Some(mut block) = done.map(|i| self.handed.swap_remove(i)).and_then(|b| Arc::try_unwrap(b).ok()) {
            block.clear();
            return block;
        }
        SampleBlock::new(self.block.n, self.block.bodies, self.block_samples)
    }

    fn send_block(&mut self) -> Result<(), Error> {
        if self.workers.is_empty() || self.block.len() == 0 {
            return Ok(());
        }
        self.last_send = Instant::now();
        let empty = self.empty_block();
        let full = Arc::new(std::mem::replace(&mut self.block, empty));
        for i in 0..self.workers.len() {
            if !self.workers[i].1.send(full.clone()) {
                // the worker stopped on an error: report it
                return self.join_all();
            }
        }
        if self.handed.len() >= BLOCKS_KEPT {
            self.handed.remove(0);
        }
        self.handed.push(full);
        Ok(())
    }

    /// Lets every worker finish what it was sent and takes the recorders back, in order; the
    /// first error of any.
    fn join_all(&mut self) -> Result<(), Error> {
        let mut first_error = None;
        for (name, mut worker) in self.workers.drain(..) {
            if let Some(joined) = worker.join() {
                let (recorder, result) = joined.expect("recorder thread panicked");
                self.recorders.push((name, recorder));
                if let Err(e) = result {
                    first_error.get_or_insert(e);
                }
            }
        }
        first_error.map_or(Ok(()), Err)
    }
}

/// Runs `each` on every recorder at once, the first on this thread and the others on threads of
/// their own; the first error in the recorders' order.
fn side_by_side(recorders: &mut [(String, SendRecorder)], each: impl Fn(&mut SendRecorder) -> Result<(), Error> + Sync) -> Result<(), Error> {
    let Some(((_, first), others)) = recorders.split_first_mut() else { return Ok(()) };
    std::thread::scope(|scope| {
        let each = &each;
        let others: Vec<_> = others.iter_mut().map(|(_, r)| scope.spawn(move || each(r))).collect();
        let mut result = each(first);
        for other in others {
            let other = other.join().expect("recorder thread panicked");
            result = result.and(other);
        }
        result
    })
}

impl Recorder for Threaded {
    fn start(&mut self, run: &RunInfo) -> Result<(), Error> {
        side_by_side(&mut self.recorders, |r| r.start(run))?;
        let model = &run.experiment.model;
        self.block = SampleBlock::new(model.dof(), model.bodies.len(), self.block_samples);
        for (name, recorder) in std::mem::take(&mut self.recorders) {
            let worker = BatchWorker::spawn_shared(&name, recorder, |r: &mut SendRecorder, block: &Arc<SampleBlock>| (0..block.len()).try_for_each(|i| r.record(&block.sample(i))));
            self.workers.push((name, worker.map_err(|e| Error::output(std::path::Path::new("recorder thread"), e))?));
        }
        self.last_send = Instant::now();
        Ok(())
    }

    fn record(&mut self, s: &Sample) -> Result<(), Error> {
        self.block.push(s);
        // the clock is read every 16 samples only: at 1 kHz that is still every 16 ms of simulation
        let late = || self.block.len().is_multiple_of(16) && self.last_send.elapsed() >= self.max_latency;
        if self.block.len() >= self.block_samples || s.is_final || late() {
            self.send_block()?;
        }
        Ok(())
    }

    fn finish(&mut self, run: &RunInfo, summary: &Summary) -> Result<(), Error> {
        self.send_block()?;
        self.join_all()?;
        side_by_side(&mut self.recorders, |r| r.finish(run, summary))
    }
}

#[cfg(test)]
mod tests {
    use super::Threaded;
    use crate::config::RunConfig;
    use crate::error::Error;
    use crate::experiment::Experiment;
    use crate::recorder::{Recorder, RunInfo};
    use crate::sample::Sample;
    use crate::summary::Summary;
    use std::sync::{Arc, Mutex};
    use std::time::Duration;

    /// What a recorder saw: each sample's step, angle and tool position, and how often it was finished.
    #[derive(Clone, Default)]
    struct Seen {
        samples: Arc<Mutex<Vec<(usize, f64, [f64; 3])>>>,
        finished: Arc<Mutex<usize>>,
    }

    struct Collect {
        seen: Seen,
        fail_at: Option<usize>,
    }

    impl Recorder for Collect {
        fn start(&mut self, _: &RunInfo) -> Result<(), Error> {
            Ok(())
        }
        fn record(&mut self, s: &Sample) -> Result<(), Error> {
            if Some(s.k) == self.fail_at {
                return Err(Error::output(std::path::Path::new("collect"), "disk full"));
            }
            self.seen.samples.lock().unwrap().push((s.k, s.q[0], s.tool_position.into()));
            Ok(())
        }
        fn finish(&mut self, _: &RunInfo, _: &Summary) -> Result<(), Error> {
            *self.seen.finished.lock().unwrap() += 1;
            Ok(())
        }
    }

    fn experiment() -> Experiment {
        let model = crate::model::load_urdf_str(crate::builtin::builtin(std::path::Path::new(crate::builtin::DEFAULT_URDF)).unwrap(), std::path::Path::new("box.urdf")).unwrap();
        Experiment::with_model(RunConfig { duration: 2.0, ..RunConfig::default() }, model).unwrap()
    }

    #[test]
    fn every_recorder_on_its_thread_sees_every_sample_in_order_as_the_loop_made_it() {
        let experiment = experiment();
        let (here, first, second) = (Seen::default(), Seen::default(), Seen::default());
        let mut inline = Collect { seen: here.clone(), fail_at: None };
        let mut threaded = Threaded::new(Duration::from_millis(20)).with(Collect { seen: first.clone(), fail_at: None }).with(Collect { seen: second.clone(), fail_at: None });
        crate::sim::simulate(&experiment, &mut [&mut inline, &mut threaded], None).unwrap();
        let expected = here.samples.lock().unwrap().clone();
        assert_eq!(expected.len(), experiment.steps + 1);
        for seen in [&first, &second] {
            // the same numbers, bit for bit, in the same order: one shared copy, blocks reused
            assert!(*seen.samples.lock().unwrap() == expected);
            assert_eq!(*seen.finished.lock().unwrap(), 1);
        }
    }

    #[test]
    fn a_recorder_that_fails_stops_the_run_with_its_error() {
        let experiment = experiment();
        let (fine, failing) = (Seen::default(), Seen::default());
        let mut threaded = Threaded::new(Duration::from_millis(20)).with(Collect { seen: fine.clone(), fail_at: None }).with(Collect { seen: failing.clone(), fail_at: Some(700) });
        let error = crate::sim::simulate(&experiment, &mut [&mut threaded], None).unwrap_err().to_string();
        assert!(error.contains("collect") && error.contains("disk full"), "{error}");
        let failed = failing.samples.lock().unwrap();
        assert_eq!(failed.len(), 700, "the failing recorder saw the samples before its failure");
        assert!(failed.iter().enumerate().all(|(i, s)| s.0 == i));
    }
}
