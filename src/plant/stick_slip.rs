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
//! previous step's pieces start the search, so a stuck joint costs one solve. A + diag is factored
//! once a solve whatever the pieces: the joints on breakpoints are held at their values through the
//! Schur complement of its inverse (a substitution each), so a search of several steps costs
//! substitutions, not factorizations. What ends the search is exact: every condition holds to the
//! rounding of the solve (no regularization, no creep), a joint on a breakpoint exactly on it.

use crate::dynamics::{ldlt_in_place, ldlt_in_place_slice, ldlt_solve_in_place, ldlt_solve_slice, ltdl_in_place, ltdl_solve_in_place};
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
}

/// One joint's φ_i as the solve under way sees it, worked out once from its law: the breakpoints,
/// the slope on each segment, which breakpoint is the kink and which are limits.
#[derive(Clone, Copy, Debug)]
struct Shape {
    points: [f64; 3],
    /// How many breakpoints.
    m: usize,
    /// The slope on segment k (between breakpoints k − 1 and k), k = 0..=m.
    slopes: [f64; 4],
    /// The pieces it can be on (a finite bound closes the segment beyond it).
    first: usize,
    last: usize,
    /// The kink's breakpoint, if φ_i has one (strictly between the limits).
    kink: Option<usize>,
    /// Whether the first breakpoint is the lower limit, the last the upper.
    lower_limit: bool,
    upper_limit: bool,
}

impl Shape {
    const NONE: Shape = Shape { points: [0.0; 3], m: 0, slopes: [0.0; 4], first: 0, last: 0, kink: None, lower_limit: false, upper_limit: false };

    fn of(law: &JointLaw) -> Self {
        let (points, m) = law.breakpoints();
        let (first, last) = law.piece_range(m);
        let mut slopes = [0.0; 4];
        for (k, slope) in slopes.iter_mut().enumerate().take(m + 1) {
            *slope = law.segment_slope(&points, m, k);
        }
        let kink = if law.has_kink() { points[..m].iter().position(|&p| p == 0.0) } else { None };
        let lower_limit = law.lower.is_finite();
        let upper_limit = law.upper.is_finite() && m > 0 && points[m - 1] == law.upper;
        Shape { points, m, slopes, first, last, kink, lower_limit, upper_limit }
    }

    /// The ends of segment k.
    fn ends(&self, k: usize) -> (f64, f64) {
        (if k >= 1 { self.points[k - 1] } else { f64::NEG_INFINITY }, if k < self.m { self.points[k] } else { f64::INFINITY })
    }

    /// ∂φ_i at breakpoint k: [the slope left of it, the slope right of it], a limit's far side
    /// unbounded.
    fn subdifferential(&self, k: usize) -> (f64, f64) {
        let left = if k == 0 && self.lower_limit { f64::NEG_INFINITY } else { self.slopes[k] };
        let right = if k + 1 == self.m && self.upper_limit { f64::INFINITY } else { self.slopes[k + 1] };
        (left, right)
    }

    /// The piece x lies on (a breakpoint when x equals it).
    fn piece_of(&self, x: f64) -> usize {
        let mut piece = 0;
        for (k, &p) in self.points[..self.m].iter().enumerate() {
            if x == p {
                piece = 2 * k + 1;
                break;
            }
            if x > p {
                piece = 2 * k + 2;
            }
        }
        piece.clamp(self.first, self.last)
    }
}

/// Workspace of the solve, sized once for n joints (no allocation per solve).
pub struct StickSlipSolver {
    n: usize,
    factor: DMatrix<f64>,
    /// Scratch by joint: the values the fixed joints are held at ([`Self::solve_holding`]), or a
    /// unit column.
    rhs: Vec<f64>,
    /// Per joint, the piece of φ_i it is on (see [`JointLaw`]); kept between solves as the start
    /// (`UNKNOWN` before the first: at rest, where x = 0 lies).
    piece: Vec<usize>,
    /// Per joint, its φ_i in the solve under way.
    shapes: Vec<Shape>,
    /// Per joint, the sign of x in the last solve that searched the pieces (0: at rest, or none
    /// yet); unchanged by a guess that held.
    side: Vec<i8>,
    /// The sides [`Self::solve_held`] tries.
    trial: Vec<i8>,
    /// Whether the last solve was [`Self::solve_held`]'s, which leaves `piece` as it was; then
    /// `held_limit` says which resting joints rest on a limit.
    pieces_stale: bool,
    held_limit: Vec<i8>,
    /// Each joint's parent joint when A has a branched tree's sparsity (LᵀDL), else dense LDLᵀ.
    tree_parents: Option<Vec<Option<usize>>>,
    violated: Vec<usize>,
    /// Per joint: whether this solve has already moved it across its kink.
    crossed: Vec<bool>,
    /// Whether `factor` holds F = A + diag factored, as this solve loaded it.
    factored_whole: bool,
    /// The joints on breakpoints in the linear system under way, and F⁻¹'s columns for them
    /// (column j at j·n; `have_column` says which this solve has worked out: F does not change
    /// within a solve).
    fixed: Vec<usize>,
    inverse_columns: Vec<f64>,
    have_column: Vec<bool>,
    /// The most fixed joints solved through the Schur complement ([`schur_limit`]).
    schur_max: usize,
    /// The Schur complement F⁻¹ restricted to the fixed joints, and its right-hand side.
    schur: Vec<f64>,
    schur_rhs: Vec<f64>,
    /// Solves that needed the fallback (coordinate descent) because pivoting did not finish.
    pub fallbacks: u64,
    /// Linear systems solved by the pivoting, over every solve (the fast paths' first solve not
    /// counted).
    pub pivot_iterations: u64,
    /// Factorizations, over every solve.
    pub factorizations: u64,
}

