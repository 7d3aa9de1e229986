//! The net unbalance a balancer leaves: the reference unbalance U and the
//! balancing error ε of cargo angles, for any rotor model. `metrics` names
//! them among its scales (docs/metrics.md); the linear analysis uses them
//! to tell a balanced fixed point from an unbalanced one.

use crate::model::forced::unbalance_forcing;
use crate::model::start::{add_cargo_unbalance, is_plane_translation, rotor_unbalance};
use crate::model::system::RotorSystem;

/// Reference unbalance U: the size of the rotor's own unbalance (M e for the
/// plane rotor, the largest bearing-equivalent one on two supports), or
/// Σ m l when the rotor has none.
pub fn reference_unbalance(system: &RotorSystem) -> f64 {
    let own = system.rotor().own_unbalance();
    if own > 0.0 {
        own
    } else {
        system.cargo().iter().map(|c| c.unbalance()).sum::<f64>()
    }
}

/// Balancing error ε: size of the total unbalance of rotor and cargoes (at
/// angles ψ relative to the rotor) over U; for the plane rotor
/// |Σ m_j l_j e^{iψ_j} + M e e^{iψ₀}| / U.
pub fn balancing_error(system: &RotorSystem, psi: &[f64], unbalance_ref: f64) -> f64 {
    if is_plane_translation(system) {
        let (ux, uy) = crate::model::start::total_unbalance(system, psi);
        return planar_norm(ux, uy) / unbalance_ref;
    }
    let (fc, _) = unbalance_forcing(system, psi, true);
    system.rotor().unbalance_size(&fc) / unbalance_ref
}

/// ε per balancer plane: the unbalance of rotor and cargoes (at angles ψ)
/// as equivalent unbalances in each balancer plane, over U; `None` where the
/// rotor model does not define them (see
/// [`crate::model::rotor::Rotor::plane_unbalance_sizes`]).
pub fn plane_balancing_errors(
    system: &RotorSystem,
    psi: &[f64],
    unbalance_ref: f64,
) -> Option<Vec<f64>> {
    let (fc, _) = unbalance_forcing(system, psi, true);
    let sizes = system.rotor().plane_unbalance_sizes(&fc)?;
    Some(sizes.into_iter().map(|u| u / unbalance_ref).collect())
}

/// [`balancing_error`] for repeated use on one system: what does not depend
/// on the angles (the rotor's unbalance vector, each cargo's m l, which
/// formula applies) is worked out once. Gives the same bits.
#[derive(Debug, Clone)]
pub struct BalancingGauge {
    /// (U_x, U_y) of the rotor itself for the plane rotor; None otherwise.
    plane: Option<(f64, f64)>,
    cargo_unbalance: Vec<f64>,
    unbalance_ref: f64,
}

impl BalancingGauge {
    /// A gauge for `system`, relative to `unbalance_ref`.
    pub fn new(system: &RotorSystem, unbalance_ref: f64) -> Self {
        let plane = is_plane_translation(system).then(|| rotor_unbalance(system));
        BalancingGauge {
            plane,
            cargo_unbalance: system.cargo().iter().map(|c| c.unbalance()).collect(),
            unbalance_ref,
        }
    }

    /// ε at cargo angles ψ, as [`balancing_error`] computes it.
    pub fn error(&self, system: &RotorSystem, psi: &[f64]) -> f64 {
        let Some(rotor) = self.plane else {
            return balancing_error(system, psi, self.unbalance_ref);
        };
        let cargo = self
            .cargo_unbalance
            .iter()
            .copied()
            .zip(psi.iter().copied());
        let (ux, uy) = add_cargo_unbalance(rotor, cargo);
        planar_norm(ux, uy) / self.unbalance_ref
    }
}

/// Decides ε ≤ δ sample after sample, computing ε (and its trig) only when
/// a bound cannot: for the plane rotor |ε(ψ) − ε(ψ₀)| ≤ Σ_j (m_j l_j / U)
/// |ψ_j − ψ₀_j|, because |e^{ia} − e^{ib}| ≤ |a − b|, so from the last ε
/// computed (at ψ₀) the answer is often already certain. The decisions are
/// those of computing ε every time: the bound is widened by far more than
/// the rounding of either side.
#[derive(Debug, Clone)]
pub struct BandDecider {
    /// m_j l_j / U per cargo; None where the bound is not derived (rotors
    /// with several coordinates): there ε is always computed.
    weights: Option<Vec<f64>>,
    /// The last ε computed, and the angles it was computed at.
    anchor: Option<(f64, Vec<f64>)>,
}

/// What [`BandDecider::check`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BandCheck {
    /// The bound settled it: whether ε ≤ δ.
    Decided(bool),
    /// ε had to be computed (it may be non-finite).
    Computed(f64),
}

impl BandDecider {
    /// A decider for the system `gauge` measures.
    pub fn new(gauge: &BalancingGauge) -> Self {
        BandDecider {
            weights: gauge.plane.map(|_| {
                gauge
                    .cargo_unbalance
                    .iter()
                    .map(|u| u / gauge.unbalance_ref)
                    .collect()
            }),
            anchor: None,
        }
    }

    /// Whether ε(ψ) ≤ δ, by the bound if it settles it, else by computing ε.
    pub fn check(
        &mut self,
        gauge: &BalancingGauge,
        system: &RotorSystem,
        psi: &[f64],
        delta: f64,
    ) -> BandCheck {
        if let (Some(weights), Some((eps0, psi0))) = (&self.weights, &self.anchor) {
            let reach: f64 = weights
                .iter()
                .zip(psi.iter().zip(psi0))
                .map(|(w, (p, p0))| w * (p - p0).abs())
                .sum();
            // Far wider than rounding: ε and the sum err by ~1e-15.
            let reach = reach * (1.0 + 1e-9) + 1e-12 * delta;
            if eps0 + reach < delta {
                return BandCheck::Decided(true);
            }
            if eps0 - reach > delta {
                return BandCheck::Decided(false);
            }
        }
        let eps = gauge.error(system, psi);
        if self.weights.is_some() {
            // Reuse the anchor's storage: a sample allocates nothing.
            match &mut self.anchor {
                _ if !eps.is_finite() => self.anchor = None,
                Some((eps0, psi0)) if psi0.len() == psi.len() => {
                    *eps0 = eps;
                    psi0.copy_from_slice(psi);
                }
                anchor => *anchor = Some((eps, psi.to_vec())),
            }
        }
        BandCheck::Computed(eps)
    }
}

/// |(x, y)| for the observer's per-sample sizes (r and ε): sqrt(x² + y²),
/// which costs a third of `hypot` (its scaling against overflow and
/// underflow was 6 % of a study's time); `hypot` only where x² + y² would
/// overflow or underflow, far outside any vibration or unbalance.
pub(crate) fn planar_norm(x: f64, y: f64) -> f64 {
    let sq = x * x + y * y;
    if sq.is_finite() && sq >= f64::MIN_POSITIVE {
        sq.sqrt()
    } else {
        x.hypot(y)
    }
}
