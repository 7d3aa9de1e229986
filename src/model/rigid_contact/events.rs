//! What happens at rigid contact's events: the start's links, impacts,
//! partings, and the loop that opens every link that would pull. The
//! systems supply their equations through [`Clustered`]; the logic is the
//! same in every frame.

use super::{GAP_OFFSET, RigidContact, RingPair, TOUCHING_AT_START};
use crate::integrate::{EventFlow, OdeSystem};

/// A system whose weights may be held in clusters by rigid contact.
pub trait Clustered: OdeSystem {
    /// Its rigid contact.
    fn rigid(&self) -> &RigidContact;
    /// Index of the first weight's angle ψ_0 in q.
    fn first_weight(&self) -> usize;
    /// Number of generalised coordinates (q̇ starts there in the state).
    fn coordinates(&self) -> usize;
    /// The velocity change of every coordinate, `response` (length
    /// [`Clustered::coordinates`]), that the generalised impulse `impulse`
    /// on the weights (one per weight) makes at state y: M⁻¹ times it, with
    /// the current clusters moving as one.
    fn impulse_response(&self, t: f64, y: &[f64], impulse: &[f64], response: &mut [f64]);
}

/// Choose the starting mode: link every pair that starts touching and not
/// parting (a clustered start), as a dead impact, then open every link that
/// would pull.
pub fn start<S: Clustered + ?Sized>(system: &S, t: f64, y: &mut [f64]) {
    let rc = system.rigid();
    let (first, nq) = (system.first_weight(), system.coordinates());
    let n = rc.half_angle.len();
    rc.arrange(&y[first..first + n]);
    rc.unfold(&mut y[first..first + n]);
    {
        let mut s = rc.scratch();
        s.dydt.resize(y.len(), 0.0);
        s.impulse.resize(n, 0.0);
        s.response.resize(nq, 0.0);
    }
    resolve(system, t, y, TOUCHING_AT_START, true);
}

/// g_k(t, y) for every pair: an open pair's gap past [`GAP_OFFSET`], a
/// linked pair's torque past −λ_tol.
pub fn values<S: Clustered + ?Sized>(system: &S, t: f64, y: &[f64], out: &mut [f64]) {
    let rc = system.rigid();
    current_torques(system, t, y);
    let first = system.first_weight();
    let psi = &y[first..first + rc.half_angle.len()];
    let mode = rc.mode.borrow();
    for (k, g) in out.iter_mut().enumerate() {
        *g = if mode.linked[k] {
            mode.torque[k] + rc.pull_tolerance
        } else {
            rc.gap(&mode.pairs[k], psi) + GAP_OFFSET
        };
    }
}

/// g_k(t, y) of one pair: an open pair's gap needs the angles alone.
pub fn value<S: Clustered + ?Sized>(system: &S, k: usize, t: f64, y: &[f64]) -> f64 {
    let rc = system.rigid();
    let (pair, linked) = {
        let mode = rc.mode.borrow();
        (mode.pairs[k].clone(), mode.linked[k])
    };
    if !linked {
        let first = system.first_weight();
        return rc.gap(&pair, &y[first..first + rc.half_angle.len()]) + GAP_OFFSET;
    }
    if !rc.mode.borrow().torques_current(t, y) {
        refresh_torques(system, t, y);
    }
    rc.mode.borrow().torque[k] + rc.pull_tolerance
}

/// dg_k/dt for the open pairs (the closing rate, from the state alone); 0
/// for links, whose torque's rate would cost a derivative of the forces.
pub fn rates<S: Clustered + ?Sized>(system: &S, y: &[f64], out: &mut [f64]) {
    let rc = system.rigid();
    let (first, nq) = (system.first_weight(), system.coordinates());
    let mode = rc.mode.borrow();
    for (k, r) in out.iter_mut().enumerate() {
        let RingPair { behind, ahead, .. } = mode.pairs[k];
        *r = if mode.linked[k] {
            0.0
        } else {
            y[nq + first + ahead] - y[nq + first + behind]
        };
    }
}

/// Pair `k`'s function reached zero at (t, y): a link parts, or an open
/// pair meets in an impact. A gap growing through its zero (a pair that
/// touched without closing) changes nothing.
pub fn handle<S: Clustered + ?Sized>(
    system: &S,
    t: f64,
    y: &mut [f64],
    k: usize,
    falling: bool,
) -> EventFlow {
    let rc = system.rigid();
    let linked = rc.mode.borrow().linked[k];
    if linked && falling {
        unlink(rc, k);
    }
    // A gap growing through its zero (a pair that touched without closing)
    // changes nothing; `resolve` finds every pair that meets, this one and
    // any other at touching (to the event's offset) and closing.
    resolve(system, t, y, GAP_OFFSET, false);
    EventFlow::Continue
}

