//! The update of the joint velocities (or accelerations) under Coulomb friction and position
//! limits, solved exactly: find x with
//!
//! ```text
//!   g = b − A·x  ∈  ∂φ(x),   φ(x) = Σ_i φ_i(x_i)
//! ```
//!
//! A symmetric positive definite, φ_i convex and piecewise linear: slope `below` for x_i < 0 and
//! `above` for x_i > 0 (a kink at 0 when they differ: Coulomb friction, hF on each side in the
//! discrete step), +∞ outside [lower, upper] (the position limits). Equivalently x is the unique
//! minimizer of ½xᵀAx − bᵀx + φ(x) (strictly convex). In the discrete plant x = v⁺, A = M + hD,
//! b = M·v + h(τ + τ_g − C·v): the friction impulse on joint i is −g_i, within [−hF⁺, hF⁻]… when
//! the joint sticks (x_i = 0 exactly) and ∓hF on a sliding joint; a joint at a limit takes the
//! limit's impulse on top. With no friction and no limit reached, x = A⁻¹b: Drake's update.
//!
//! Solved as a mixed linear complementarity problem by block principal pivoting with the
//! Júdice–Pires safeguard (Murty's least-index single pivot when the block step stops reducing
//! the number of violated conditions; finite for a P-matrix such as A): each joint is on one
//! piece of φ_i — a segment (g_i known: its slope) or a breakpoint (x_i known: 0 or a limit) — the
//! linear system for that choice is solved, and a joint whose x leaves its segment, or whose g
//! leaves its breakpoint's subdifferential, moves one piece towards where it belongs. The
//! previous step's pieces start the search, so a stuck joint costs one solve. What ends the search
//! is exact: every condition holds to the rounding of the solve (no regularization, no creep).

use crate::dynamics::{ldlt_in_place, ldlt_solve_in_place, ltdl_in_place, ltdl_solve_in_place};
use nalgebra::DMatrix;

/// One joint's φ_i.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLaw {
    /// Bounds on x_i (infinite where none). lower ≤ upper.
    pub lower: f64,
    pub upper: f64,
    /// ∂φ_i on x_i < 0 and on x_i > 0: −h·F⁻ and +h·F⁺ for friction, equal (no kink) for a joint
    /// whose sliding direction is known, 0 for a frictionless joint. A kink needs below ≤ above.
    pub below: f64,
    pub above: f64,
}

impl JointLaw {
    pub const FREE: JointLaw = JointLaw { lower: f64::NEG_INFINITY, upper: f64::INFINITY, below: 0.0, above: 0.0 };

    fn has_kink(&self) -> bool {
        self.below != self.above && self.lower < 0.0 && self.upper > 0.0
    }

    /// The breakpoints in increasing order, and how many.
    fn breakpoints(&self) -> ([f64; 3], usize) {
        let mut points = [0.0; 3];
        let mut m = 0;
        if self.lower.is_finite() {
            points[m] = self.lower;
            m += 1;
        }
        if self.has_kink() {
            points[m] = 0.0;
            m += 1;
        }
        if self.upper.is_finite() && !(m > 0 && points[m - 1] == self.upper) {
            points[m] = self.upper;
            m += 1;
        }
        (points, m)
    }

    /// The slope of segment k (between breakpoints k−1 and k).
    fn segment_slope(&self, points: &[f64; 3], m: usize, k: usize) -> f64 {
        if k >= 1 && points[k - 1] >= 0.0 {
            self.above
        } else if k < m && points[k] <= 0.0 {
            self.below
        } else {
            // a segment across 0 exists only without a kink
            self.above
        }
    }

    /// The pieces a joint can be on: 2k a segment, 2k+1 breakpoint k; (first, last) valid.
    fn piece_range(&self, m: usize) -> (usize, usize) {
        let first = if self.lower.is_finite() { 1 } else { 0 };
        let last = if self.upper.is_finite() { 2 * m - 1 } else { 2 * m };
        (first, last)
    }

    /// The piece x lies on (a breakpoint when x equals it).
    fn piece_of(&self, x: f64) -> usize {
        let (points, m) = self.breakpoints();
        let (first, last) = self.piece_range(m);
        let mut piece = 0;
        for (k, &p) in points[..m].iter().enumerate() {
            if x == p {
                piece = 2 * k + 1;
                break;
            }
            if x > p {
                piece = 2 * k + 2;
            }
        }
        piece.clamp(first, last)
    }
}

