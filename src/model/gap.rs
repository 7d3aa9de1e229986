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
