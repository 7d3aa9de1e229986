//! Rigid contact between weights (`[effects.contact] model = "rigid"`).
//!
//! Weights that touch move as one cluster under a constraint, part when the
//! torque between them would pull, and meet in impacts: dead (the default,
//! balls in oil) or with a stated restitution. No contact stiffness is left,
//! so the explicit method keeps its steps through a touch; the price is an
//! event at every impact and parting, located on the integrator's dense
//! output ([`crate::integrate::events`]).
//!
//! The sized weights of a plane form a ring in race order, fixed for the run
//! (solid weights cannot pass each other). Between each weight and the next
//! along its ring sits a pair, open or linked:
//! - an open pair's event function is its gap: at zero the two meet;
//! - a linked pair's is its contact torque λ (positive pressing): below
//!   −λ_tol the two part (the tolerance is hysteresis against rounding).
//!
//! Maximal runs of linked pairs are clusters. A system sums its members'
//! rows (the λ cancel), eliminates clusters instead of weights in its
//! arrowhead mass matrix, and gives every member the cluster's
//! acceleration; λ then follows from the members' own rows
//! (`RotatingSystem`'s clustered right-hand side, which fills them in through
//! [`Mode::clusters_and_torques`]). Linked members share bit-identical
//! velocities, so their gaps stay put to rounding.

mod events;

/// `impl Events for $system` by rigid contact's event logic, for a system
/// that implements [`Clustered`]: the one registration line a system with
/// rigid contact needs (both frames' systems use it).
#[macro_export]
macro_rules! rigid_contact_events {
    ($system:ty) => {
        impl $crate::integrate::Events for $system {
            fn count(&self) -> usize {
                $crate::model::rigid_contact::Clustered::rigid(self).count()
            }
            fn values(&self, t: f64, y: &[f64], out: &mut [f64]) {
                $crate::model::rigid_contact::values(self, t, y, out);
            }
            fn value(&self, k: usize, t: f64, y: &[f64]) -> f64 {
                $crate::model::rigid_contact::value(self, k, t, y)
            }
            fn handle(
                &self,
                t: f64,
                y: &mut [f64],
                k: usize,
                falling: bool,
            ) -> $crate::integrate::EventFlow {
                $crate::model::rigid_contact::handle(self, t, y, k, falling)
            }
            fn rhs_calls(&self) -> u64 {
                $crate::model::rigid_contact::Clustered::rigid(self).rhs_calls()
            }
            fn project(&self, _t: f64, y: &mut [f64]) -> bool {
                $crate::model::rigid_contact::project(self, y)
            }
            fn clear(&self, t: f64, y: &[f64]) -> bool {
                $crate::model::rigid_contact::mode_holds(
                    self,
                    t,
                    y,
                    $crate::model::rigid_contact::CLEAR_GAP,
                    $crate::model::rigid_contact::CLEAR_PRESS,
                )
            }
            fn rates(&self, _t: f64, y: &[f64], out: &mut [f64]) -> bool {
                $crate::model::rigid_contact::rates(self, y, out);
                true
            }
            fn start(&self, t: f64, y: &mut [f64]) {
                $crate::model::rigid_contact::start(self, t, y);
            }
        }
    };
}

pub use events::{Clustered, handle, mode_holds, project, rates, start, value, values};

use super::cargo::Cargo;
use super::race_ring::for_each_ring;
use std::cell::{RefCell, RefMut};
use std::f64::consts::TAU;

/// λ_tol over the largest weight's I ω²: a parting needs a pull this far
/// past zero, well above the rounding of the torques (about 1e-16 of them)
/// and far below any torque the motion is made of.
const PULL_TOLERANCE: f64 = 1e-9;
/// Closing speeds below this fraction of ω end in a dead impact whatever the
/// restitution: rebounds that small would only chatter (a Zeno sequence).
const STICKING_SPEED: f64 = 1e-6;
/// An open pair's event fires this far (rad) past touching: the pair then
/// links and its gap is moved to zero, so that a later parting starts its
/// gap function this far above its zero rather than on it.
pub const GAP_OFFSET: f64 = 1e-12;
/// A state is clear of events ([`crate::integrate::Events::clear`]) with
/// every open pair this far (rad) apart, the penalty model's margin around
/// its kink (beyond the central differences' step in an angle)...
pub const CLEAR_GAP: f64 = 2.5e-8;
/// ... and every link pressing by this many times the parting tolerance.
pub const CLEAR_PRESS: f64 = 10.0;
/// Pairs within this gap (rad) at the start touch: clustered starts are
/// computed at 2α in floating point.
const TOUCHING_AT_START: f64 = 1e-10;