/// Workspace of the solve, sized once for n joints (no allocation per solve).
pub struct StickSlipSolver {
    n: usize,
    factor: DMatrix<f64>,
    rhs: Vec<f64>,
    /// Per joint, the piece of φ_i it is on (see [`JointLaw`]); kept between solves as the start.
    piece: Vec<usize>,
    /// Per joint, the breakpoints of the current solve's law and how many (worked out once per solve).
    points: Vec<([f64; 3], usize)>,
    /// Each joint's parent joint when A has a branched tree's sparsity (LᵀDL), else dense LDLᵀ.
    tree_parents: Option<Vec<Option<usize>>>,
    violated: Vec<usize>,
    /// Per joint: whether this solve has already moved it across its kink.
    crossed: Vec<bool>,
    /// Whether `factor` holds A + diag factored, as this solve loaded it: while every joint is on a
    /// segment the system is A + diag whatever the segments, and only its right-hand side changes.
    factored_whole: bool,
    /// Solves that needed the fallback (coordinate descent) because pivoting did not finish.
    pub fallbacks: u64,
    /// Linear systems solved by the pivoting, over every solve (the fast paths' first solve not
    /// counted).
    pub pivot_iterations: u64,
}

/// Why a solve failed: A is not positive definite (a state that is no longer finite).
#[derive(Debug, PartialEq)]
pub struct NotPositiveDefinite;

impl StickSlipSolver {
    pub fn new(n: usize, tree_parents: Option<Vec<Option<usize>>>) -> Self {
        Self { n, factor: DMatrix::zeros(n, n), rhs: vec![0.0; n], piece: vec![0; n], points: vec![([0.0; 3], 0); n], tree_parents, violated: Vec::with_capacity(n), crossed: vec![false; n], factored_whole: false, fallbacks: 0, pivot_iterations: 0 }
    }

    /// Whether joint i ended the last solve of `laws` on a limit (lower: −1, upper: +1, else 0). A
    /// limit is the first or last breakpoint (a kink at 0 lies strictly between the limits).
    pub fn limit_side(&self, laws: &[JointLaw], i: usize) -> i8 {
        let law = &laws[i];
        let (points, m) = self.points[i];
        let piece = self.piece[i];
        if piece % 2 == 0 {
            return 0;
        }
        let k = piece / 2;
        if law.lower.is_finite() && k == 0 {
            -1
        } else if law.upper.is_finite() && k == m - 1 && points[k] == law.upper {
            1
        } else {
            0
        }
    }

    /// Solve for x (A by columns, n×n; `diagonal` added to A's diagonal, e.g. h·D). On return
    /// `g` holds b − A·x for every joint (on a segment, exactly its slope, which the solve imposed).
    /// Starts from the pieces of the last solve.
    pub fn solve(&mut self, a: &[f64], diagonal: &[f64], b: &[f64], laws: &[JointLaw], x: &mut [f64], g: &mut [f64]) -> Result<(), NotPositiveDefinite> {
        let n = self.n;
        self.factored_whole = false;
        if self.solve_free(a, diagonal, b, laws, x, g)? {
            return Ok(());
        }
        for ((p, points), law) in self.piece.iter_mut().zip(&mut self.points).zip(laws) {
            *points = law.breakpoints();
            let (first, last) = law.piece_range(points.1);
            *p = (*p).clamp(first, last);
        }
        if self.solve_sliding(a, diagonal, b, laws, x, g)? {
            return Ok(());
        }
        self.crossed.fill(false);
        let mut fewest = usize::MAX;
        let mut stalled = 0;
        // Murty's rule terminates; the bound only guards against rounding cycles, after which the
        // coordinate-descent fallback finds the pieces
        let max_iterations = 20 * n + 50;
        for _ in 0..max_iterations {
            self.pivot_iterations += 1;
            self.solve_on_pieces(a, diagonal, b, laws, x)?;
            self.residual(a, diagonal, b, laws, x, g);
            self.find_violations(laws, x, g);
            let count = self.violated.len();
            if count == 0 {
                self.snap_to_pieces(laws, x);
                return Ok(());
            }
            let block = if count < fewest {
                fewest = count;
                stalled = 0;
                true
            } else {
                stalled += 1;
                stalled < 3
            };
            let moves = if block { count } else { 1 };
            for idx in 0..moves {
                let (i, up) = decode(self.violated[idx]);
                let piece = self.piece[i];
                // a block move takes a sliding joint whose x left its segment straight to the piece
                // x is on, or onto its kink when it would come to rest there ([`Self::across`]);
                // one piece at a time otherwise, and always in Murty's single moves
                self.piece[i] = if block && piece % 2 == 0 {
                    self.across(i, &laws[i], x[i])
                } else if up {
                    piece + 1
                } else {
                    piece - 1
                };
            }
        }
        self.fallbacks += 1;
        self.coordinate_descent(a, diagonal, b, laws, x, g)
    }

