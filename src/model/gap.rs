//! How close neighbouring weights come: the gap between two weights of the
//! same plane is their centre angle about the race centre minus the angle
//! α_j + α_k at which they touch (α = asin(r/l)). A negative gap is an
//! overlap, which solid weights cannot have (docs/metrics.md).

use super::cargo::Cargo;
use super::effect::contact::wrapped;

/// The weights that have a size, with their touching half-angles and planes.
#[derive(Debug, Clone, PartialEq)]
pub struct GapGauge {
    sized: Vec<(usize, f64, usize)>,
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
        pairs.then_some(GapGauge { sized })
    }

    /// The smallest gap (rad) over all pairs of one plane at angles ψ.
    /// All pairs, not only neighbours: O(n²), a few microseconds at n = 64,
    /// evaluated at the observer's sample rate only.
    pub fn min_gap(&self, psi: &[f64]) -> f64 {
        let mut smallest = f64::INFINITY;
        for (a, &(j, alpha_j, plane_j)) in self.sized.iter().enumerate() {
            for &(k, alpha_k, plane_k) in &self.sized[a + 1..] {
                if plane_k == plane_j {
                    let gap = wrapped(psi[k] - psi[j]).abs() - (alpha_j + alpha_k);
                    smallest = smallest.min(gap);
                }
            }
        }
        smallest
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
/// they could undercut it: each pair's gap is 1-Lipschitz in either angle
/// (|wrapped(x)| is the distance of x to 2πℤ), so
/// min_gap(ψ) ≥ min_gap(ψ₀) − 2 max_j |ψ_j − ψ₀_j| from the last sample
/// measured, ψ₀. The result is the minimum over every sample, bit for bit.
#[derive(Debug, Clone)]
pub struct ClosestApproach {
    smallest: f64,
    /// The gap measured at the anchor angles, and those angles.
    anchor: Option<(f64, Vec<f64>)>,
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
        if let Some((gap0, psi0)) = &self.anchor {
            let moved = psi
                .iter()
                .zip(psi0)
                .map(|(p, p0)| (p - p0).abs())
                .fold(0.0, f64::max);
            // NaN fails the test and is measured below.
            if gap0 - 2.0 * moved - BOUND_SLACK > self.smallest {
                return;
            }
        }
        let gap = gauge.min_gap(psi);
        self.smallest = self.smallest.min(gap);
        // Reuse the anchor's storage: a sample allocates nothing.
        match &mut self.anchor {
            Some((gap0, psi0)) if psi0.len() == psi.len() => {
                *gap0 = gap;
                psi0.copy_from_slice(psi);
            }
            anchor => *anchor = Some((gap, psi.to_vec())),
        }
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