/// Most rounds of impacts and partings at one instant: each round makes
/// the touching pairs stop closing and then settles which of them press; a
/// few suffice for any cluster seen (a cascade runs along a ring once).
const MAX_ROUNDS: usize = 64;

/// Most flips of one settling of the links ([`settle_links`]): least-index
/// pivoting ends on any contact problem of this kind, in a few flips per
/// pair in practice; the bound only guards against rounding that makes a
/// pair's force flicker about zero.
const MAX_FLIPS: usize = 256;

/// Settle the mode at (t, y): every open pair within `touching` (rad) of
/// touching and closing meets in an impact, and then the links are settled
/// ([`settle_links`]), until neither changes anything. Several pairs may
/// touch at once, and one impact may drive the next pair together:
/// pairwise dead impacts repeated until none closes converge to the
/// simultaneous one (each round takes a fixed share of the closing speed;
/// without the rounds here, every round was an event of its own,
/// nanoseconds apart). With `at_rest` (the start), a touching pair that is
/// not closing links too, in the first round only: later rounds would
/// relink every pair the settling had opened.
fn resolve<S: Clustered + ?Sized>(system: &S, t: f64, y: &mut [f64], touching: f64, at_rest: bool) {
    for round in 0..MAX_ROUNDS {
        let met = meet_closing_pairs(system, t, y, touching, at_rest && round == 0);
        let settled = settle_links(system, t, y, touching.max(GAP_OFFSET));
        if !met && !settled {
            return;
        }
    }
}

/// Every open pair within `touching` of touching and closing meets in an
/// impact (with `at_rest`, one at rest relative to each other links with no
/// impulse); whether any did.
fn meet_closing_pairs<S: Clustered + ?Sized>(
    system: &S,
    t: f64,
    y: &mut [f64],
    touching: f64,
    at_rest: bool,
) -> bool {
    let rc = system.rigid();
    let (first, nq) = (system.first_weight(), system.coordinates());
    let n = rc.half_angle.len();
    let mut met = false;
    let count = rc.mode.borrow().pairs.len();
    for k in 0..count {
        let (pair, linked) = {
            let mode = rc.mode.borrow();
            (mode.pairs[k].clone(), mode.linked[k])
        };
        let RingPair { behind, ahead, .. } = pair;
        if linked || rc.gap(&pair, &y[first..first + n]) > touching {
            continue;
        }
        let closing = y[nq + first + ahead] - y[nq + first + behind];
        if closing > 0.0 || (closing == 0.0 && !at_rest) {
            continue;
        }
        let e = if -closing < rc.sticking_speed {
            0.0
        } else {
            rc.restitution
        };
        impact(system, t, y, k, e);
        met = true;
    }
    met
}

/// One change [`settle_links`] makes.
enum Flip {
    /// Open this link: it pulls.
    Open(usize),
    /// Link this open pair: at touching and at rest, its free motion would
    /// close it.
    Link(usize),
}

/// Decide which of the pairs at touching and at rest relative to each
/// other press, flipping one pair at a time, the lowest-numbered wrong one
/// first: a link that pulls (λ ≤ −λ_tol) opens, and an open pair within
/// `touching` of touching, its relative speed below the sticking speed,
/// whose free motion would close it links. This is least-index principal
/// pivoting (Murty 1974) on the pairs' contact problem, a linear
/// complementarity problem whose matrix D M⁻¹ Dᵀ is positive definite, so
/// it ends at the problem's one solution: every link pressing, every open
/// pair parting. (Opening the link that pulls hardest and relinking after
/// can cycle, and it once left a pair closing at 15 rad/s² open.) A graze
/// counts as at rest: a pair whose gap fell to zero and turned there,
/// parting at a few 1e-8 rad/s while the weights behind press it, would
/// otherwise sink into overlap unseen (its event function starts the next
/// step at zero, from where a fall is no crossing). Whether anything
/// flipped. Each flip costs a right-hand side; none is spent when no pair
/// is linked or resting.
fn settle_links<S: Clustered + ?Sized>(system: &S, t: f64, y: &mut [f64], touching: f64) -> bool {
    let rc = system.rigid();
    let mut flipped = false;
    for _ in 0..MAX_FLIPS {
        let resting = resting_pairs(system, y, touching);
        if resting.is_empty() && !rc.mode.borrow().any_linked() {
            return flipped;
        }
        refresh_torques(system, t, y);
        match first_wrong_pair(system, &resting) {
            Some(Flip::Open(k)) => unlink(rc, k),
            Some(Flip::Link(k)) => impact(system, t, y, k, 0.0),
            None => return flipped,
        }
        flipped = true;
    }
    flipped
}

