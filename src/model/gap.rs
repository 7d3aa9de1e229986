//! How close neighbouring weights come: the gap between two weights of the
//! same plane is their centre angle about the race centre minus the angle
//! α_j + α_k at which they touch (α = asin(r/l)). A negative gap is an
//! overlap, which solid weights cannot have (docs/metrics.md).

use super::cargo::Cargo;
use super::effect::contact::{ALL_PAIRS_UP_TO, wrapped};
use super::race_ring::{MAX_RING, for_each_neighbour_pair, for_each_ring_pair};
use std::f64::consts::TAU;

/// Two weights (cargo indices j < k) and the gap between them (rad).
pub type PairGap = (u32, u32, f64);

/// Two neighbours along a ring (sized-weight indices, in ring order) and
/// the angle from the first's centre to the second's along the ring (rad).
type RingPair = (u32, u32, f64);

/// The weights that have a size, with their touching half-angles and planes.
#[derive(Debug, Clone, PartialEq)]
pub struct GapGauge {
    sized: Vec<(usize, f64, usize)>,
    /// The smallest touching half-angle α of a sized weight.
    smallest_half_angle: f64,
}

impl GapGauge {
    /// A gauge for these cargoes; `None` when no two weights of one plane
    /// have a size (point masses have no gap to measure).
    pub fn new(cargo: &[Cargo]) -> Option<Self> {
        let sized: Vec<(usize, f64, usize)> = cargo
            .iter()
            .enumerate()
            .filter(|(_, c)| c.radius > 0.0)
            .map(|(j, c)| (j, c.contact_half_angle(), c.plane))
            .collect();
        let pairs = sized
            .iter()
            .enumerate()
            .any(|(a, x)| sized[a + 1..].iter().any(|y| y.2 == x.2));
        let smallest_half_angle = sized.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
        pairs.then_some(GapGauge {
            sized,
            smallest_half_angle,
        })
    }

    /// The smallest gap (rad) over all pairs of one plane at angles ψ.
    ///
    /// Beyond [`ALL_PAIRS_UP_TO`] weights only neighbours along the race
    /// are measured (O(n log n), not O(n²): at n = 32 the all-pairs gauge
    /// was half of a run's time). The result is the all-pairs minimum, bit
    /// for bit, whenever no neighbour overlaps by more than the smallest α:
    /// along the shorter arc from j to k through weights l, the gap of (j, k)
    /// is the sum of the m neighbour gaps on the way plus 2Σα_l over the
    /// m − 1 weights passed, so with every neighbour gap ≥ g it is at least
    /// g + (m − 1)(g + 2α_min) ≥ g once g ≥ −2α_min, with a margin of α_min
    /// at least for rounding. Deeper overlaps (no solid weight gets near
    /// them) fall back to all pairs.
    pub fn min_gap(&self, psi: &[f64]) -> f64 {
        self.visit_min_gap(psi, &mut |_, _, _| {})
    }

    /// The minimum, calling `visit` on every pair measured.
    fn visit_min_gap(&self, psi: &[f64], visit: &mut impl FnMut(usize, usize, f64)) -> f64 {
        let n = self.sized.len();
        if n <= ALL_PAIRS_UP_TO || n > MAX_RING {
            return self.all_pairs_min_gap(psi, visit);
        }
        let neighbours = self.neighbour_min_gap(psi, visit);
        if neighbours >= -self.smallest_half_angle {
            neighbours
        } else {
            self.all_pairs_min_gap(psi, visit)
        }
    }

    /// The gap of sized weights a < b (indices into `sized`), computed as
    /// every path here computes it, so that the minima agree bit for bit.
    #[inline]
    fn pair_gap(&self, a: usize, b: usize, psi: &[f64]) -> f64 {
        let (j, alpha_j, _) = self.sized[a];
        let (k, alpha_k, _) = self.sized[b];
        wrapped(psi[k] - psi[j]).abs() - (alpha_j + alpha_k)
    }