    /// Without friction (every law's slopes 0), the unconstrained solution when it lies within every
    /// bound: then it is the solution (the problem is strictly convex), found by the same factorization
    /// and arithmetic as the pivoting's first solve from those pieces, so bit for bit the same — without
    /// the pivoting's bookkeeping, which was a fifth of a frictionless plant step away from the
    /// limits. Returns false (x overwritten) when friction or a bound calls for the pivoting.
    fn solve_free(&mut self, a: &[f64], diagonal: &[f64], b: &[f64], laws: &[JointLaw], x: &mut [f64], g: &mut [f64]) -> Result<bool, NotPositiveDefinite> {
        if laws.iter().any(|l| l.below != 0.0 || l.above != 0.0) {
            return Ok(false);
        }
        self.load_matrix(a, diagonal);
        self.factor()?;
        self.factored_whole = true;
        x.copy_from_slice(b);
        self.substitute(x);
        // strictly within: on a bound the pivoting decides whether the joint rests on it
        if !x.iter().zip(laws).all(|(xi, l)| l.lower < *xi && *xi < l.upper) {
            return Ok(false);
        }
        // each joint on the segment between its bounds (2 past a finite lower bound, else 0)
        for (p, law) in self.piece.iter_mut().zip(laws) {
            *p = if law.lower.is_finite() { 2 } else { 0 };
        }
        g.fill(0.0);
        Ok(true)
    }

    /// Every joint on a segment and staying strictly inside it (sliding on as it slid, or within
    /// its range): the first solve from those pieces is the solution, found by the same arithmetic
    /// as the pivoting's first solve, so bit for bit the same — without its bookkeeping (the
    /// residual's rows, the search for violations), most of a step with gearbox friction whose
    /// joints slide. Returns false when some joint sits on a breakpoint or leaves its segment
    /// (x is then that first solve, the factorization kept for the pivoting).
    fn solve_sliding(&mut self, a: &[f64], diagonal: &[f64], b: &[f64], laws: &[JointLaw], x: &mut [f64], g: &mut [f64]) -> Result<bool, NotPositiveDefinite> {
        if self.piece.iter().any(|p| p % 2 == 1) {
            return Ok(false);
        }
        self.solve_on_pieces(a, diagonal, b, laws, x)?;
        for (i, law) in laws.iter().enumerate() {
            let ((points, m), k) = (self.points[i], self.piece[i] / 2);
            let below = if k >= 1 { points[k - 1] } else { f64::NEG_INFINITY };
            let above = if k < m { points[k] } else { f64::INFINITY };
            if !(below < x[i] && x[i] < above) {
                return Ok(false);
            }
            g[i] = law.segment_slope(&points, m, k);
        }
        Ok(true)
    }

    /// Where a block move takes joint i, sliding on a segment that `x` (its solution there) has left:
    /// the piece x is on — but onto the kink instead of across it when the joint would come to rest
    /// there. Across the kink its slope drops by the whole band (above − below), which moves x_i back
    /// by the band times the factored system's (F⁻¹)_ii (how x_i answers its own right-hand side with
    /// every other piece held); when that carries it past the kink again, or when this solve has
    /// moved it across once already, neither side holds it and it sticks. (A joint reversing under a
    /// large torque goes across in one move; one slowing to rest would otherwise swing from side to
    /// side until Murty's single moves took it onto the kink.)
    fn across(&mut self, i: usize, law: &JointLaw, x: f64) -> usize {
        let target = law.piece_of(x);
        let piece = self.piece[i];
        let (points, m) = self.points[i];
        let Some(k) = points[..m].iter().position(|&p| p == 0.0 && law.has_kink()) else { return target };
        let kink = 2 * k + 1;
        if target == kink || (piece < kink) == (target < kink) {
            return target;
        }
        if self.crossed[i] {
            return kink;
        }
        // (F⁻¹)_ii: the factored system solved for the unit vector e_i (`rhs` is free until the
        // next solve loads it)
        let mut unit = std::mem::take(&mut self.rhs);
        unit.fill(0.0);
        unit[i] = 1.0;
        self.substitute(&mut unit);
        let back = (law.above - law.below) * unit[i];
        self.rhs = unit;
        if x.abs() <= back {
            return kink;
        }
        self.crossed[i] = true;
        target
    }