/// The open pairs within `touching` of touching whose relative speed is
/// below the sticking speed, leaving out any whose link would close its
/// ring (weights that fill the race keep one pair open).
fn resting_pairs<S: Clustered + ?Sized>(system: &S, y: &[f64], touching: f64) -> Vec<usize> {
    let rc = system.rigid();
    let (first, nq) = (system.first_weight(), system.coordinates());
    let n = rc.half_angle.len();
    let mode = rc.mode.borrow();
    (0..mode.pairs.len())
        .filter(|&k| {
            let RingPair { behind, ahead, .. } = mode.pairs[k];
            !mode.linked[k]
                && (y[nq + first + ahead] - y[nq + first + behind]).abs() < rc.sticking_speed
                && rc.gap(&mode.pairs[k], &y[first..first + n]) <= touching
                && mode.open_elsewhere_in_ring(k)
        })
        .collect()
}

/// The lowest-numbered pair whose contact force has the wrong sign at the
/// torques and accelerations just computed: a pulling link, or one of the
/// `resting` open pairs that its free motion closes.
fn first_wrong_pair<S: Clustered + ?Sized>(system: &S, resting: &[usize]) -> Option<Flip> {
    let rc = system.rigid();
    let (first, nq) = (system.first_weight(), system.coordinates());
    let accel = &rc.scratch().dydt;
    let mode = rc.mode.borrow();
    (0..mode.pairs.len()).find_map(|k| {
        if mode.linked[k] {
            (mode.torque[k] <= -rc.pull_tolerance).then_some(Flip::Open(k))
        } else {
            let RingPair { behind, ahead, .. } = mode.pairs[k];
            let closes = accel[nq + first + ahead] < accel[nq + first + behind];
            (closes && resting.contains(&k)).then_some(Flip::Link(k))
        }
    })
}

/// Give every cluster one velocity (inertia-weighted, keeping its momentum)
/// and its links zero gap, where the method let them drift by more than
/// [`GAP_OFFSET`] or at all; whether anything moved. An explicit method
/// gives linked members bit-identical velocities, so for it nothing does.
pub fn project<S: Clustered + ?Sized>(system: &S, y: &mut [f64]) -> bool {
    let rc = system.rigid();
    let (first, nq) = (system.first_weight(), system.coordinates());
    let n = rc.half_angle.len();
    let mode = rc.mode.borrow();
    if !mode.any_linked() {
        return false;
    }
    let mut moved = false;
    for c in 0..mode.clusters.len() {
        let members = mode.clusters.members(c);
        if members.len() < 2 {
            continue;
        }
        let rate = |y: &[f64], j: usize| y[nq + first + j];
        if members.iter().any(|&j| rate(y, j) != rate(y, members[0])) {
            let total: f64 = members.iter().map(|&j| rc.inertia[j]).sum();
            let moment: f64 = members.iter().map(|&j| rc.inertia[j] * rate(y, j)).sum();
            let common = moment / total;
            for &j in members {
                y[nq + first + j] = common;
            }
            moved = true;
        }
        for (i, &link) in mode.clusters.links(c).iter().enumerate() {
            let gap = rc.gap(&mode.pairs[link], &y[first..first + n]);
            if gap.abs() > GAP_OFFSET {
                // The members ahead of the link move onto touching.
                for &j in &members[i + 1..] {
                    y[first + j] -= gap;
                }
                moved = true;
            }
        }
    }
    moved
}

/// Make the mode's torques those at (t, y), unless no link needs one or
/// they already are (an explicit method's last stage leaves them).
fn current_torques<S: Clustered + ?Sized>(system: &S, t: f64, y: &[f64]) {
    let stale = {
        let mode = system.rigid().mode.borrow();
        mode.any_linked() && !mode.torques_current(t, y)
    };
    if stale {
        refresh_torques(system, t, y);
    }
}