/// A joint's piece before its first solve.
const UNKNOWN: usize = usize::MAX;

/// Why a solve failed: A is not positive definite (a state that is no longer finite).
#[derive(Debug, PartialEq)]
pub struct NotPositiveDefinite;

/// The most joints on breakpoints whose values are imposed through the one factorization of F
/// (Schur complements on F⁻¹'s columns) rather than by factoring the reduced system: each costs a
/// substitution where the reduced system costs a factorization — for the 6-joint arm a
/// factorization is five substitutions. (n/6 for the larger trees, whose factorization grows
/// faster than a substitution.)
fn schur_limit(n: usize) -> usize {
    (n / 6).max(4)
}

impl StickSlipSolver {
    pub fn new(n: usize, tree_parents: Option<Vec<Option<usize>>>) -> Self {
        let limit = schur_limit(n);
        Self {
            n,
            factor: DMatrix::zeros(n, n),
            rhs: vec![0.0; n],
            piece: vec![UNKNOWN; n],
            shapes: vec![Shape::NONE; n],
            side: vec![0; n],
            trial: vec![0; n],
            pieces_stale: false,
            held_limit: vec![0; n],
            tree_parents,
            violated: Vec::with_capacity(n),
            crossed: vec![false; n],
            factored_whole: false,
            fixed: Vec::with_capacity(n),
            inverse_columns: vec![0.0; n * n],
            have_column: vec![false; n],
            schur_max: limit,
            schur: vec![0.0; limit * limit],
            schur_rhs: vec![0.0; limit],
            fallbacks: 0,
            pivot_iterations: 0,
            factorizations: 0,
        }
    }

    /// Whether joint i ended the last solve on a limit (lower: −1, upper: +1, else 0). A limit is
    /// the first or last breakpoint (a kink at 0 lies strictly between the limits).
    pub fn limit_side(&self, i: usize) -> i8 {
        if self.pieces_stale {
            return self.held_limit[i];
        }
        let (shape, piece) = (&self.shapes[i], self.piece[i]);
        if piece % 2 == 0 {
            return 0;
        }
        let k = piece / 2;
        if shape.lower_limit && k == 0 {
            -1
        } else if shape.upper_limit && k + 1 == shape.m {
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
        self.have_column.fill(false);
        if self.solve_free(a, diagonal, b, laws, x, g)? {
            self.pieces_stale = false;
            return Ok(());
        }
        if self.solve_held(a, diagonal, b, laws, x, g)? {
            self.pieces_stale = true;
            return Ok(());
        }
        for (((p, shape), law), &side) in self.piece.iter_mut().zip(&mut self.shapes).zip(laws).zip(&self.side) {
            *shape = Shape::of(law);
            *p = if self.pieces_stale {
                // the last solve ended on the sides it held: the segment on the side each moved to
                shape.piece_of(side as f64 * f64::MIN_POSITIVE)
            } else if *p == UNKNOWN {
                shape.piece_of(0.0)
            } else {
                (*p).clamp(shape.first, shape.last)
            };
        }
        self.pieces_stale = false;
        // the last solve's pieces, tried as they are: x holds their solution after this
        if self.solve_sliding(a, diagonal, b, x, g)? {
            return Ok(());
        }
        let mut solved = true;
        self.crossed.fill(false);
        let mut fewest = usize::MAX;
        let mut stalled = 0;
        // Murty's rule terminates; the bound only guards against rounding cycles, after which the
        // coordinate-descent fallback finds the pieces
        let max_iterations = 20 * n + 50;
        for _ in 0..max_iterations {
            self.pivot_iterations += 1;
            if !solved {
                self.solve_on_pieces(a, diagonal, b, x)?;
            }
            solved = false;
            self.residual(a, diagonal, b, x, g);
            self.find_violations(x, g);
            let count = self.violated.len();
            if count == 0 {
                self.snap_to_pieces(x);
                self.record_sides(x);
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
                    self.across(i, &laws[i], x[i])?
                } else if up {
                    piece + 1
                } else {
                    piece - 1
                };
            }
        }
        self.fallbacks += 1;
        self.coordinate_descent(a, diagonal, b, laws, x, g)?;
        self.record_sides(x);
        Ok(())
    }

