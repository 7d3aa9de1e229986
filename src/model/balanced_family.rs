//! Stability over the family of balanced states, not at one point of it.
//!
//! n ≥ 3 weights in a plane balance anywhere on an (n − 2)-dimensional
//! family of positions, and part of that family can be unstable while the
//! rest is stable (Green, Champneys and Lieven's Bristol analysis finds such
//! families). [`analyse`](super::linear::analyse) linearises at the symmetric
//! fan only; a run that settles somewhere else on the family is not bound by
//! it. Here the linearisation is repeated at members of the family spread
//! over it, each refined onto the full equations by the same
//! Levenberg–Marquardt search,
//! so "unstable" can be said only where every point tried is unstable.

use super::linear::{LinearError, LinearReport, analyse, balancing_angles, correction_unbalances};
use super::system::RotorSystem;
use num_complex::Complex64;
use std::f64::consts::PI;

/// How many points of the family are tried, the symmetric fan included.
pub const FAMILY_POINTS: usize = 24;

/// The linear analyses at the points of the family that were reached.
#[derive(Debug, Clone)]
pub struct FamilyStability {
    /// Points tried (guesses), the fan included.
    pub tried: usize,
    /// The analyses that found a balanced state, the fan's first when it did.
    pub points: Vec<LinearReport>,
    /// Whether the analysis at the symmetric fan found a balanced state.
    pub fan_reached: bool,
}

impl FamilyStability {
    /// The stable point with the fastest slowest decay, if any is stable.
    pub fn fastest_stable(&self) -> Option<&LinearReport> {
        self.points
            .iter()
            .filter(|r| r.stable)
            .max_by(|a, b| a.slowest_decay.total_cmp(&b.slowest_decay))
    }

    /// How many of the points reached are stable.
    pub fn stable_count(&self) -> usize {
        self.points.iter().filter(|r| r.stable).count()
    }

    /// The analysis at the symmetric fan, when it found a balanced state.
    pub fn at_fan(&self) -> Option<&LinearReport> {
        self.points.first().filter(|_| self.fan_reached)
    }
}

/// Linear stability at the fan and at up to [`FAMILY_POINTS`] − 1 other
/// positions of the family; the fan's error when no point was reached.
pub fn family_stability(system: &RotorSystem) -> Result<FamilyStability, LinearError> {
    let fan = balancing_angles(system);
    // Fewer than three weights in every plane: the balanced state is a point.
    let single_point = (0..system.rotor().planes())
        .all(|p| system.cargo().iter().filter(|c| c.plane == p).count() < 3);
    let tries = if single_point { 1 } else { FAMILY_POINTS };
    let mut points = Vec::new();
    let first_error = match analyse(system, Some(&fan)) {
        Ok(r) => {
            points.push(r);
            None
        }
        Err(e) => Some(e),
    };
    let targets = correction_unbalances(system);
    for k in 1..tries {
        let Some(guess) = family_member(system, &targets, &fan, k) else {
            continue;
        };
        if let Ok(r) = analyse(system, Some(&guess)) {
            points.push(r);
        }
    }
    match first_error {
        Some(e) if points.is_empty() => Err(e),
        _ => Ok(FamilyStability {
            tried: tries,
            fan_reached: first_error.is_none(),
            points,
        }),
    }
}

/// The k-th member of the rigid balanced family, Σ_j c_j e^{iψ_j} = T_p in
/// every plane p: all but two weights of a plane of three or more at
/// spread-out angles (an additive recurrence on irrational steps, which
/// fills the circle evenly), the last two placed by the law of cosines to
/// close the sum. `None` when the two cannot close it for this k.
fn family_member(
    system: &RotorSystem,
    targets: &[Complex64],
    fan: &[f64],
    k: usize,
) -> Option<Vec<f64>> {
    let cargo = system.cargo();
    let mut psi = fan.to_vec();
    for (p, target) in targets.iter().enumerate() {
        let members: Vec<usize> = (0..cargo.len()).filter(|&j| cargo[j].plane == p).collect();
        if members.len() < 3 {
            continue;
        }
        let (free, last) = members.split_at(members.len() - 2);
        let mut rest = *target;
        for (i, &j) in free.iter().enumerate() {
            // √2, √3, √5, … : steps whose multiples never repeat.
            let step = PRIMES[i % PRIMES.len()].sqrt().fract();
            psi[j] = 2.0 * PI * (0.5 + k as f64 * step).fract();
            rest -= Complex64::from_polar(cargo[j].unbalance(), psi[j]);
        }
        let (a, b) = (cargo[last[0]].unbalance(), cargo[last[1]].unbalance());
        let r = rest.norm();
        if r > a + b || r < (a - b).abs() || r == 0.0 {
            return None;
        }
        let gamma_a = ((r * r + a * a - b * b) / (2.0 * r * a))
            .clamp(-1.0, 1.0)
            .acos();
        let gamma_b = ((r * r + b * b - a * a) / (2.0 * r * b))
            .clamp(-1.0, 1.0)
            .acos();
        // Alternate the two mirror closures from one k to the next.
        let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
        psi[last[0]] = rest.arg() + sign * gamma_a;
        psi[last[1]] = rest.arg() - sign * gamma_b;
    }
    Some(psi)
}

/// Irrational square roots for the spread of the free weights.
const PRIMES: [f64; 6] = [2.0, 3.0, 5.0, 7.0, 11.0, 13.0];