/// Evaluate the right-hand side at (t, y) for its side effect: the mode's
/// torques.
fn refresh_torques<S: Clustered + ?Sized>(system: &S, t: f64, y: &[f64]) {
    let rc = system.rigid();
    let mut dydt = std::mem::take(&mut rc.scratch().dydt);
    dydt.resize(y.len(), 0.0);
    system.rhs(t, y, &mut dydt);
    rc.scratch().dydt = dydt;
    rc.rhs_calls.set(rc.rhs_calls.get() + 1);
}

/// Open pair `k` (behind A, ahead B) meets: the impulse along the pair that
/// leaves it parting at `e` times its closing speed, through the whole mass
/// matrix (rotor and other clusters included, as momentum requires). A dead
/// impact (e = 0) links the pair, moves B onto touching and gives the merged
/// cluster one velocity.
fn impact<S: Clustered + ?Sized>(system: &S, t: f64, y: &mut [f64], k: usize, e: f64) {
    let rc = system.rigid();
    let (first, nq) = (system.first_weight(), system.coordinates());
    let n = rc.half_angle.len();
    let pair = rc.mode.borrow().pairs[k].clone();
    let RingPair { behind, ahead, .. } = pair;
    let mut scratch = rc.scratch();
    let scratch = &mut *scratch;
    scratch.impulse.iter_mut().for_each(|p| *p = 0.0);
    scratch.impulse[ahead] = 1.0;
    scratch.impulse[behind] = -1.0;
    system.impulse_response(t, y, &scratch.impulse, &mut scratch.response);
    let (qd, rate_of) = (nq, |y: &[f64], j: usize| y[nq + first + j]);
    let closing = rate_of(y, ahead) - rate_of(y, behind);
    let per_unit = scratch.response[first + ahead] - scratch.response[first + behind];
    if closing < 0.0 && per_unit > 0.0 {
        let size = -(1.0 + e) * closing / per_unit;
        for (v, dv) in y[qd..qd + nq].iter_mut().zip(&scratch.response) {
            *v += size * dv;
        }
    }
    let mut mode = rc.mode.borrow_mut();
    let mode = &mut *mode;
    // B's members move forward by the overlap onto touching (a rebound
    // then starts its gap function above its zero, not on it).
    let overlap = -rc.gap(&pair, &y[first..first + n]);
    let b = (0..mode.clusters.len())
        .find(|&c| mode.clusters.members(c).contains(&ahead))
        .expect("every weight is in a cluster");
    for &j in mode.clusters.members(b) {
        y[first + j] += overlap;
    }
    if e > 0.0 {
        return;
    }
    // A ring all of whose pairs are linked would have no place to start
    // its clusters: weights that fill the race keep one pair open.
    if !mode.open_elsewhere_in_ring(k) {
        return;
    }
    mode.linked[k] = true;
    mode.rebuild(n);
    // One velocity for the merged cluster: the impulse left its members
    // equal to rounding; the inertia-weighted mean keeps its momentum.
    let c = (0..mode.clusters.len())
        .find(|&c| mode.clusters.members(c).contains(&ahead))
        .expect("every weight is in a cluster");
    let inertia = |j: usize| rc.inertia[j];
    let members = mode.clusters.members(c);
    let total: f64 = members.iter().map(|&j| inertia(j)).sum();
    let moment: f64 = members.iter().map(|&j| inertia(j) * rate_of(y, j)).sum();
    let common = moment / total;
    for &j in members {
        y[nq + first + j] = common;
    }
}

/// Open link `k`.
fn unlink(rc: &RigidContact, k: usize) {
    let n = rc.half_angle.len();
    let mut mode = rc.mode.borrow_mut();
    mode.linked[k] = false;
    mode.torque[k] = 0.0;
    mode.rebuild(n);
}

/// Whether the current mode holds at (t, y) with room to spare: every open
/// pair more than `margin` (rad) apart and every link pressing by more than
/// `press` times the parting tolerance. A stretch of the run on which it
/// holds is smooth: no event can fall in it.
pub fn mode_holds<S: Clustered + ?Sized>(
    system: &S,
    t: f64,
    y: &[f64],
    margin: f64,
    press: f64,
) -> bool {
    let rc = system.rigid();
    current_torques(system, t, y);
    let first = system.first_weight();
    let psi = &y[first..first + rc.half_angle.len()];
    let mode = rc.mode.borrow();
    (0..mode.pairs.len()).all(|k| {
        if mode.linked[k] {
            mode.torque[k] > press * rc.pull_tolerance
        } else {
            rc.gap(&mode.pairs[k], psi) > margin
        }
    })
}
