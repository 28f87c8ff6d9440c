use super::Trajectory;
use crate::error::Error;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

/// `--trajectory FILE`: a joint schedule (from `armscope trajectory` or anywhere else), followed by
/// cubic Hermite interpolation, its derivative as the velocity command; held at its last point.
#[derive(Debug)]
pub struct JointSchedule {
    pub source: String,
    pub times: Vec<f64>,
    /// The joints' positions, one row of `dof` per time, rows one after the other (one block: a
    /// sample reads two rows, where a row each on the heap cost a pointer and a bounds check each).
    positions: Vec<f64>,
    tangents: Vec<f64>,
    dof: usize,
    /// The interval the last sample fell in: a run samples its schedule at increasing times, so
    /// the next lies in it or the one after, found without the binary search over every time
    /// (half a sample's cost on a 30 fps episode). Only a hint: any interval is right to start from.
    cursor: AtomicUsize,
}

impl Clone for JointSchedule {
    fn clone(&self) -> Self {
        Self { source: self.source.clone(), times: self.times.clone(), positions: self.positions.clone(), tangents: self.tangents.clone(), dof: self.dof, cursor: AtomicUsize::new(self.cursor.load(Ordering::Relaxed)) }
    }
}

impl JointSchedule {
    pub fn new(source: String, times: Vec<f64>, positions: Vec<Vec<f64>>) -> Result<Self, String> {
        if times.len() < 2 {
            return Err("needs at least two rows".into());
        }
        if times.windows(2).any(|w| !(w[1] > w[0])) || times.iter().any(|t| !t.is_finite()) {
            return Err("times must be finite and increasing".into());
        }
        if positions.iter().flatten().any(|q| !q.is_finite()) {
            return Err("positions must be finite".into());
        }
        let n = times.len();
        let dof = positions[0].len();
        if positions.iter().any(|row| row.len() != dof) {
            return Err("every row needs the same number of joints".into());
        }
        // finite-difference tangents (one-sided at the ends): C¹ interpolation
        let tangents = (0..n)
            .flat_map(|k| {
                let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
                let span = times[b] - times[a];
                positions[a].iter().zip(&positions[b]).map(move |(qa, qb)| (qb - qa) / span)
            })
            .collect();
        Ok(Self { source, times, positions: positions.concat(), tangents, dof, cursor: AtomicUsize::new(0) })
    }

    /// The positions at the schedule's k-th time.
    pub fn row(&self, k: usize) -> &[f64] {
        &self.positions[k * self.dof..(k + 1) * self.dof]
    }

    /// The interpolation's tangents at the schedule's k-th time.
    fn tangent_row(&self, k: usize) -> &[f64] {
        &self.tangents[k * self.dof..(k + 1) * self.dof]
    }

    /// k with times[k] ≤ t < times[k + 1], for t within the schedule.
    fn interval(&self, t: f64) -> usize {
        let times = &self.times;
        let hint = self.cursor.load(Ordering::Relaxed);
        let k = if hint + 1 < times.len() && times[hint] <= t && t < times[hint + 1] {
            hint
        } else if hint + 2 < times.len() && times[hint + 1] <= t && t < times[hint + 2] {
            hint + 1
        } else {
            times.partition_point(|&x| x <= t) - 1
        };
        self.cursor.store(k, Ordering::Relaxed);
        k
    }

    /// Read a CSV (`t,q1..qN`, header row) or an .npy (float64, shape (rows, 1 + N), t first).
    pub fn load(path: &Path, dof: usize) -> Result<Self, Error> {
        let fail = |m: String| Error::flag("--trajectory", format!("{}: {m}", path.display()));
        let rows: Vec<Vec<f64>> = if path.extension().is_some_and(|e| e == "npy") {
            let bytes = std::fs::read(path).map_err(|e| fail(e.to_string()))?;
            let (shape, data) = crate::npy::read_f64(&bytes).map_err(fail)?;
            if shape.len() != 2 {
                return Err(fail(format!("expected a 2-D array, got shape {shape:?}")));
            }
            data.chunks(shape[1]).map(|c| c.to_vec()).collect()
        } else {
            let text = std::fs::read_to_string(path).map_err(|e| fail(e.to_string()))?;
            let mut lines = text.lines().filter(|l| !l.trim().is_empty() && !l.starts_with('#'));
            lines.next().ok_or_else(|| fail("empty file".into()))?;
            lines
                .enumerate()
                .map(|(i, l)| l.split(',').map(|x| x.trim().parse::<f64>().map_err(|_| fail(format!("row {}: '{x}' is not a number", i + 2)))).collect())
                .collect::<Result<_, _>>()?
        };
        if let Some(bad) = rows.iter().find(|r| r.len() != dof + 1) {
            return Err(fail(format!("rows have {} columns; this model needs {} (t and one per joint)", bad.len(), dof + 1)));
        }
        let times = rows.iter().map(|r| r[0]).collect();
        let positions = rows.iter().map(|r| r[1..].to_vec()).collect();
        Self::new(path.display().to_string(), times, positions).map_err(fail)
    }