/// The rigid contact of one system's weights: geometry, tolerances and the
/// run's current mode.
#[derive(Debug)]
pub struct RigidContact {
    /// α_j = asin(r/l) of each weight (0: no size, never touches).
    half_angle: Vec<f64>,
    /// Plane of each weight.
    plane: Vec<usize>,
    /// κ m l² of each weight: a merged cluster's velocity is their
    /// inertia-weighted mean.
    inertia: Vec<f64>,
    /// Parting over closing speed in an impact.
    restitution: f64,
    /// λ below −this parts a link (N·m).
    pull_tolerance: f64,
    /// Closing speeds below this stick (rad/s).
    sticking_speed: f64,
    /// Right-hand sides evaluated for the events (counted in a run's cost).
    rhs_calls: std::cell::Cell<u64>,
    /// Which pairs are linked, the clusters and the latest torques. A
    /// `RefCell` because the integrator sees the system through `&self`;
    /// only events change it, the right-hand side writes λ.
    mode: RefCell<Mode>,
    /// Scratch for a right-hand side evaluated to learn λ and for an
    /// impact's impulse (no allocation per event).
    scratch: RefCell<Scratch>,
}

/// Buffers of [`RigidContact`] reused from call to call.
#[derive(Debug, Default)]
pub struct Scratch {
    /// A derivative the events ask for.
    pub dydt: Vec<f64>,
    /// A generalised impulse on each weight, and the velocity change it makes.
    pub impulse: Vec<f64>,
    /// Velocity change of every coordinate.
    pub response: Vec<f64>,
}

/// Two neighbours along a ring: `ahead` is the next weight along the race
/// in the direction of growing angle.
#[derive(Debug, Clone, PartialEq)]
pub struct RingPair {
    /// The weight behind.
    pub behind: usize,
    /// The weight ahead.
    pub ahead: usize,
    /// The whole turns (2π n) that make ψ_ahead − ψ_behind + this the
    /// forward angle from one to the other: fixed for the run, since the
    /// weights cannot pass, so that the gap is continuous in the angles
    /// however far they turn or overlap (a wrapped difference would jump by
    /// a turn at an overlap a step can cross).
    turns: f64,
}

/// Which pairs are linked, and what follows from it.
#[derive(Debug, Clone, Default)]
pub struct Mode {
    /// Every pair, ring after ring.
    pairs: Vec<RingPair>,
    /// Weights of each ring, in race order.
    rings: Vec<Vec<usize>>,
    /// Index of each ring's first pair.
    ring_pairs: Vec<usize>,
    /// Whether each pair is linked.
    linked: Vec<bool>,
    /// How many are (kept by [`Mode::rebuild`]: the right-hand side asks
    /// on every call).
    links: usize,
    /// Contact torque of each linked pair from the latest right-hand side
    /// (N·m, positive pressing); 0 for open pairs.
    torque: Vec<f64>,
    /// The clusters of the current links.
    clusters: Clusters,
    /// The (t, y) the torques were recorded at, while the links have not
    /// changed since: an explicit method's last stage is its step's end, so
    /// the events read the torques it left instead of a call of their own.
    torques_at: Option<(f64, Vec<f64>)>,
}

/// Maximal linked runs of weights (a weight alone is a cluster of one).
#[derive(Debug, Clone, Default)]
pub struct Clusters {
    /// Weights cluster after cluster, each cluster in race order.
    members: Vec<usize>,
    /// One past each cluster's last entry in `members`.
    ends: Vec<usize>,
    /// The pair linking `members[i]` to `members[i + 1]` in one cluster
    /// (`usize::MAX` after a cluster's last member).
    link_after: Vec<usize>,
}