    /// Which way each joint moves: the next solve's first guess ([`Self::solve_held`]).
    fn record_sides(&mut self, x: &[f64]) {
        for (side, &xi) in self.side.iter_mut().zip(x) {
            *side = if xi > 0.0 { 1 } else if xi < 0.0 { -1 } else { 0 };
        }
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
        self.factor_whole(a, diagonal)?;
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

    /// The last solve's outcome guessed to hold: each joint that moved slides on the way it moved
    /// (slope `above` one way, `below` the other), each that was at rest stays at rest (x_i = 0,
    /// held through the Schur complement). That is the solution when every moving x_i keeps its
    /// sign strictly within its bounds and every resting joint's g_i lies in ∂φ_i(0). When it is not,
    /// the guess is mended a few times as the pieces' search would move it — a moving joint whose x
    /// changed sign reverses (and rests, if it changes sign again), a resting one pushed out of its
    /// band starts moving that way — each try a substitution. Most plant steps of an arm, moving,
    /// holding, starting, stopping or chattering, end here, without the pieces' bookkeeping; a limit
    /// reached, or a guess still wrong after the tries, is left to the search. Returns false (x
    /// overwritten) then.
    fn solve_held(&mut self, a: &[f64], diagonal: &[f64], b: &[f64], laws: &[JointLaw], x: &mut [f64], g: &mut [f64]) -> Result<bool, NotPositiveDefinite> {
        // on the tutorial's 30 s --drive pd run three tries leave 6.6 % of the solves to the search, five 0.04 %
        const TRIES: usize = 5;
        let n = self.n;
        self.trial.copy_from_slice(&self.side);
        self.crossed.fill(false);
        for _ in 0..TRIES {
            self.fixed.clear();
            for (i, ((xi, (law, &side)), (bi, gi))) in x.iter_mut().zip(laws.iter().zip(&self.trial)).zip(b.iter().zip(g.iter_mut())).enumerate() {
                if side == 0 {
                    if !(law.lower <= 0.0 && 0.0 <= law.upper) {
                        return Ok(false);
                    }
                    self.fixed.push(i);
                    *xi = *bi;
                } else {
                    *gi = if side > 0 { law.above } else { law.below };
                    *xi = if *gi != 0.0 { bi - *gi } else { *bi };
                }
            }
            for &j in &self.fixed {
                self.rhs[j] = 0.0;
            }
            self.solve_holding(a, diagonal, x)?;
            let mut settled = true;
            for (i, ((&xi, law), side)) in x.iter().zip(laws).zip(self.trial.iter_mut()).enumerate() {
                if *side == 0 {
                    // ∂φ_i(0): unbounded towards a limit at 0, else the band [below, above]
                    let mut row = 0.0;
                    for (aij, xj) in a[i * n..(i + 1) * n].iter().zip(x.iter()) {
                        row += aij * xj;
                    }
                    g[i] = b[i] - row;
                    if law.lower != 0.0 && g[i] < law.below {
                        (*side, settled) = (-1, false);
                    } else if law.upper != 0.0 && g[i] > law.above {
                        (*side, settled) = (1, false);
                    }
                } else if (*side > 0 && xi >= law.upper) || (*side < 0 && xi <= law.lower) {
                    // a limit reached
                    return Ok(false);
                } else if (*side > 0 && xi <= 0.0) || (*side < 0 && xi >= 0.0) {
                    *side = if self.crossed[i] { 0 } else { -*side };
                    self.crossed[i] = true;
                    settled = false;
                }
            }
            if settled {
                self.side.copy_from_slice(&self.trial);
                for ((limit, law), &side) in self.held_limit.iter_mut().zip(laws).zip(&self.side) {
                    *limit = if side != 0 { 0 } else if law.lower == 0.0 { -1 } else if law.upper == 0.0 { 1 } else { 0 };
                }
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// The last solve's pieces, solved for: when every joint is on a segment and stays strictly
    /// inside it (sliding on as it slid, or within its range) that is the solution, without the
    /// pivoting's bookkeeping (the residual's rows, the search for violations) — most of a step with
    /// gearbox friction whose joints slide. Returns false when some joint sits on a breakpoint or
    /// leaves its segment; x is then the solution on those pieces, the pivoting's first.
    fn solve_sliding(&mut self, a: &[f64], diagonal: &[f64], b: &[f64], x: &mut [f64], g: &mut [f64]) -> Result<bool, NotPositiveDefinite> {
        self.solve_on_pieces(a, diagonal, b, x)?;
        if !self.fixed.is_empty() {
            return Ok(false);
        }
        for (i, shape) in self.shapes.iter().enumerate() {
            let k = self.piece[i] / 2;
            let (below, above) = shape.ends(k);
            if !(below < x[i] && x[i] < above) {
                return Ok(false);
            }
            g[i] = shape.slopes[k];
        }
        Ok(true)
    }

    /// Where a block move takes joint i, sliding on a segment that `x` (its solution there) has left:
    /// the piece x is on — but onto the kink instead of across it when the joint would come to rest
    /// there. Across the kink its slope drops by the whole band (above − below), which moves x_i back
    /// by the band times (F⁻¹)_ii, how x_i answers its own right-hand side (with the joints on
    /// breakpoints held, the Schur complement's correction); when that carries it past the kink
    /// again, or when this solve has moved it across once already, neither side holds it and it
    /// sticks. (A joint reversing under a large torque goes across in one move; one slowing to rest
    /// would otherwise swing from side to side until Murty's single moves took it onto the kink.)
    fn across(&mut self, i: usize, law: &JointLaw, x: f64) -> Result<usize, NotPositiveDefinite> {
        let shape = self.shapes[i];
        let target = shape.piece_of(x);
        let Some(k) = shape.kink else { return Ok(target) };
        let (piece, kink) = (self.piece[i], 2 * k + 1);
        if target == kink || (piece < kink) == (target < kink) {
            return Ok(target);
        }
        if self.crossed[i] {
            return Ok(kink);
        }
        let back = (law.above - law.below) * self.response(i)?;
        if x.abs() <= back {
            return Ok(kink);
        }
        self.crossed[i] = true;
        Ok(target)
    }

    /// How x_i answers a unit change of its own right-hand side in the linear system under way
    /// (joint i on a segment): (F⁻¹)_ii less what holding the fixed joints takes back.
    fn response(&mut self, i: usize) -> Result<f64, NotPositiveDefinite> {
        if self.factored_whole && self.fixed.len() <= self.schur_max {
            self.column(i)?;
            let n = self.n;
            let mut response = self.inverse_columns[i * n + i];
            if !self.fixed.is_empty() {
                // e_iᵀ F⁻¹ E (Eᵀ F⁻¹ E)⁻¹ Eᵀ F⁻¹ e_i, S already factored by the last solve
                let count = self.fixed.len();
                for (k, &j) in self.fixed.iter().enumerate() {
                    self.schur_rhs[k] = self.inverse_columns[j * n + i];
                }
                let mut coupling = std::mem::take(&mut self.schur_rhs);
                ldlt_solve_slice(&self.schur[..count * count], &mut coupling[..count], count);
                for (k, &j) in self.fixed.iter().enumerate() {
                    response -= self.inverse_columns[j * n + i] * coupling[k];
                }
                self.schur_rhs = coupling;
            }
            Ok(response)
        } else {
            // the reduced system is what is factored: solve it for e_i
            let mut unit = std::mem::take(&mut self.rhs);
            unit.fill(0.0);
            unit[i] = 1.0;
            self.substitute(&mut unit);
            let response = unit[i];
            self.rhs = unit;
            Ok(response)
        }
    }

    /// The linear system for the current pieces: x_i fixed on a breakpoint, g_i = the slope on a
    /// segment ([`Self::solve_holding`]: F = A + diag factored once a solve, whatever the pieces).
    fn solve_on_pieces(&mut self, a: &[f64], diagonal: &[f64], b: &[f64], x: &mut [f64]) -> Result<(), NotPositiveDefinite> {
        self.fixed.clear();
        for (j, (&piece, shape)) in self.piece.iter().zip(&self.shapes).enumerate() {
            if piece % 2 == 0 {
                let slope = shape.slopes[piece / 2];
                x[j] = if slope != 0.0 { b[j] - slope } else { b[j] };
            } else {
                x[j] = b[j];
                self.fixed.push(j);
            }
        }
        for &j in &self.fixed {
            self.rhs[j] = self.shapes[j].points[self.piece[j] / 2];
        }
        self.solve_holding(a, diagonal, x)
    }

    /// F·x = r with the joints in `fixed` held at their values in `rhs` (x holds r on entry): with
    /// a few, x = y + W·μ with y = F⁻¹r, W = F⁻¹E (a substitution per fixed joint, once a solve) and
    /// S·μ = c − Eᵀy, S = EᵀF⁻¹E the Schur complement; with many, the reduced system (the fixed rows
    /// and columns taken out) factored instead.
    fn solve_holding(&mut self, a: &[f64], diagonal: &[f64], x: &mut [f64]) -> Result<(), NotPositiveDefinite> {
        let count = self.fixed.len();
        if count > self.schur_max || count == self.n {
            return self.solve_reduced(a, diagonal, x);
        }
        if !self.factored_whole {
            self.factor_whole(a, diagonal)?;
        }
        self.substitute(x);
        if count == 0 {
            return Ok(());
        }
        for k in 0..count {
            self.column(self.fixed[k])?;
        }
        for (l, &jl) in self.fixed.iter().enumerate() {
            self.schur_rhs[l] = self.rhs[jl] - x[jl];
        }
        self.hold_fixed(x)?;
        // on its value exactly, not to the rounding of the correction
        for &j in &self.fixed {
            x[j] = self.rhs[j];
        }
        Ok(())
    }

    /// x += W·μ with S·μ = `schur_rhs` (S = EᵀF⁻¹E, symmetric positive definite: a principal block
    /// of F⁻¹; W = F⁻¹E, the fixed joints' columns already worked out): what holds the fixed joints
    /// where `schur_rhs` moves them.
    fn hold_fixed(&mut self, x: &mut [f64]) -> Result<(), NotPositiveDefinite> {
        let (n, count) = (self.n, self.fixed.len());
        for (l, &jl) in self.fixed.iter().enumerate() {
            for (k, &jk) in self.fixed.iter().enumerate() {
                self.schur[l * count + k] = self.inverse_columns[jl * n + jk];
            }
        }
        if !ldlt_in_place_slice(&mut self.schur[..count * count], count) {
            return Err(NotPositiveDefinite);
        }
        ldlt_solve_slice(&self.schur[..count * count], &mut self.schur_rhs[..count], count);
        for (l, &jl) in self.fixed.iter().enumerate() {
            let (mu, column) = (self.schur_rhs[l], &self.inverse_columns[jl * n..(jl + 1) * n]);
            for (xi, wi) in x.iter_mut().zip(column) {
                *xi += wi * mu;
            }
        }
        Ok(())
    }

    /// The linear system with the fixed joints' rows and columns taken out of A + diag (their
    /// values, in `rhs` by joint, moved to the right-hand side `x` holds), factored as it is.
    fn solve_reduced(&mut self, a: &[f64], diagonal: &[f64], x: &mut [f64]) -> Result<(), NotPositiveDefinite> {
        if self.fixed.len() == self.n {
            // every joint fixed: nothing to solve
            x.copy_from_slice(&self.rhs);
            return Ok(());
        }
        self.load_matrix(a, diagonal);
        self.factored_whole = false;
        for &j in &self.fixed {
            let fixed = self.rhs[j];
            for (i, xi) in x.iter_mut().enumerate() {
                *xi -= self.factor[(i, j)] * fixed;
                self.factor[(i, j)] = 0.0;
                self.factor[(j, i)] = 0.0;
            }
            self.factor[(j, j)] = 1.0;
            x[j] = fixed;
        }
        self.factor()?;
        self.substitute(x);
        Ok(())
    }

    /// F⁻¹'s column j, worked out once a solve.
    fn column(&mut self, j: usize) -> Result<(), NotPositiveDefinite> {
        if self.have_column[j] {
            return Ok(());
        }
        if !self.factored_whole {
            return Err(NotPositiveDefinite);
        }
        let n = self.n;
        let mut column = std::mem::take(&mut self.inverse_columns);
        let unit = &mut column[j * n..(j + 1) * n];
        unit.fill(0.0);
        unit[j] = 1.0;
        self.substitute(unit);
        self.inverse_columns = column;
        self.have_column[j] = true;
        Ok(())
    }

    /// F = A + diag, loaded and factored.
    fn factor_whole(&mut self, a: &[f64], diagonal: &[f64]) -> Result<(), NotPositiveDefinite> {
        self.load_matrix(a, diagonal);
        self.factor()?;
        self.factored_whole = true;
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
        self.factorizations += 1;
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
    fn find_violations(&mut self, x: &[f64], g: &[f64]) {
        self.violated.clear();
        let scale = x.iter().fold(1.0_f64, |s, v| s.max(v.abs()));
        for (i, shape) in self.shapes.iter().enumerate() {
            let piece = self.piece[i];
            let k = piece / 2;
            if piece % 2 == 0 {
                // on segment k, between breakpoints k−1 and k: a kink is left within rounding of
                // the solve (both pieces give the same x there), a limit exactly as it is reached
                let (below, above) = shape.ends(k);
                let tolerance = |end: usize| if shape.kink == Some(end) { 1e-13 * scale } else { 0.0 };
                if k < shape.m && x[i] > above + tolerance(k) {
                    self.violated.push(encode(i, true));
                } else if k >= 1 && x[i] < below - tolerance(k - 1) {
                    self.violated.push(encode(i, false));
                }
            } else {
                // on breakpoint k: g within [slope left of it, slope right of it]
                let (left, right) = shape.subdifferential(k);
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
    fn residual(&self, a: &[f64], diagonal: &[f64], b: &[f64], x: &[f64], g: &mut [f64]) {
        let n = x.len();
        for i in 0..n {
            let piece = self.piece[i];
            if piece % 2 == 0 {
                g[i] = self.shapes[i].slopes[piece / 2];
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
    fn snap_to_pieces(&self, x: &mut [f64]) {
        for (i, shape) in self.shapes.iter().enumerate() {
            let piece = self.piece[i];
            if let (0, Some(kink)) = (piece % 2, shape.kink) {
                let k = piece / 2;
                if (k == kink && x[i] > 0.0) || (k == kink + 1 && x[i] < 0.0) {
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
                let piece = self.shapes[i].piece_of(xi);
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
        self.solve_on_pieces(a, diagonal, b, x)?;
        self.residual(a, diagonal, b, x, g);
        self.snap_to_pieces(x);
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
                reference.shapes.iter_mut().zip(&laws).for_each(|(s, l)| *s = Shape::of(l));
                let mut y = vec![0.0; n];
                reference.solve_on_pieces(&a, &diagonal, &b, &mut y).unwrap();
                assert!(x.iter().zip(&y).all(|(p, q)| p.to_bits() == q.to_bits()), "case {case}: {x:?} vs {y:?}");
                assert!((0..n).all(|i| solver.limit_side(i) == 0) && g.iter().all(|&gi| gi == 0.0));
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
        // band, so it sticks (x₀ = 0), while joint 1, coupled to it, slides on — and joint 2, on its
        // own, runs into its upper limit, which sends the solve to the pieces' search. Sliding
        // forward puts x₀ below 0 and sliding back above it: neither side holds it, and the block
        // move goes onto the kink at once — two linear solves (the guess, then the kink and the
        // limit), where a move across it would swing from side to side until Murty's single moves
        // took it there. (The coupling makes (A⁻¹)₀₀ = 2.8 where 1/A₀₀ = 1: a move judged on A's
        // diagonal alone would cross.)
        let a = [1.0, 0.8, 0.0, 0.8, 1.0, 0.0, 0.0, 0.0, 1.0];
        let law = JointLaw { below: -0.3, above: 0.3, ..JointLaw::FREE };
        let limited = JointLaw { upper: 2.5, ..law };
        let laws = [law, law, limited];
        let mut solver = StickSlipSolver::new(3, None);
        let (mut x, mut g) = ([0.0; 3], [0.0; 3]);
        solver.solve(&a, &[0.0; 3], &[2.0, 2.0, 1.0], &laws, &mut x, &mut g).unwrap();
        assert!(x.iter().all(|&xi| xi > 0.0), "all slide forward first: {x:?}");
        let before = solver.pivot_iterations;
        let b = [1.3, 2.0, 3.0];
        solver.solve(&a, &[0.0; 3], &b, &laws, &mut x, &mut g).unwrap();
        assert_eq!((x[0], x[2]), (0.0, 2.5), "joint 0 sticks, joint 2 stops at its limit: {x:?}");
        // x₁ = (b₁ − 0.3)/A₁₁ and joint 0's residual within its band
        assert!((x[1] - 1.7).abs() < 1e-15 && (b[0] - 0.8 * x[1]).abs() <= 0.3, "{x:?}");
        assert_eq!(solver.limit_side(2), 1);
        assert_eq!(solver.pivot_iterations - before, 2, "the guess, then the kink");
    }

    /// An arm holding still, every joint within its band: x = 0 exactly, found without factoring
    /// anything; one joint pushed out of its band moves alone, the others held.
    #[test]
    fn an_arm_held_still_by_its_friction_costs_no_factorization() {
        let mut seed = 0x3C6E_F372_FE94_F82B_u64;
        let n = 6;
        let a = random_spd(n, &mut seed);
        let laws: Vec<JointLaw> = (0..n).map(|_| JointLaw { lower: -5.0, upper: 5.0, below: -1.0, above: 1.2 }).collect();
        let mut solver = StickSlipSolver::new(n, None);
        let (mut x, mut g) = (vec![0.0; n], vec![0.0; n]);
        let mut b = vec![0.5, -0.9, 0.3, 1.1, -0.2, 0.0];
        for _ in 0..3 {
            solver.solve(&a, &[0.0; 6], &b, &laws, &mut x, &mut g).unwrap();
            assert!(x.iter().all(|&xi| xi == 0.0) && g == b, "held still: {x:?}");
        }
        assert_eq!((solver.factorizations, solver.pivot_iterations), (0, 0));
        b[2] = 4.0;
        solver.solve(&a, &[0.0; 6], &b, &laws, &mut x, &mut g).unwrap();
        for i in 0..n {
            let g: f64 = b[i] - (0..n).map(|j| a[j * n + i] * x[j]).sum::<f64>();
            assert!(optimality_violation(&laws[i], x[i], g) < 1e-12, "joint {i}: x = {}, g = {g}", x[i]);
        }
        assert!(x[2] > 0.0 && solver.pivot_iterations == 0, "{x:?}");
    }

    /// A joint reversing, coming to rest or starting to move, next to one that slides on: the last
    /// solve's outcome, mended, is the solution — no search of the pieces — and each meets every
    /// condition.
    #[test]
    fn reversing_stopping_and_starting_are_mended_without_the_search() {
        let a = [1.0, 0.6, 0.6, 1.0];
        let law = JointLaw { below: -0.3, above: 0.3, ..JointLaw::FREE };
        let laws = [law, law];
        let mut solver = StickSlipSolver::new(2, None);
        let (mut x, mut g) = ([0.0; 2], [0.0; 2]);
        solver.solve(&a, &[0.0; 2], &[2.0, 3.0], &laws, &mut x, &mut g).unwrap();
        let before = solver.pivot_iterations;
        // joint 0: reverses, reverses back, comes to rest, stays, starts again; joint 1 slides on
        for (step, b0) in [-2.0, 2.5, 1.6, 1.7, 4.0, -3.0].into_iter().enumerate() {
            let b = [b0, 3.0];
            solver.solve(&a, &[0.0; 2], &b, &laws, &mut x, &mut g).unwrap();
            for i in 0..2 {
                let g: f64 = b[i] - (0..2).map(|j| a[j * 2 + i] * x[j]).sum::<f64>();
                assert!(optimality_violation(&laws[i], x[i], g) < 1e-12, "step {step} joint {i}: x = {}, g = {g}", x[i]);
            }
            assert_eq!(x[0] == 0.0, (2..4).contains(&step), "step {step}: joint 0 at rest exactly when its band holds it: {x:?}");
        }
        assert_eq!(solver.pivot_iterations, before, "no search of the pieces");
    }

    /// Random problems (friction and limits on every joint, 1–12 joints, warm starts), solved with
    /// the joints on breakpoints held through the Schur complement on the one factorization, and
    /// with the reduced system factored every time: the same limits reached, x and g to rounding.
    #[test]
    fn the_schur_complement_and_the_reduced_system_agree() {
        let mut seed = 0x51_7C_C1_B7_27_22_0A_95_u64;
        let mut held = 0;
        for trial in 0..400 {
            let n = 1 + trial % 12;
            let a = random_spd(n, &mut seed);
            let mut schur = StickSlipSolver::new(n, None);
            let mut reduced = StickSlipSolver::new(n, None);
            reduced.schur_max = 0;
            for _round in 0..3 {
                let mut r = || {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    (seed % 20001) as f64 / 10000.0 - 1.0
                };
                let b: Vec<f64> = (0..n).map(|_| 2.0 * r()).collect();
                let laws: Vec<JointLaw> = (0..n).map(|_| JointLaw { lower: -0.3 - 0.5 * (r() + 1.0), upper: 0.3 + 0.5 * (r() + 1.0), below: -0.6 * (r() + 1.0), above: 0.6 * (r() + 1.0) }).collect();
                let diagonal = vec![0.01; n];
                let (mut x1, mut g1, mut x2, mut g2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
                schur.solve(&a, &diagonal, &b, &laws, &mut x1, &mut g1).unwrap();
                reduced.solve(&a, &diagonal, &b, &laws, &mut x2, &mut g2).unwrap();
                assert!((0..n).all(|i| schur.limit_side(i) == reduced.limit_side(i)), "trial {trial}: the same limits reached");
                let scale = x2.iter().chain(&b).fold(1.0_f64, |s, v| s.max(v.abs()));
                for i in 0..n {
                    assert!((x1[i] - x2[i]).abs() <= 1e-12 * scale && (g1[i] - g2[i]).abs() <= 1e-12 * scale, "trial {trial} joint {i}: x {} vs {}, g {} vs {}", x1[i], x2[i], g1[i], g2[i]);
                }
                held += (1..=schur.schur_max.min(n - 1)).contains(&x1.iter().filter(|&&xi| xi == 0.0).count()) as usize;
            }
        }
        assert!(held > 300, "the Schur complement exercised: {held}");
    }

    /// The linear system on any pieces with at most `schur_max` joints fixed is solved on the one
    /// factorization of A + diag, each fixed joint's value exact.
    #[test]
    fn pieces_with_a_few_fixed_joints_cost_no_factorization() {
        let mut seed = 0x2B_99_2D_DF_A2_32_49_D6_u64;
        let n = 7;
        let a = random_spd(n, &mut seed);
        let diagonal = vec![0.02; n];
        let b: Vec<f64> = random_spd(n, &mut seed)[..n].to_vec();
        let law = JointLaw { lower: -0.7, upper: 0.9, below: -0.2, above: 0.3 };
        let mut solver = StickSlipSolver::new(n, None);
        solver.shapes.fill(Shape::of(&law));
        solver.factor_whole(&a, &diagonal).unwrap();
        let factorizations = solver.factorizations;
        // pieces: 1 lower limit, 2 below the kink, 3 the kink, 4 above it, 5 upper limit
        for (pattern, pieces) in [[2, 4, 2, 4, 2, 4, 2], [3, 4, 2, 4, 2, 4, 2], [1, 4, 3, 4, 2, 5, 2], [3, 3, 3, 3, 2, 4, 2]].iter().enumerate() {
            solver.piece.copy_from_slice(pieces);
            let mut x = vec![0.0; n];
            solver.solve_on_pieces(&a, &diagonal, &b, &mut x).unwrap();
            let mut reduced = StickSlipSolver::new(n, None);
            reduced.shapes.fill(Shape::of(&law));
            reduced.piece.copy_from_slice(pieces);
            reduced.schur_max = 0;
            let mut y = vec![0.0; n];
            reduced.solve_on_pieces(&a, &diagonal, &b, &mut y).unwrap();
            for i in 0..n {
                assert!((x[i] - y[i]).abs() < 1e-12, "pattern {pattern} joint {i}: {} vs {}", x[i], y[i]);
                if pieces[i] % 2 == 1 {
                    assert_eq!(x[i], [-0.7, 0.0, 0.9][pieces[i] / 2], "pattern {pattern} joint {i} on its breakpoint exactly");
                }
            }
        }
        assert_eq!(solver.factorizations, factorizations, "no factorization after the first");
    }

    /// A problem that changes little from one solve to the next (a plant stepping on): the last
    /// solve's outcome, sliding joints sliding on and resting ones resting, is the solution most of
    /// the time and is taken without searching the pieces — and every solution meets every condition.
    #[test]
    fn a_slowly_changing_problem_is_solved_by_the_last_outcome_and_meets_every_condition() {
        let mut seed = 0x6A09_E667_F3BC_C908_u64;
        let n = 6;
        let a = random_spd(n, &mut seed);
        let start: Vec<f64> = random_spd(n, &mut seed)[..n].iter().map(|v| 3.0 * v).collect();
        let drift: Vec<f64> = random_spd(n, &mut seed)[n..2 * n].to_vec();
        // bands wide enough that some joints rest, narrow enough that others slide
        let laws: Vec<JointLaw> = (0..n).map(|i| JointLaw { lower: -50.0, upper: 40.0, below: -0.4 - 0.3 * i as f64, above: 0.5 + 0.2 * i as f64 }).collect();
        let mut solver = StickSlipSolver::new(n, None);
        let (mut x, mut g) = (vec![0.0; n], vec![0.0; n]);
        let (solves, mut resting) = (2000, 0);
        for k in 0..solves {
            let b: Vec<f64> = start.iter().zip(&drift).map(|(s, d)| s + 1e-3 * k as f64 * d).collect();
            solver.solve(&a, &[0.0; 6], &b, &laws, &mut x, &mut g).unwrap();
            for i in 0..n {
                let g: f64 = b[i] - (0..n).map(|j| a[j * n + i] * x[j]).sum::<f64>();
                assert!(optimality_violation(&laws[i], x[i], g) < 1e-12, "solve {k} joint {i}: x = {}, g = {g}", x[i]);
            }
            resting += x.iter().filter(|&&xi| xi == 0.0).count();
        }
        assert!(resting > solves && resting < (n - 1) * solves, "some joints rest, some slide: {resting} joint-solves at rest");
        assert!(solver.pivot_iterations < solves as u64 / 10, "the pieces searched in {} of {solves} solves", solver.pivot_iterations);
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