    /// [`GapGauge::min_gap`], keeping the pairs it measured (cargo indices
    /// j < k and their gap) in `pairs`: each pair's gap at these angles
    /// bounds it nearby ([`ClosestApproach`]). After an all-pairs fallback
    /// the neighbours are listed twice, which changes no bound. The
    /// neighbour pairs go to `ring` too, oriented along their ring: (sized
    /// index from, sized index to, the angle from one centre to the next
    /// along the ring, in [0, 2π]; ∞ for a ring of two, whose one pair any
    /// order keeps). `ring` is left empty when every pair was measured.
    fn min_gap_of_ring_pairs(
        &self,
        psi: &[f64],
        pairs: &mut Vec<PairGap>,
        ring: &mut Vec<RingPair>,
    ) -> f64 {
        pairs.clear();
        ring.clear();
        let n = self.sized.len();
        let mut visit = |j: usize, k: usize, gap| pairs.push((j as u32, k as u32, gap));
        if n <= ALL_PAIRS_UP_TO || n > MAX_RING {
            return self.all_pairs_min_gap(psi, &mut visit);
        }
        let angle = |a: usize| psi[self.sized[a].0].rem_euclid(TAU);
        let mut smallest = f64::INFINITY;
        for_each_ring_pair(
            n,
            |a| self.sized[a].2,
            |_| true,
            |a| psi[self.sized[a].0],
            |from, to, len| {
                let (a, b) = (from.min(to), from.max(to));
                let gap = self.pair_gap(a, b, psi);
                visit(self.sized[a].0, self.sized[b].0, gap);
                smallest = smallest.min(gap);
                let along = if len == 2 {
                    f64::INFINITY
                } else {
                    (angle(to) - angle(from)).rem_euclid(TAU)
                };
                ring.push((from as u32, to as u32, along));
            },
        );
        if smallest >= -self.smallest_half_angle {
            smallest
        } else {
            // As `visit_min_gap` does: the neighbours stay listed.
            ring.clear();
            self.all_pairs_min_gap(psi, &mut visit)
        }
    }

    /// The neighbour pairs of `ring` measured at `psi`, if the weights are
    /// still in the ring's order: each pair's angle along the ring, carried
    /// from `psi0` by the change of its two angles, stays above half the
    /// smallest α. Then the neighbours are the same pairs, so the minimum
    /// over them is the one [`GapGauge::min_gap_of_ring_pairs`] would give,
    /// bit for bit, without sorting. The angles along the ring move on to
    /// `psi` and `pairs` takes the new gaps. None if the order may have
    /// changed or an overlap needs every pair: then `pairs` and `ring` are
    /// the caller's to measure afresh.
    fn min_gap_in_same_order(
        &self,
        psi0: &[f64],
        psi: &[f64],
        pairs: &mut [PairGap],
        ring: &mut [RingPair],
    ) -> Option<f64> {
        let margin = 0.5 * self.smallest_half_angle;
        let moved = |a: u32| {
            let j = self.sized[a as usize].0;
            psi[j] - psi0[j]
        };
        // On None the caller measures afresh, rebuilding `pairs` and `ring`.
        let mut smallest = f64::INFINITY;
        for (pair, entry) in pairs.iter_mut().zip(ring.iter_mut()) {
            let (from, to, along) = *entry;
            let along = along + (moved(to) - moved(from));
            // A NaN angle goes the full way too.
            if along <= margin || along.is_nan() {
                return None;
            }
            entry.2 = along;
            let (a, b) = (from.min(to) as usize, from.max(to) as usize);
            pair.2 = self.pair_gap(a, b, psi);
            smallest = smallest.min(pair.2);
        }
        (smallest >= -self.smallest_half_angle).then_some(smallest)
    }

    /// Every pair of one plane: O(n²).
    fn all_pairs_min_gap(&self, psi: &[f64], visit: &mut impl FnMut(usize, usize, f64)) -> f64 {
        let mut smallest = f64::INFINITY;
        for (a, &(_, _, plane_j)) in self.sized.iter().enumerate() {
            for (b, &(_, _, plane_k)) in self.sized.iter().enumerate().skip(a + 1) {
                if plane_k == plane_j {
                    let gap = self.pair_gap(a, b, psi);
                    visit(self.sized[a].0, self.sized[b].0, gap);
                    smallest = smallest.min(gap);
                }
            }
        }
        smallest
    }