    /// The linear system for the current pieces: x_i fixed on a breakpoint, g_i = the slope on a
    /// segment.
    fn solve_on_pieces(&mut self, a: &[f64], diagonal: &[f64], b: &[f64], laws: &[JointLaw], x: &mut [f64]) -> Result<(), NotPositiveDefinite> {
        let n = self.n;
        let on_segments = self.piece.iter().all(|p| p % 2 == 0);
        if !(on_segments && self.factored_whole) {
            self.load_matrix(a, diagonal);
        }
        self.rhs.copy_from_slice(b);
        for (j, law) in laws.iter().enumerate() {
            let piece = self.piece[j];
            let (points, m) = self.points[j];
            if piece % 2 == 0 {
                let slope = law.segment_slope(&points, m, piece / 2);
                if slope != 0.0 {
                    self.rhs[j] -= slope;
                }
            }
        }
        for j in 0..n {
            let piece = self.piece[j];
            if piece % 2 == 0 {
                continue;
            }
            let fixed = self.points[j].0[piece / 2];
            for i in 0..n {
                self.rhs[i] -= self.factor[(i, j)] * fixed;
                self.factor[(i, j)] = 0.0;
                self.factor[(j, i)] = 0.0;
            }
            self.factor[(j, j)] = 1.0;
            self.rhs[j] = fixed;
        }
        x.copy_from_slice(&self.rhs);
        if on_segments {
            // the same matrix for any segments (a joint sliding either way, or the other): factored
            // once a solve, only the right-hand side substituted again (a chattering joint
            // reverses every step: two solves of a step, one factorization)
            if !self.factored_whole {
                self.factor()?;
                self.factored_whole = true;
            }
        } else {
            self.factor()?;
            self.factored_whole = false;
        }
        self.substitute(x);
        Ok(())
    }

    /// A + diag into the factor's workspace.
    fn load_matrix(&mut self, a: &[f64], diagonal: &[f64]) {
        self.factor.as_mut_slice().copy_from_slice(a);
        for (i, d) in diagonal.iter().enumerate() {
            self.factor[(i, i)] += d;
        }
    }

    /// Factor the workspace's matrix (along the tree, or dense LDLᵀ).
    fn factor(&mut self) -> Result<(), NotPositiveDefinite> {
        let factored = match &self.tree_parents {
            Some(parents) => ltdl_in_place(&mut self.factor, parents),
            None => ldlt_in_place(&mut self.factor),
        };
        if factored { Ok(()) } else { Err(NotPositiveDefinite) }
    }

    /// Solve with the factored workspace for `x`, which holds the right-hand side on entry.
    fn substitute(&self, x: &mut [f64]) {
        match &self.tree_parents {
            Some(parents) => ltdl_solve_in_place(&self.factor, parents, x),
            None => ldlt_solve_in_place(&self.factor, x),
        }
    }