    pub fn duration(&self) -> f64 {
        self.times[self.times.len() - 1]
    }
}

impl Trajectory for JointSchedule {
    fn sample(&self, t: f64, cmd: &mut [f64], cmd_dot: &mut [f64]) {
        let last = self.times.len() - 1;
        // before its start and from its end on the schedule holds still; at its first point it is
        // already moving (the derivative from the right), as a wave is at t = 0
        if t < self.times[0] || t >= self.times[last] {
            let k = if t < self.times[0] { 0 } else { last };
            cmd.copy_from_slice(self.row(k));
            cmd_dot.fill(0.0);
            return;
        }
        let k = self.interval(t);
        let h = self.times[k + 1] - self.times[k];
        let s = (t - self.times[k]) / h;
        let (s2, s3) = (s * s, s * s * s);
        let (h00, h10, h01, h11) = (2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s, -2.0 * s3 + 3.0 * s2, s3 - s2);
        let (d00, d10, d01, d11) = (6.0 * s2 - 6.0 * s, 3.0 * s2 - 4.0 * s + 1.0, -6.0 * s2 + 6.0 * s, 3.0 * s2 - 2.0 * s);
        let (p0, p1, m0, m1) = (self.row(k), self.row(k + 1), self.tangent_row(k), self.tangent_row(k + 1));
        let cmd_dot = &mut cmd_dot[..self.dof];
        for (j, c) in cmd[..self.dof].iter_mut().enumerate() {
            let (p0, p1, m0, m1) = (p0[j], p1[j], m0[j], m1[j]);
            *c = h00 * p0 + h10 * h * m0 + h01 * p1 + h11 * h * m1;
            cmd_dot[j] = (d00 * p0 + d01 * p1) / h + d10 * m0 + d11 * m1;
        }
    }

    fn describe(&self) -> String {
        format!("joint schedule {} ({} points over {} s, cubic Hermite)", self.source, self.times.len(), self.duration())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_passes_through_the_points_and_its_derivative_matches_finite_differences() {
        let times: Vec<f64> = (0..20).map(|k| k as f64 * 0.1).collect();
        let positions: Vec<Vec<f64>> = times.iter().map(|t| vec![t.sin(), (2.0 * t).cos()]).collect();
        let s = JointSchedule::new("test".into(), times.clone(), positions.clone()).unwrap();
        let (mut q, mut qd) = (vec![0.0; 2], vec![0.0; 2]);
        for (t, p) in times.iter().zip(&positions).skip(1).take(17) {
            s.sample(*t + 1e-12, &mut q, &mut qd);
            assert!((q[0] - p[0]).abs() < 1e-9 && (q[1] - p[1]).abs() < 1e-9);
        }
        for t in [0.234, 0.777, 1.55] {
            s.sample(t, &mut q, &mut qd);
            let (mut plus, mut minus, mut tmp) = (vec![0.0; 2], vec![0.0; 2], vec![0.0; 2]);
            s.sample(t + 1e-6, &mut plus, &mut tmp);
            s.sample(t - 1e-6, &mut minus, &mut tmp);
            for j in 0..2 {
                assert!((qd[j] - (plus[j] - minus[j]) / 2e-6).abs() < 1e-5, "t {t} joint {j}");
            }
        }
    }

    #[test]
    fn a_sample_is_the_same_whatever_was_sampled_before_it() {
        // the interval hint of the last sample only shortens the search: samples in time order, in
        // reverse, jumping, and on the points themselves give the same bits as a fresh schedule's
        let times: Vec<f64> = (0..50).map(|k| k as f64 / 30.0 + 0.002 * (k % 3) as f64).collect();
        let positions: Vec<Vec<f64>> = times.iter().map(|t| vec![(3.0 * t).sin(), t * t, -t]).collect();
        let schedule = JointSchedule::new("test".into(), times.clone(), positions).unwrap();
        let fresh_sample = |t: f64| {
            let fresh = JointSchedule::new("test".into(), schedule.times.clone(), (0..times.len()).map(|k| schedule.row(k).to_vec()).collect()).unwrap();
            let (mut q, mut qd) = (vec![0.0; 3], vec![0.0; 3]);
            fresh.sample(t, &mut q, &mut qd);
            (q, qd)
        };
        let mut queries: Vec<f64> = (0..1700).map(|k| k as f64 * 1e-3).collect();
        queries.extend(queries.clone().iter().rev());
        queries.extend([1.2, 0.01, 1.6, 0.5, 0.5, times[7], times[8], times[49], -1.0, 9.0, times[0]]);
        let (mut q, mut qd) = (vec![0.0; 3], vec![0.0; 3]);
        for &t in &queries {
            schedule.sample(t, &mut q, &mut qd);
            assert_eq!((q.clone(), qd.clone()), fresh_sample(t), "t = {t}");
        }
    }
}
