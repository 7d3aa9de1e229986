//! How the accelerations of the rotor systems couple, for implicit solvers
//! ([`crate::integrate::CouplingStructure`]): the rotor's accelerations are
//! the head, and each weight touches only its neighbours along its race
//! (the contact effect, the only one coupling weights directly).

use super::cargo::Cargo;
use super::race_ring::{MAX_RING, for_each_ring};
use crate::integrate::CouplingStructure;

/// Write the rings of `out` for cargoes at relative angles `psi`, their
/// coordinates numbered from `head`: per plane the sized weights in race
/// order, every point-sized one a ring of its own. `out.head` and
/// `out.coupling` are the caller's. False beyond [`MAX_RING`] weights.
pub fn cargo_rings(cargo: &[Cargo], psi: &[f64], head: usize, out: &mut CouplingStructure) -> bool {
    let n = cargo.len();
    if n > MAX_RING {
        return false;
    }
    out.order.clear();
    out.ring_ends.clear();
    let (order, ends) = (&mut out.order, &mut out.ring_ends);
    for_each_ring(
        n,
        |j| cargo[j].plane,
        |j| cargo[j].radius > 0.0,
        |j| psi[j],
        |ring| {
            if !ring.is_empty() {
                order.extend(ring.iter().map(|&j| head + j as usize));
                ends.push(order.len());
            }
        },
    );
    for (j, c) in cargo.iter().enumerate() {
        if c.radius <= 0.0 {
            order.push(head + j);
            ends.push(order.len());
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sized_weights_ring_by_plane_in_race_order_and_points_stand_alone() {
        let ball = |plane, radius| Cargo {
            plane,
            radius,
            ..Cargo::point(0.01, 0.05, 0.0, 1.4)
        };
        let cargo = [
            ball(0, 0.005),
            ball(1, 0.005),
            ball(0, 0.0),
            ball(0, 0.005),
            ball(1, 0.005),
            ball(0, 0.005),
        ];
        let psi = [3.0, 0.5, 1.0, -0.5, 7.0, 1.0];
        let mut out = CouplingStructure::default();
        assert!(cargo_rings(&cargo, &psi, 2, &mut out));
        // Plane 0: ψ = 3.0, 2π − 0.5, 1.0 sorted modulo 2π → cargoes 5, 0, 3.
        // Plane 1: 0.5 and 7.0 − 2π = 0.717 → cargoes 1, 4. Point 2 alone.
        assert_eq!(out.order, vec![7, 2, 5, 3, 6, 4]);
        assert_eq!(out.ring_ends, vec![3, 5, 6]);
    }
}