    /// Each joint whose x leaves its segment or whose g leaves its breakpoint's subdifferential,
    /// encoded with the direction it must move (see `decode`), in increasing joint order.
    fn find_violations(&mut self, laws: &[JointLaw], x: &[f64], g: &[f64]) {
        self.violated.clear();
        let scale = x.iter().fold(1.0_f64, |s, v| s.max(v.abs()));
        for (i, law) in laws.iter().enumerate() {
            let (points, m) = self.points[i];
            let piece = self.piece[i];
            let k = piece / 2;
            if piece % 2 == 0 {
                // on segment k, between breakpoints k−1 and k: a kink is left within rounding of
                // the solve (both pieces give the same x there), a limit exactly as it is reached
                let tolerance = |p: f64| if p == 0.0 && law.has_kink() { 1e-13 * scale } else { 0.0 };
                if k < m && x[i] > points[k] + tolerance(points[k]) {
                    self.violated.push(encode(i, true));
                } else if k >= 1 && x[i] < points[k - 1] - tolerance(points[k - 1]) {
                    self.violated.push(encode(i, false));
                }
            } else {
                // on breakpoint k: g within [slope left of it, slope right of it]; a limit's side
                // is unbounded
                let left = if k == 0 && law.lower.is_finite() { f64::NEG_INFINITY } else { law.segment_slope(&points, m, k) };
                let right = if k == m - 1 && law.upper.is_finite() && points[k] == law.upper { f64::INFINITY } else { law.segment_slope(&points, m, k + 1) };
                if g[i] > right {
                    self.violated.push(encode(i, true));
                } else if g[i] < left {
                    self.violated.push(encode(i, false));
                }
            }
        }
    }

    /// g = b − (A + diag)·x: on a segment the slope the solve imposed there, on a breakpoint the
    /// row worked out (A by columns, symmetric: row i read as column i) — only the rows the checks
    /// need, as a frictionless step away from its limits needs none.
    fn residual(&self, a: &[f64], diagonal: &[f64], b: &[f64], laws: &[JointLaw], x: &[f64], g: &mut [f64]) {
        let n = x.len();
        for i in 0..n {
            let (piece, (points, m)) = (self.piece[i], self.points[i]);
            if piece % 2 == 0 {
                g[i] = laws[i].segment_slope(&points, m, piece / 2);
                continue;
            }
            let mut ax = diagonal[i] * x[i];
            for (aij, xj) in a[i * n..(i + 1) * n].iter().zip(x) {
                ax += aij * xj;
            }
            g[i] = b[i] - ax;
        }
    }

    /// A joint on a segment that ends at a kink may sit a rounding error past it: put it on the kink.
    fn snap_to_pieces(&self, laws: &[JointLaw], x: &mut [f64]) {
        for (i, law) in laws.iter().enumerate() {
            let (piece, (points, m)) = (self.piece[i], self.points[i]);
            if piece % 2 == 0 && law.has_kink() {
                let k = piece / 2;
                if (k < m && points[k] == 0.0 && x[i] > 0.0) || (k >= 1 && points[k - 1] == 0.0 && x[i] < 0.0) {
                    x[i] = 0.0;
                }
            }
        }
    }

    /// The fallback: exact minimization along one coordinate at a time (each a soft threshold and
    /// a clamp) until the pieces stop changing, then the pivoting from those pieces.
    fn coordinate_descent(&mut self, a: &[f64], diagonal: &[f64], b: &[f64], laws: &[JointLaw], x: &mut [f64], g: &mut [f64]) -> Result<(), NotPositiveDefinite> {
        let n = self.n;
        x.iter_mut().zip(laws).for_each(|(xi, law)| *xi = 0.0_f64.clamp(law.lower, law.upper));
        let mut unchanged = 0;
        for _ in 0..100_000 {
            let mut changed = false;
            for i in 0..n {
                let aii = a[i * n + i] + diagonal[i];
                if !(aii > 0.0) {
                    return Err(NotPositiveDefinite);
                }
                // r = b_i − Σ_{j≠i} A_ij x_j
                let mut r = b[i];
                for (j, aij) in a[i * n..(i + 1) * n].iter().enumerate() {
                    if j != i {
                        r -= aij * x[j];
                    }
                }
                let law = &laws[i];
                let xi = if r > law.above {
                    (r - law.above) / aii
                } else if r < law.below {
                    (r - law.below) / aii
                } else if law.has_kink() {
                    0.0
                } else {
                    (r - law.above) / aii
                };
                let xi = xi.clamp(law.lower, law.upper);
                let piece = law.piece_of(xi);
                if piece != self.piece[i] {
                    self.piece[i] = piece;
                    changed = true;
                }
                x[i] = xi;
            }
            unchanged = if changed { 0 } else { unchanged + 1 };
            if unchanged >= 3 {
                break;
            }
        }
        // polish: the exact solution on the pieces found (within rounding of the descent, they are
        // the solution's)
        self.solve_on_pieces(a, diagonal, b, laws, x)?;
        self.residual(a, diagonal, b, laws, x, g);
        self.snap_to_pieces(laws, x);
        Ok(())
    }
}

