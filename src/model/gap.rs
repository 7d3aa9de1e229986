//! How close neighbouring weights come: the gap between two weights of the
//! same plane is their centre angle about the race centre minus the angle
//! α_j + α_k at which they touch (α = asin(r/l)). A negative gap is an
//! overlap, which solid weights cannot have (docs/metrics.md).

use super::cargo::Cargo;
use super::effect::contact::{ALL_PAIRS_UP_TO, wrapped};
use super::race_ring::{MAX_RING, for_each_neighbour_pair};

/// Two weights (cargo indices j < k) and the gap between them (rad).
pub type PairGap = (u32, u32, f64);

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

    /// [`GapGauge::min_gap`], keeping the pairs it measured (cargo indices
    /// j < k and their gap) in `pairs`: each pair's gap at these angles
    /// bounds it nearby ([`ClosestApproach`]). After an all-pairs fallback
    /// the neighbours are listed twice, which changes no bound.
    pub fn min_gap_of_pairs(&self, psi: &[f64], pairs: &mut Vec<PairGap>) -> f64 {
        pairs.clear();
        self.visit_min_gap(psi, &mut |j, k, gap| pairs.push((j as u32, k as u32, gap)))
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
#[derive(Debug, Clone)]
pub struct ClosestApproach {
    smallest: f64,
    /// The angles of the last sample measured, and its pairs with their gaps.
    anchor: Option<(Vec<f64>, Vec<PairGap>)>,
}

impl Default for ClosestApproach {
    fn default() -> Self {
        ClosestApproach {
            smallest: f64::INFINITY,
            anchor: None,
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
        let gap = gauge.min_gap_of_pairs(psi, pairs);
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
    use crate::model::race_ring::uniform;
    use std::f64::consts::TAU;

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
                let per_plane = n.div_ceil(planes) as f64;
                let base = 0.05 * (0.9 * std::f64::consts::PI / per_plane).sin();
                let cargo: Vec<Cargo> = (0..n)
                    .map(|j| Cargo {
                        radius: base * (0.6 + 0.4 * ((j * 7) % 5) as f64 / 4.0),
                        plane: j % planes,
                        ..Cargo::point(0.01, 0.05, 0.1, 1.4)
                    })
                    .collect();
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
}