    /// Neighbours along the race, plane by plane ([`crate::model::race_ring`]).
    fn neighbour_min_gap(&self, psi: &[f64], visit: &mut impl FnMut(usize, usize, f64)) -> f64 {
        let mut smallest = f64::INFINITY;
        for_each_neighbour_pair(
            self.sized.len(),
            |a| self.sized[a].2,
            |_| true,
            |a| psi[self.sized[a].0],
            |a, b| {
                let gap = self.pair_gap(a, b, psi);
                visit(self.sized[a].0, self.sized[b].0, gap);
                smallest = smallest.min(gap);
            },
        );
        smallest
    }

    /// The smallest touching half-angle α of a sized weight (rad).
    pub fn smallest_half_angle(&self) -> f64 {
        self.smallest_half_angle
    }

    /// Whether every pair of one plane is as far from touching at `later`
    /// as at `now` in kind: apart by more than `margin` at both, or
    /// overlapping (in contact) by more than `margin` at both. A contact
    /// that opens or closes, or sits within `margin` of it, is a kink in
    /// the equations of motion, where no linearisation holds.
    pub fn same_contacts(&self, now: &[f64], later: &[f64], margin: f64) -> bool {
        for (a, &(j, alpha_j, plane_j)) in self.sized.iter().enumerate() {
            for &(k, alpha_k, plane_k) in &self.sized[a + 1..] {
                if plane_k == plane_j {
                    let touch = alpha_j + alpha_k;
                    let g0 = wrapped(now[k] - now[j]).abs() - touch;
                    let g1 = wrapped(later[k] - later[j]).abs() - touch;
                    let apart = g0 > margin && g1 > margin;
                    let pressed = g0 < -margin && g1 < -margin;
                    if !(apart || pressed) {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// The touching angle 2α of the smallest pair (rad), the scale of a gap.
    pub fn contact_angle(&self) -> f64 {
        let mut smallest = f64::INFINITY;
        for (a, &(_, alpha_j, plane_j)) in self.sized.iter().enumerate() {
            for &(_, alpha_k, plane_k) in &self.sized[a + 1..] {
                if plane_k == plane_j {
                    smallest = smallest.min(alpha_j + alpha_k);
                }
            }
        }
        smallest
    }
}

/// The smallest gap over a run's samples, computing the gaps only where
/// they could undercut it. Each pair's gap is 1-Lipschitz in the pair's
/// angle difference (|wrapped(x)| is the distance of x to 2πℤ), so from
/// the last sample measured, ψ₀, with Δ = ψ − ψ₀, a pair measured there
/// keeps gap(ψ) ≥ gap(ψ₀) − |Δ_k − Δ_j|. Pairs not measured (not
/// neighbours at ψ₀) are bounded through the neighbours between them, as
/// in [`GapGauge::min_gap`], while those bounds stay above −α_min. Weights
/// resting against each other in a pack keep their bounds while free ones
/// move: a bound on each pair, not on the fastest weight. The result is the
/// minimum over every sample, bit for bit.
///
/// When a bound fails (a pressed pack keeps its gaps near the minimum, so
/// most samples), a sample whose weights are still in the anchor's order
/// along each ring measures the anchor's neighbour pairs again in O(n), as
/// [`GapGauge::min_gap`] would but without its sort; a pack of 24
/// balls spent a third of its run in the sorts.
#[derive(Debug, Clone)]
pub struct ClosestApproach {
    smallest: f64,
    /// The angles of the last sample measured, and its pairs with their gaps.
    anchor: Option<(Vec<f64>, Vec<PairGap>)>,
    /// The anchor's neighbour pairs in ring order, with their angles along
    /// the ring; empty when the anchor measured every pair.
    ring: Vec<RingPair>,
}

impl Default for ClosestApproach {
    fn default() -> Self {
        ClosestApproach {
            smallest: f64::INFINITY,
            anchor: None,
            ring: Vec::new(),
        }
    }
}

/// Slack on the bound (rad): far beyond the rounding of angle differences
/// even for angles of thousands of radians.
const BOUND_SLACK: f64 = 1e-9;

impl ClosestApproach {
    /// Take the sample at angles ψ into the minimum.
    pub fn sample(&mut self, gauge: &GapGauge, psi: &[f64]) {
        if let Some((psi0, pairs)) = &self.anchor {
            let mut bound = f64::INFINITY;
            for &(j, k, gap0) in pairs {
                let (j, k) = (j as usize, k as usize);
                let moved = ((psi[k] - psi0[k]) - (psi[j] - psi0[j])).abs();
                bound = bound.min(gap0 - moved);
            }
            // NaN fails both tests and is measured below.
            if bound - BOUND_SLACK > self.smallest && bound >= -gauge.smallest_half_angle() {
                return;
            }
        }
        // Reuse the anchor's storage: a sample allocates nothing once the
        // pair list has grown to its size.
        let (psi0, pairs) = self.anchor.get_or_insert_with(|| (Vec::new(), Vec::new()));
        let same_order = if self.ring.is_empty() {
            None
        } else {
            gauge.min_gap_in_same_order(psi0, psi, pairs, &mut self.ring)
        };
        let gap =
            same_order.unwrap_or_else(|| gauge.min_gap_of_ring_pairs(psi, pairs, &mut self.ring));
        self.smallest = self.smallest.min(gap);
        psi0.clear();
        psi0.extend_from_slice(psi);
    }

    /// The smallest gap so far (∞ before any sample).
    pub fn smallest(&self) -> f64 {
        self.smallest
    }
}

/// Two weights of one plane that start closer than they may: their indices
/// (from 0), their centre angle and the angle at which they touch (rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartClash {
    /// First weight.
    pub first: usize,
    /// Second weight.
    pub second: usize,
    /// Their centre angle |Δψ| about the race centre.
    pub apart: f64,
    /// The smallest centre angle they may have: 2α for sized weights; for
    /// point masses, anything but zero.
    pub touching: f64,
}

/// The first pair of weights in one plane whose start angles overlap (sized
/// weights) or coincide (point masses, to within 1e-9 rad, where the
/// symmetric state is an equilibrium they would never leave).
pub fn start_clash(cargo: &[Cargo], angles: &[f64]) -> Option<StartClash> {
    for j in 0..cargo.len() {
        for k in j + 1..cargo.len() {
            if cargo[j].plane != cargo[k].plane {
                continue;
            }
            let apart = wrapped(angles[k] - angles[j]).abs();
            let touching = cargo[j].contact_half_angle() + cargo[k].contact_half_angle();
            // Touching exactly is allowed: a pressed start; allow for rounding.
            let clash = if touching > 0.0 {
                apart < touching * (1.0 - 1e-9)
            } else {
                apart < 1e-9
            };
            if clash {
                return Some(StartClash {
                    first: j,
                    second: k,
                    apart,
                    touching,
                });
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::test_stream::uniform;
    use std::f64::consts::TAU;

    /// n balls dealt to `planes` planes, each plane's race (radius 0.05)
    /// 90 % full at the largest size, the sizes spread over the fraction
    /// `spread` below it.
    fn mixed_balls(n: usize, planes: usize, spread: f64) -> Vec<Cargo> {
        let per_plane = n.div_ceil(planes) as f64;
        let base = 0.05 * (0.9 * std::f64::consts::PI / per_plane).sin();
        (0..n)
            .map(|j| Cargo {
                radius: base * (1.0 - spread + spread * ((j * 7) % 5) as f64 / 4.0),
                plane: j % planes,
                ..Cargo::point(0.01, 0.05, 0.1, 1.4)
            })
            .collect()
    }

    /// Beyond eight weights the gauge measures neighbours only; on packed
    /// states (overlapping, touching, apart), mixed sizes, one or two
    /// planes and angles many turns out, it gives the all-pairs minimum bit
    /// for bit, also where an overlap is deep enough to need the fallback.
    #[test]
    fn neighbours_give_the_all_pairs_minimum_bit_for_bit() {
        let mut seed = 11;
        let (mut fast, mut fallback) = (0, 0);
        for n in [9_usize, 16, 33, 64, 200] {
            for planes in [1, 2] {
                let cargo = mixed_balls(n, planes, 0.4);
                let gauge = GapGauge::new(&cargo).unwrap();
                let largest = cargo
                    .iter()
                    .map(Cargo::contact_half_angle)
                    .fold(0.0, f64::max);
                let pitch = 2.0 * largest;
                for squeeze in [0.3, 0.9, 0.97, 1.0, 1.05, 1.5] {
                    let psi: Vec<f64> = (0..n)
                        .map(|j| {
                            (j / planes) as f64 * pitch * squeeze
                                + 0.1 * pitch * uniform(&mut seed)
                                + 40.0 * (uniform(&mut seed) - 0.5).round() * TAU
                        })
                        .collect();
                    let exact = gauge.all_pairs_min_gap(&psi, &mut |_, _, _| {});
                    let got = gauge.min_gap(&psi);
                    assert_eq!(got.to_bits(), exact.to_bits(), "n = {n}, {squeeze}");
                    if gauge.neighbour_min_gap(&psi, &mut |_, _, _| {})
                        >= -gauge.smallest_half_angle
                    {
                        fast += 1;
                    } else {
                        fallback += 1;
                    }
                }
            }
        }
        assert!(
            fast > 20 && fallback > 0,
            "{fast} fast, {fallback} fallbacks"
        );
    }

    /// Packed weights of mixed sizes rock about their places, the pack
    /// turns many times round the race and one weight swings through its
    /// neighbours now and then: after every sample the closest approach is
    /// the running all-pairs minimum, bit for bit, while most samples are
    /// measured in the anchor's order and some must sort again.
    #[test]
    fn closest_approach_is_the_running_all_pairs_minimum_bit_for_bit() {
        let mut seed = 5;
        let (mut in_order, mut sorted) = (0, 0);
        for n in [5_usize, 9, 24, 64] {
            for planes in [1, 2] {
                let gauge = GapGauge::new(&mixed_balls(n, planes, 0.2)).unwrap();
                let pitch = 2.0 * gauge.smallest_half_angle() * 1.1;
                let phase: Vec<f64> = (0..n).map(|_| TAU * uniform(&mut seed)).collect();
                let mut closest = ClosestApproach::default();
                let mut exact = f64::INFINITY;
                for step in 0..3000 {
                    let t = step as f64 * 0.01;
                    let psi: Vec<f64> = (0..n)
                        .map(|j| {
                            let swing = if j == 3 { 6.0 * (0.3 * t).sin() } else { 0.0 };
                            (j / planes) as f64 * pitch
                                + 0.08 * pitch * (7.0 * t + phase[j]).sin()
                                + pitch * swing
                                + 2.0 * t
                        })
                        .collect();
                    let mut pairs = Vec::new();
                    let mut ring = closest.ring.clone();
                    if let Some((psi0, anchor_pairs)) = &closest.anchor
                        && !ring.is_empty()
                    {
                        pairs.clone_from(anchor_pairs);
                        match gauge.min_gap_in_same_order(psi0, &psi, &mut pairs, &mut ring) {
                            Some(_) => in_order += 1,
                            None => sorted += 1,
                        }
                    }
                    closest.sample(&gauge, &psi);
                    exact = exact.min(gauge.all_pairs_min_gap(&psi, &mut |_, _, _| {}));
                    assert_eq!(
                        closest.smallest().to_bits(),
                        exact.to_bits(),
                        "n = {n}, {planes} planes, step {step}"
                    );
                }
            }
        }
        // A weight that jumps past its neighbours between samples on a
        // sparse race, where no overlap warns of the new order.
        let cargo: Vec<Cargo> = (0..12)
            .map(|_| Cargo {
                radius: 0.004,
                ..Cargo::point(0.01, 0.05, 0.1, 1.4)
            })
            .collect();
        let gauge = GapGauge::new(&cargo).unwrap();
        let spacing = TAU / 12.0;
        let mut closest = ClosestApproach::default();
        let mut exact = f64::INFINITY;
        for step in 0..2000 {
            let psi: Vec<f64> = (0..12)
                .map(|j| match j {
                    0 => 1.37 * spacing * step as f64,
                    _ => j as f64 * spacing + 1e-3 * uniform(&mut seed),
                })
                .collect();
            closest.sample(&gauge, &psi);
            exact = exact.min(gauge.all_pairs_min_gap(&psi, &mut |_, _, _| {}));
            assert_eq!(
                closest.smallest().to_bits(),
                exact.to_bits(),
                "jumper, step {step}"
            );
        }
        eprintln!("{in_order} samples could be measured in order, {sorted} not");
        assert!(
            in_order > 3_000 && sorted > 20,
            "{in_order} in order, {sorted} sorted"
        );
    }
}
