//! Events of a hybrid system, as SciPy's `solve_ivp(events=…)` and Hairer's
//! SOLOUT locate them: state functions g_k(t, y) whose zero crossing changes
//! the system (an impact, a contact that opens) or ends the run. After each
//! accepted step the driver compares every g_k at the step's two ends; where
//! one changed sign it finds the crossing on the step's dense output, hands
//! the observer the step up to it, lets the system change its state there,
//! and restarts the method from that state.
//!
//! Like SciPy's, the test sees sign changes at step ends only: a function
//! that crosses zero twice within one step is not seen. Written here because
//! the root is sought on this crate's own dense output (no root-finding
//! crate takes an interpolant by reference without allocating per call).

/// What the run does after an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventFlow {
    /// Go on from the (possibly changed) state.
    Continue,
    /// End the run at the event.
    Stop,
}

/// The event functions of a hybrid system and what happens at their zeros.
pub trait Events {
    /// Number of event functions.
    fn count(&self) -> usize;
    /// g_k(t, y) for every k into `out` (length [`Events::count`]).
    fn values(&self, t: f64, y: &[f64], out: &mut [f64]);
    /// g_k(t, y) alone: what the search for a crossing evaluates, so a
    /// system whose functions differ in cost (a gap against a force) pays
    /// for the one sought. The default evaluates them all.
    fn value(&self, k: usize, t: f64, y: &[f64]) -> f64 {
        let mut g = vec![0.0; self.count()];
        self.values(t, y, &mut g);
        g[k]
    }
    /// Function `k` reached zero at (t, y), falling (from positive) when
    /// `falling`: change `y` in place (an impulse, a new mode) and say
    /// whether the run goes on.
    fn handle(&self, t: f64, y: &mut [f64], k: usize, falling: bool) -> EventFlow;
    /// dg_k/dt at (t, y) into `out` for the functions whose rate is cheap
    /// (0 for the others), and return true; or return false (the default).
    /// With rates, a function that falls and rises again within one step
    /// is searched for a dip below zero between the step's ends, which the
    /// test at the ends alone cannot see.
    fn rates(&self, _t: f64, _y: &[f64], _out: &mut [f64]) -> bool {
        false
    }
    /// Whether (t, y) lies inside the current mode with room to spare, so
    /// that a smooth flow from it can be trusted for a while (e.g. by a
    /// linearisation). The default: no event function at its zero.
    fn clear(&self, t: f64, y: &[f64]) -> bool {
        let mut g = vec![0.0; self.count()];
        self.values(t, y, &mut g);
        g.iter().all(|&g| g != 0.0)
    }
    /// After an accepted step, move the state back onto the current mode's
    /// constraints where the method let it drift (an implicit method's
    /// Newton iterations need not keep linked weights' velocities equal),
    /// and say whether it changed. The default: nothing to keep.
    fn project(&self, _t: f64, _y: &mut [f64]) -> bool {
        false
    }
    /// Right-hand sides the events have evaluated so far (e.g. for a force
    /// their functions read), beyond the integrator's own: a run's cost
    /// counts them. The default: none.
    fn rhs_calls(&self) -> u64 {
        0
    }
    /// Put the initial state (t0, y) into a mode the system can start from
    /// (e.g. link weights that start touching), before the first step; the
    /// default leaves it as it is.
    fn start(&self, _t: f64, _y: &mut [f64]) {}
}

/// Whether g went from one side of zero to the other (or onto it) between
/// two step ends; a function that starts the step at zero (just handled)
/// has not crossed.
pub(crate) fn crossed(before: f64, after: f64) -> bool {
    (before > 0.0 && after <= 0.0) || (before < 0.0 && after >= 0.0)
}

/// Whether g, not rising at the step's start (rate `r0` ≤ 0: a pair that
/// has just parted starts at rest) and rising at its end (`r1` > 0), may
/// have dipped below zero in between: only when its ends are within twice
/// the step's largest rate times the step length of zero (a dip below both
/// ends is at most about that deep).
pub(crate) fn may_dip(g: (f64, f64), r: (f64, f64), h: f64) -> bool {
    r.0 <= 0.0
        && r.1 > 0.0
        && g.0 > 0.0
        && g.1 > 0.0
        && g.0.min(g.1) <= 2.0 * h * r.0.abs().max(r.1)
}