fn encode(joint: usize, up: bool) -> usize {
    2 * joint + up as usize
}

fn decode(code: usize) -> (usize, bool) {
    (code / 2, code % 2 == 1)
}



#[cfg(test)]
mod tests {
    use super::*;

    /// Every joint's conditions, checked directly: x within its bounds and g in ∂φ_i(x_i).
    fn optimality_violation(law: &JointLaw, x: f64, g: f64) -> f64 {
        let lo_slope = if x <= law.lower { f64::NEG_INFINITY } else if x > 0.0 { law.above } else { law.below };
        let hi_slope = if x >= law.upper { f64::INFINITY } else if x < 0.0 { law.below } else { law.above };
        // at x = 0 with a kink: [below, above]
        let (lo, hi) = if x == 0.0 && law.has_kink() {
            (if x <= law.lower { f64::NEG_INFINITY } else { law.below }, if x >= law.upper { f64::INFINITY } else { law.above })
        } else {
            (lo_slope.min(hi_slope), hi_slope.max(lo_slope))
        };
        let outside = (lo - g).max(g - hi).max(0.0);
        outside + (law.lower - x).max(0.0) + (x - law.upper).max(0.0)
    }

    fn random_spd(n: usize, seed: &mut u64) -> Vec<f64> {
        let mut next = || {
            *seed ^= *seed << 13;
            *seed ^= *seed >> 7;
            *seed ^= *seed << 17;
            (*seed % 20001) as f64 / 10000.0 - 1.0
        };
        let l: Vec<f64> = (0..n * n).map(|_| next()).collect();
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let mut s = if i == j { 0.5 } else { 0.0 };
                for k in 0..n {
                    s += l[i * n + k] * l[j * n + k];
                }
                a[j * n + i] = s;
            }
        }
        a
    }

    #[test]
    fn frictionless_shortcut_is_the_pivoting_bit_for_bit() {
        // the shortcut's solution, where it applies, equals the pivoting's from the free pieces
        // exactly; where the free solution leaves a bound the pivoting takes over and the conditions hold
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let (mut shortcut, mut pivoted) = (0, 0);
        for case in 0..400 {
            let n = 1 + case % 7;
            let a = random_spd(n, &mut seed);
            let b: Vec<f64> = random_spd(n, &mut seed)[..n].to_vec();
            let width = if case % 2 == 0 { 10.0 } else { 0.3 };
            let laws: Vec<JointLaw> = (0..n).map(|i| JointLaw { lower: -width * (1.0 + i as f64 * 0.1), upper: width, below: 0.0, above: 0.0 }).collect();
            let diagonal = vec![0.01; n];
            let mut solver = StickSlipSolver::new(n, None);
            let (mut x, mut g) = (vec![0.0; n], vec![0.0; n]);
            solver.solve(&a, &diagonal, &b, &laws, &mut x, &mut g).unwrap();
            let inside = x.iter().zip(&laws).all(|(xi, l)| l.lower < *xi && *xi < l.upper);
            if inside {
                shortcut += 1;
                let mut reference = StickSlipSolver::new(n, None);
                reference.piece.iter_mut().zip(&laws).for_each(|(p, l)| *p = if l.lower.is_finite() { 2 } else { 0 });
                reference.points.iter_mut().zip(&laws).for_each(|(p, l)| *p = l.breakpoints());
                let mut y = vec![0.0; n];
                reference.solve_on_pieces(&a, &diagonal, &b, &laws, &mut y).unwrap();
                assert!(x.iter().zip(&y).all(|(p, q)| p.to_bits() == q.to_bits()), "case {case}: {x:?} vs {y:?}");
                assert!((0..n).all(|i| solver.limit_side(&laws, i) == 0) && g.iter().all(|&gi| gi == 0.0));
            } else {
                pivoted += 1;
                for i in 0..n {
                    assert!(optimality_violation(&laws[i], x[i], g[i]) <= 1e-12, "case {case}, joint {i}");
                }
            }
        }
        assert!(shortcut > 50 && pivoted > 50, "both paths exercised: {shortcut} / {pivoted}");
    }

    #[test]
    fn one_joint_is_the_soft_threshold() {
        // x = sgn(b)·max(|b| − hF, 0)/A
        let mut solver = StickSlipSolver::new(1, None);
        let law = JointLaw { below: -0.3, above: 0.3, ..JointLaw::FREE };
        for (b, expected) in [(1.0, 0.35), (-1.0, -0.35), (0.2, 0.0), (-0.3, 0.0)] {
            let (mut x, mut g) = ([0.0], [0.0]);
            solver.solve(&[2.0], &[0.0], &[b], &[law], &mut x, &mut g).unwrap();
            assert!((x[0] - expected).abs() < 1e-15, "b = {b}: x = {}", x[0]);
        }
    }

    #[test]
    fn a_sliding_joint_brought_to_rest_goes_onto_its_kink_in_one_move() {
        // joint 0 slid forward in the last step; now the rest of the impulse on it is within its
        // band, so it sticks (x₀ = 0), while joint 1, coupled to it, slides on. Sliding forward
        // puts x₀ below 0 and sliding back above it: neither side holds it, and the block move
        // goes onto the kink at once — two linear solves (the guess, then the kink), where a move
        // across it would swing from side to side until Murty's single moves took it there. (The
        // coupling makes (A⁻¹)₀₀ = 2.8 where 1/A₀₀ = 1: a move judged on A's diagonal alone would
        // cross.)
        let a = [1.0, 0.8, 0.8, 1.0];
        let law = JointLaw { below: -0.3, above: 0.3, ..JointLaw::FREE };
        let laws = [law, law];
        let mut solver = StickSlipSolver::new(2, None);
        let (mut x, mut g) = ([0.0; 2], [0.0; 2]);
        solver.solve(&a, &[0.0; 2], &[2.0, 2.0], &laws, &mut x, &mut g).unwrap();
        assert!(x[0] > 0.0 && x[1] > 0.0, "both slide forward first: {x:?}");
        let before = solver.pivot_iterations;
        let b = [1.3, 2.0];
        solver.solve(&a, &[0.0; 2], &b, &laws, &mut x, &mut g).unwrap();
        assert_eq!(x[0], 0.0, "joint 0 sticks: {x:?}");
        // x₁ = (b₁ − 0.3)/A₁₁ and joint 0's residual within its band
        assert!((x[1] - 1.7).abs() < 1e-15 && (b[0] - 0.8 * x[1]).abs() <= 0.3, "{x:?}");
        assert_eq!(solver.pivot_iterations - before, 2, "the guess, then the kink");
    }

    #[test]
    fn random_problems_meet_every_condition() {
        // friction on every joint, some limits, warm and cold starts: the conditions that define
        // the solution hold to rounding (1e-12 of the problem's scale)
        let mut seed = 0x2545F4914F6CDD1D_u64;
        for trial in 0..300 {
            let n = 1 + trial % 7;
            let a = random_spd(n, &mut seed);
            let mut solver = StickSlipSolver::new(n, None);
            for round in 0..3 {
                let mut r = || {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    (seed % 20001) as f64 / 10000.0 - 1.0
                };
                let b: Vec<f64> = (0..n).map(|_| 2.0 * r()).collect();
                let laws: Vec<JointLaw> = (0..n)
                    .map(|_| {
                        let f_pos = 0.5 * (r() + 1.0);
                        let f_neg = 0.5 * (r() + 1.0);
                        let lower = if r() > 0.3 { -0.5 * (r() + 1.0) } else { f64::NEG_INFINITY };
                        let upper = if r() > 0.3 { 0.5 * (r() + 1.0) } else { f64::INFINITY };
                        JointLaw { lower, upper, below: -f_neg, above: f_pos }
                    })
                    .collect();
                let (mut x, mut g) = (vec![0.0; n], vec![0.0; n]);
                solver.solve(&a, &vec![0.0; n], &b, &laws, &mut x, &mut g).unwrap();
                for i in 0..n {
                    // the residual worked out here, every row (the solver's g gives segments their slope)
                    let g: f64 = b[i] - (0..n).map(|j| a[j * n + i] * x[j]).sum::<f64>();
                    let v = optimality_violation(&laws[i], x[i], g);
                    assert!(v < 1e-12, "trial {trial} round {round} joint {i}: x = {}, g = {g}, law {:?}", x[i], laws[i]);
                }
            }
        }
        // (the coordinate-descent fallback was never needed)
    }
}