impl Clusters {
    /// Number of clusters.
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// True when there is no weight.
    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// The weights of cluster `c`, in race order.
    pub fn members(&self, c: usize) -> &[usize] {
        let start = if c == 0 { 0 } else { self.ends[c - 1] };
        &self.members[start..self.ends[c]]
    }

    /// The links of cluster `c`: entry i joins member i to member i + 1.
    pub fn links(&self, c: usize) -> &[usize] {
        let start = if c == 0 { 0 } else { self.ends[c - 1] };
        &self.link_after[start..self.ends[c] - 1]
    }
}

impl Mode {
    /// The clusters of the current links.
    pub fn clusters(&self) -> &Clusters {
        &self.clusters
    }

    /// Whether any pair is linked (otherwise every weight moves alone).
    pub fn any_linked(&self) -> bool {
        self.links > 0
    }

    /// The clusters, and the torques of the links to fill in (a
    /// right-hand side computes them with the accelerations).
    pub fn clusters_and_torques(&mut self) -> (&Clusters, &mut [f64]) {
        (&self.clusters, &mut self.torque)
    }

    /// Note that the torques just recorded are those at (t, y).
    pub fn recorded_at(&mut self, t: f64, y: &[f64]) {
        match &mut self.torques_at {
            Some((at, state)) if state.len() == y.len() => {
                *at = t;
                state.copy_from_slice(y);
            }
            slot => *slot = Some((t, y.to_vec())),
        }
    }

    /// Whether the torques are those at (t, y) under the current links.
    fn torques_current(&self, t: f64, y: &[f64]) -> bool {
        self.torques_at
            .as_ref()
            .is_some_and(|(at, state)| *at == t && state[..] == *y)
    }

    /// Whether pair `k`'s ring has an open pair other than `k` (so that
    /// linking `k` leaves the ring a place to start its clusters).
    fn open_elsewhere_in_ring(&self, k: usize) -> bool {
        let ring = self.ring_pairs.partition_point(|&p| p <= k) - 1;
        let ring_first = self.ring_pairs[ring];
        let ring_len = self.rings[ring].len();
        (ring_first..ring_first + ring_len).any(|p| p != k && !self.linked[p])
    }

    /// Rebuild the clusters from the links (after an event).
    fn rebuild(&mut self, weights: usize) {
        self.torques_at = None;
        self.links = self.linked.iter().filter(|&&l| l).count();
        let c = &mut self.clusters;
        c.members.clear();
        c.ends.clear();
        c.link_after.clear();
        let mut in_ring = vec![false; weights];
        for (r, ring) in self.rings.iter().enumerate() {
            let m = ring.len();
            for &j in ring {
                in_ring[j] = true;
            }
            let first_pair = self.ring_pairs[r];
            let pairs = if m >= 2 { m } else { 0 };
            // Start after an open pair, so that no cluster wraps past the
            // ring's start (a fully linked ring is never made).
            let open = (0..pairs).find(|&i| !self.linked[first_pair + i]);
            let begin = open.map_or(0, |i| (i + 1) % m.max(1));
            for step in 0..m {
                let pos = (begin + step) % m;
                c.members.push(ring[pos]);
                let link = first_pair + pos;
                if pairs > 0 && step + 1 < m && self.linked[link] {
                    c.link_after.push(link);
                } else {
                    c.link_after.push(usize::MAX);
                    c.ends.push(c.members.len());
                }
            }
        }
        for (j, inside) in in_ring.iter().enumerate() {
            if !inside {
                c.members.push(j);
                c.link_after.push(usize::MAX);
                c.ends.push(c.members.len());
            }
        }
    }
}

