//! Identical weights that meet: the pairs that can coincide, and the test
//! that two did (docs/model.md, "Identical weights that meet").

use super::{Sample, SettlingObserver};
use crate::integrate::Flow;

/// Pairs (i, j) of weights in the same plane with identical parameters:
/// the only ones whose states can become equal and then stay equal. With
/// contact on, weights of finite size never meet (the contact force keeps
/// them 2α apart), so they are left out and cost nothing per sample.
pub(super) fn identical_pairs(
    cargo: &[crate::model::cargo::Cargo],
    contact: bool,
) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for i in 0..cargo.len() {
        for j in i + 1..cargo.len() {
            let (a, b) = (&cargo[i], &cargo[j]);
            if a.plane == b.plane
                && !(contact && a.radius > 0.0)
                && a.mass == b.mass
                && a.track_radius == b.track_radius
                && a.drag == b.drag
                && a.kappa == b.kappa
                && a.rolling_coupling == b.rolling_coupling
                && a.rolling_inertia == b.rolling_inertia
                && a.radius == b.radius
            {
                pairs.push((i, j));
            }
        }
    }
    pairs
}

/// Two angles (or rates) this close are the same number to the last bits:
/// a few units in the last place of the larger.
fn same_to_the_last_bits(a: f64, b: f64) -> bool {
    (a - b).abs() <= 8.0 * f64::EPSILON * a.abs().max(b.abs()).max(1.0)
}

/// The first of `pairs` whose angles (mod 2π) and rates are equal to the
/// last bits in state y.
pub(super) fn coincident_pair(
    pairs: &[(usize, usize)],
    lay: crate::model::system::Layout,
    y: &[f64],
) -> Option<(usize, usize)> {
    let (head, nq) = (lay.head(), lay.nq());
    pairs.iter().copied().find(|&(i, j)| {
        let (a, b) = (y[head + i], y[head + j]);
        let gap = crate::model::effect::contact::wrapped(a - b);
        same_to_the_last_bits(a, a - gap)
            && same_to_the_last_bits(y[nq + head + i], y[nq + head + j])
    })
}

impl SettlingObserver<'_> {
    /// The part that notes the first pair of identical weights to coincide,
    /// and when.
    pub(super) fn watch_twins(&mut self, s: &mut Sample) -> Flow {
        if self.merged.is_none() {
            self.merged = self.coincident().map(|(i, j)| (i, j, s.t));
        }
        Flow::Continue
    }

    /// The first pair of identical weights whose angles (mod 2π) and rates
    /// are equal to the last bits in the scratch state, if any.
    pub(super) fn coincident(&self) -> Option<(usize, usize)> {
        coincident_pair(&self.twins, self.system.layout(), &self.scratch)
    }

    /// The growth rate (1/s) of the antisymmetric mode of weights i and j at
    /// state y: δ = ψ_i − ψ_j obeys δ̈ = a δ + b δ̇ to first order, from
    /// central differences of the right-hand side; positive when the pair,
    /// once apart, would part further (real weights would separate).
    pub(super) fn parting_rate(&self, t: f64, y: &[f64], i: usize, j: usize) -> f64 {
        let lay = self.system.layout();
        let (head, nq) = (lay.head(), lay.nq());
        let y0 = self.inertial(t, y);
        let response = |offset: usize, h: f64| {
            let mut plus = y0.clone();
            let mut minus = y0.clone();
            plus[offset + head + i] += h;
            plus[offset + head + j] -= h;
            minus[offset + head + i] -= h;
            minus[offset + head + j] += h;
            let (mut dp, mut dm) = (vec![0.0; y0.len()], vec![0.0; y0.len()]);
            crate::integrate::OdeSystem::rhs(self.system, t, &plus, &mut dp);
            crate::integrate::OdeSystem::rhs(self.system, t, &minus, &mut dm);
            let ddot = |d: &[f64]| d[nq + head + i] - d[nq + head + j];
            (ddot(&dp) - ddot(&dm)) / (4.0 * h)
        };
        let a = response(0, 1e-7);
        let b = response(nq, 1e-7 * self.omega.max(1.0));
        // Largest real part of the roots of λ² − b λ − a.
        let disc = b * b + 4.0 * a;
        if disc >= 0.0 {
            0.5 * (b + disc.sqrt())
        } else {
            0.5 * b
        }
    }
}