/// Whether g, falling at both of the step's ends (rates `r0` < 0 and
/// `r1` ≤ 0) yet higher at its end than at its start, may have dipped below
/// zero in between: it rose somewhere, so it is not monotone, and from
/// within reach of zero (its start within `h`·|r0| of it) it may have gone
/// under first. The step's ends disagree with a smooth fall there (an
/// explicit method's error in a gap, far below the tolerance on the angles
/// it is the difference of, after an impact left a pair closing at a
/// picoradian), so the dense output is scanned rather than searched as one
/// valley.
pub(crate) fn may_dip_unevenly(g: (f64, f64), r: (f64, f64), h: f64) -> bool {
    r.0 < 0.0 && r.1 <= 0.0 && g.0 > 0.0 && g.1 > g.0 && g.0 <= h * r.0.abs()
}

/// Interior points at which a step's dense output is scanned for an uneven
/// dip: a dip seen so far spanned a third of its step.
const DIP_SCAN_POINTS: usize = 16;

/// The first point (t, g) of an even scan of g over (a, b) at or below
/// zero; else the bottom of the valley around the scan's lowest point
/// ([`lowest`] between its neighbours).
pub(crate) fn scan_for_dip(mut g: impl FnMut(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let at = |i: usize| a + (b - a) * i as f64 / (DIP_SCAN_POINTS + 1) as f64;
    let mut low = (0, f64::INFINITY);
    for i in 1..=DIP_SCAN_POINTS {
        let value = g(at(i));
        if value <= 0.0 {
            return (at(i), value);
        }
        if value < low.1 {
            low = (i, value);
        }
    }
    lowest(g, at(low.0 - 1), at(low.0 + 1))
}

/// Golden-section steps of the search for a dip: the bracket shrinks to
/// 0.618⁴⁰ ≈ 4·10⁻⁹ of the step.
const DIP_ITERATIONS: usize = 40;

/// The lowest point (t, g) of g on [a, b], found by golden-section search
/// (g is taken as having one minimum in the step, as a function that falls
/// and then rises does).
pub(crate) fn lowest(mut g: impl FnMut(f64) -> f64, mut a: f64, mut b: f64) -> (f64, f64) {
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    let mut x1 = b - ratio * (b - a);
    let mut x2 = a + ratio * (b - a);
    let (mut g1, mut g2) = (g(x1), g(x2));
    for _ in 0..DIP_ITERATIONS {
        if g1 <= g2 {
            b = x2;
            x2 = x1;
            g2 = g1;
            x1 = b - ratio * (b - a);
            g1 = g(x1);
        } else {
            a = x1;
            x1 = x2;
            g1 = g2;
            x2 = a + ratio * (b - a);
            g2 = g(x2);
        }
    }
    if g1 <= g2 { (x1, g1) } else { (x2, g2) }
}

/// Iterations of the root search at most: the Illinois method gains about
/// 1.44 digits per evaluation; 100 halve any bracket well past rounding.
const MAX_ITERATIONS: usize = 100;

/// The time in (a, b] at which g, continuous with g(a) = ga and g(b) = gb of
/// opposite signs (or gb = 0), reaches zero: the Illinois variant of regula
/// falsi (Dowell and Jarratt 1971), to within a few units of rounding in t.
/// The result is the bracket's end on the far side, so that the state there
/// has crossed.
pub(crate) fn first_root(
    mut g: impl FnMut(f64) -> f64,
    (mut a, mut ga): (f64, f64),
    (mut b, mut gb): (f64, f64),
) -> f64 {
    if gb == 0.0 {
        return b;
    }
    // Which end was retained last: -1 a, +1 b (halve its value, Illinois).
    let mut side = 0i8;
    for _ in 0..MAX_ITERATIONS {
        let tol = 4.0 * f64::EPSILON * a.abs().max(b.abs()).max(f64::MIN_POSITIVE);
        if b - a <= tol {
            break;
        }
        let mut t = b - gb * (b - a) / (gb - ga);
        // Stay strictly inside: a secant on rounding-level values can land
        // on an end.
        if !(t > a && t < b) {
            t = 0.5 * (a + b);
        }
        let gt = g(t);
        if gt == 0.0 {
            return t;
        }
        if (gt > 0.0) == (ga > 0.0) {
            a = t;
            ga = gt;
            if side == -1 {
                gb *= 0.5;
            }
            side = -1;
        } else {
            b = t;
            gb = gt;
            if side == 1 {
                ga *= 0.5;
            }
            side = 1;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_root_of_a_smooth_function_is_found_to_rounding() {
        // "To rounding": within the search's own 4 ε·|t|.
        let within = |t: f64, want: f64| (t - want).abs() <= 4.0 * f64::EPSILON * want;
        let root = first_root(f64::cos, (0.0, 1.0), (3.0, 3f64.cos()));
        assert!(within(root, std::f64::consts::FRAC_PI_2), "{root}");
        // A flat end (the plain secant would crawl from one side).
        let g = |t: f64| t.powi(5) - 0.5;
        let root = first_root(g, (0.0, -0.5), (2.0, g(2.0)));
        assert!(within(root, 0.5f64.powf(0.2)), "{root}");
        assert!(g(root) >= 0.0, "the far side of the crossing");
    }

    #[test]
    fn an_uneven_dip_is_scanned_for() {
        // Falls at both ends, ends higher than it starts: a dip below zero
        // near the start, g = 1e-12 − t + 3t² − 1.9t³ on [0, 1] (rates −1 and
        // −0.7; below zero from about 1e-12 to 0.478).
        let g = |t: f64| 1e-12 - t + 3.0 * t * t - 1.9 * t * t * t;
        let dg = |t: f64| -1.0 + 6.0 * t - 5.7 * t * t;
        assert!(g(1.0) > g(0.0) && dg(1.0) < 0.0);
        assert!(may_dip_unevenly((g(0.0), g(1.0)), (dg(0.0), dg(1.0)), 1.0));
        assert!(!may_dip((g(0.0), g(1.0)), (dg(0.0), dg(1.0)), 1.0));
        let (t, low) = scan_for_dip(g, 0.0, 1.0);
        assert!(low <= 0.0 && t > 0.0 && t < 0.478, "{t} {low}");
        // A monotone fall that stays above zero: no uneven dip to seek.
        assert!(!may_dip_unevenly((1.0, 0.5), (-1.0, -0.1), 1.0));
        // Rising at the end: the unimodal search's case, not this one.
        assert!(!may_dip_unevenly((1e-12, 0.5), (-1.0, 0.1), 1.0));
        // A shallow valley between scan points is found by the refinement.
        let narrow = |t: f64| (t - 0.5).abs() - 1e-3;
        let (t, low) = scan_for_dip(narrow, 0.0, 1.0);
        assert!(low <= 0.0 && (t - 0.5).abs() < 1e-3, "{t} {low}");
    }

    #[test]
    fn a_dip_inside_a_step_is_found() {
        // g = (t − 0.5)² − 0.01 dips below zero between ends at +0.24.
        let g = |t: f64| (t - 0.5) * (t - 0.5) - 0.01;
        assert!(may_dip((g(0.0), g(1.0)), (-1.0, 1.0), 1.0));
        let (t, low) = lowest(g, 0.0, 1.0);
        assert!((t - 0.5).abs() < 1e-6 && low < 0.0, "{t} {low}");
        // Far from zero for its rates: no search.
        assert!(!may_dip((5.0, 5.0), (-1.0, 1.0), 1.0));
        assert!(!may_dip((0.1, 0.1), (1.0, 1.0), 1.0));
    }

    #[test]
    fn a_crossing_is_a_change_of_side() {
        assert!(crossed(1.0, -1.0) && crossed(-1.0, 2.0) && crossed(1.0, 0.0));
        assert!(!crossed(0.0, -1.0) && !crossed(1.0, 2.0) && !crossed(-1.0, -0.5));
    }
}