impl RigidContact {
    /// The rigid contact of these weights at nominal speed `omega`.
    pub fn new(cargo: &[Cargo], omega: f64, restitution: f64) -> Self {
        let largest = cargo.iter().map(Cargo::inertia).fold(0.0, f64::max);
        RigidContact {
            half_angle: cargo.iter().map(Cargo::contact_half_angle).collect(),
            plane: cargo.iter().map(|c| c.plane).collect(),
            inertia: cargo.iter().map(Cargo::inertia).collect(),
            restitution,
            pull_tolerance: PULL_TOLERANCE * largest * omega * omega,
            sticking_speed: STICKING_SPEED * omega,
            rhs_calls: std::cell::Cell::new(0),
            mode: RefCell::new(Mode::default()),
            scratch: RefCell::new(Scratch::default()),
        }
    }

    /// The run's current mode (the right-hand side reads the clusters and
    /// writes the torques).
    pub fn mode(&self) -> RefMut<'_, Mode> {
        self.mode.borrow_mut()
    }

    /// The buffers the systems fill for the events.
    pub fn scratch(&self) -> RefMut<'_, Scratch> {
        self.scratch.borrow_mut()
    }

    /// How contact is modelled by a system that holds rigid contact (or
    /// not) and has the penalty contact effect among its effects (or not):
    /// "rigid", "penalty" or none.
    pub fn model_name(rigid: bool, penalty: bool) -> Option<&'static str> {
        if rigid {
            Some("rigid")
        } else {
            penalty.then_some("penalty")
        }
    }

    /// Right-hand sides evaluated for the events so far.
    pub fn rhs_calls(&self) -> u64 {
        self.rhs_calls.get()
    }

    /// Number of event functions: one per pair (known once the run has started).
    pub fn count(&self) -> usize {
        self.mode.borrow().pairs.len()
    }

    /// The gap (rad) of `pair` at angles `psi`: their centre angle along
    /// the race less the touching angle α_b + α_a.
    pub fn gap(&self, pair: &RingPair, psi: &[f64]) -> f64 {
        psi[pair.ahead] - psi[pair.behind] + pair.turns
            - (self.half_angle[pair.behind] + self.half_angle[pair.ahead])
    }

    /// Move weights that start overlapping apart, onto touching: along
    /// each ring from the end of its widest gap, each weight is pushed
    /// ahead to at least its touching angle past the one before. A start
    /// built in code may overlap (scene files refuse it); penalty contact
    /// would push such weights apart in the first instants, rigid contact
    /// needs them apart before it can begin.
    fn unfold(&self, psi: &mut [f64]) {
        let mode = self.mode.borrow();
        for ring in &mode.rings {
            let m = ring.len();
            if m < 2 {
                continue;
            }
            let forward = |a: usize, b: usize, psi: &[f64]| (psi[b] - psi[a]).rem_euclid(TAU);
            let widest = (0..m)
                .max_by(|&a, &b| {
                    let gap = |i: usize| forward(ring[i], ring[(i + 1) % m], psi);
                    gap(a).total_cmp(&gap(b))
                })
                .unwrap_or(0);
            let begin = (widest + 1) % m;
            // Unwrapped angles along the ring as given (each the one
            // before plus the forward angle to it), then pushed apart.
            let mut given = psi[ring[begin]];
            let mut pushed = given;
            let mut shifts = Vec::with_capacity(m);
            for step in 1..m {
                let (prev, j) = (ring[(begin + step - 1) % m], ring[(begin + step) % m]);
                given += forward(prev, j, psi);
                pushed = given.max(pushed + self.half_angle[prev] + self.half_angle[j]);
                shifts.push((j, pushed - given));
            }
            for (j, shift) in shifts {
                psi[j] += shift;
            }
        }
    }

    /// Find the rings and pairs at angles `psi`, every pair open.
    fn arrange(&self, psi: &[f64]) {
        let n = psi.len();
        let mut mode = self.mode.borrow_mut();
        let mode = &mut *mode;
        mode.rings.clear();
        mode.pairs.clear();
        mode.ring_pairs.clear();
        for_each_ring(
            n,
            |j| self.plane[j],
            |j| self.half_angle[j] > 0.0,
            |j| psi[j],
            |ring| {
                if ring.is_empty() {
                    return;
                }
                mode.ring_pairs.push(mode.pairs.len());
                let m = ring.len();
                if m >= 2 {
                    for i in 0..m {
                        let (behind, ahead) = (ring[i] as usize, ring[(i + 1) % m] as usize);
                        // Sorted by angle: the forward angle is in [0, 2π).
                        let d = psi[ahead] - psi[behind];
                        let turns = TAU * ((d.rem_euclid(TAU) - d) / TAU).round();
                        mode.pairs.push(RingPair {
                            behind,
                            ahead,
                            turns,
                        });
                    }
                }
                mode.rings.push(ring.iter().map(|&j| j as usize).collect());
            },
        );
        mode.linked = vec![false; mode.pairs.len()];
        mode.torque = vec![0.0; mode.pairs.len()];
        mode.rebuild(n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(plane: usize) -> Cargo {
        Cargo {
            radius: 0.01,
            plane,
            ..Cargo::point(0.05, 0.1, 0.0, 1.4)
        }
    }

    #[test]
    fn clusters_are_the_linked_runs_of_each_ring() {
        let cargo = vec![
            ball(0),
            ball(0),
            ball(0),
            ball(0),
            Cargo::point(0.1, 0.1, 0.0, 1.0),
        ];
        let rc = RigidContact::new(&cargo, 100.0, 0.0);
        // Race order 2, 0, 3, 1 (by angle); weight 4 has no size.
        rc.arrange(&[1.0, 3.0, 0.5, 2.0, 0.0]);
        let mut mode = rc.mode();
        assert_eq!(mode.rings, vec![vec![2, 0, 3, 1]]);
        let pairs: Vec<_> = mode.pairs.iter().map(|p| (p.behind, p.ahead)).collect();
        assert_eq!(pairs, vec![(2, 0), (0, 3), (3, 1), (1, 2)]);
        // Link 1→2 across the ring's start, and 0→3.
        mode.linked[3] = true;
        mode.linked[1] = true;
        mode.rebuild(5);
        let c = mode.clusters().clone();
        let all: Vec<Vec<usize>> = (0..c.len()).map(|i| c.members(i).to_vec()).collect();
        assert_eq!(all, vec![vec![0, 3], vec![1, 2], vec![4]]);
        assert_eq!(c.links(0), &[1]);
        assert_eq!(c.links(1), &[3]);
        assert!(c.links(2).is_empty());
    }

    #[test]
    fn a_gap_is_the_forward_angle_less_the_touching_angle() {
        let cargo = vec![ball(0), ball(0)];
        let rc = RigidContact::new(&cargo, 100.0, 0.0);
        let two_alpha = 2.0 * cargo[0].contact_half_angle();
        let gaps = |arranged_at: &[f64], psi: &[f64]| {
            rc.arrange(arranged_at);
            let mode = rc.mode.borrow();
            let pair = |b: usize, a: usize| {
                let p = mode.pairs.iter().find(|p| (p.behind, p.ahead) == (b, a));
                rc.gap(p.expect("both pairs of a ring of two"), psi)
            };
            (pair(0, 1), pair(1, 0))
        };
        // Across 2π: the near pair's forward angle is 2α + 0.01.
        let psi = [6.2, 6.2 + two_alpha + 0.01];
        let (near, far) = gaps(&psi, &psi);
        assert!((near - 0.01).abs() < 1e-12);
        // The other side of a ring of two is the rest of the turn.
        assert!((far - (TAU - 2.0 * two_alpha - 0.01)).abs() < 1e-12);
        // Two close weights: the far pair is open by the rest of the turn.
        let psi = [0.0, two_alpha + 0.05];
        let (_, far) = gaps(&psi, &psi);
        assert!((far - (TAU - 2.0 * two_alpha - 0.05)).abs() < 1e-12);
        // Later, however far the pair turns or sinks in, the gap moves with
        // the angles: no jump of a turn.
        let later = [-60.0, -60.0 + two_alpha - 0.3];
        let (near, _) = gaps(&psi, &later);
        assert!((near + 0.3).abs() < 1e-9, "{near}");
    }
}
