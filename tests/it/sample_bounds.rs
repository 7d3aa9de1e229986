//! The observer's per-sample shortcuts give the exact answers: `BandDecider`
//! decides ε ≤ δ and `ClosestApproach` keeps the smallest gap without
//! computing them where a Lipschitz bound settles it; their results must be
//! those of computing every sample.

use autobal::model::cargo::Cargo;
use autobal::model::effect::Effects;
use autobal::model::gap::{ClosestApproach, GapGauge};
use autobal::model::rotor::PlaneRotor;
use autobal::model::scene::Scene;
use autobal::model::speed::SpeedLaw;
use autobal::model::unbalance::{BalancingGauge, BandCheck, BandDecider, reference_unbalance};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

#[test]
fn band_decisions_are_those_of_computing_the_balancing_error_every_time() {
    // Three weights of capacity 3 M e on the dimensionless rotor: ε ranges
    // from 0 (balanced) to about 4.
    let scene = Scene {
        rotor: PlaneRotor::isotropic(1.0, 0.01, 1.0, 0.1).into(),
        balancer: None,
        balancers: Vec::new(),
        cargo: vec![Cargo::point(0.01, 1.0, 0.01, 1.4); 3],
        speed: SpeedLaw::Constant { omega: 4.0 },
        effects: Effects::default(),
    };
    let system = scene.build().unwrap();
    let gauge = BalancingGauge::new(&system, reference_unbalance(&system));
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
    let (mut decided, mut computed) = (0u32, 0u32);
    for delta in [0.05, 0.5, 2.0] {
        let mut decider = BandDecider::new(&gauge);
        // A random walk with steps from tiny to large, through balance.
        let mut psi = vec![0.3, 2.4, 4.5];
        for _ in 0..20_000 {
            let size = 10f64.powf(rng.random_range(-6.0..-0.5));
            for p in &mut psi {
                *p += size * rng.random_range(-1.0..1.0);
            }
            let exact = gauge.error(&system, &psi) <= delta;
            match decider.check(&gauge, &system, &psi, delta) {
                BandCheck::Decided(inside) => {
                    assert_eq!(inside, exact, "ψ = {psi:?}, δ = {delta}");
                    decided += 1;
                }
                BandCheck::Computed(eps) => {
                    assert_eq!(eps <= delta, exact);
                    computed += 1;
                }
            }
        }
    }
    // Not vacuous: most samples of a slow walk need no trig.
    assert!(decided > computed, "decided {decided}, computed {computed}");
}

#[test]
fn the_closest_approach_is_the_minimum_over_every_sample() {
    // Four balls of half-angle 0.2 rad each (sized weights have gaps).
    let ball = Cargo {
        radius: 0.2_f64.sin(),
        ..Cargo::point(0.01, 1.0, 0.01, 1.4)
    };
    let alpha = ball.contact_half_angle();
    assert!(alpha > 0.0);
    let gauge = GapGauge::new(&vec![ball; 4]).unwrap();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    let mut psi = vec![0.0, 1.6, 3.2, 4.8];
    let (mut closest, mut exact) = (ClosestApproach::default(), f64::INFINITY);
    for step in 0..20_000 {
        // Drift together now and then, so that the minimum keeps moving.
        let size = 10f64.powf(rng.random_range(-6.0..-1.0));
        for (j, p) in psi.iter_mut().enumerate() {
            let pull = if step % 5000 < 2500 {
                -(j as f64) * 1e-4
            } else {
                0.0
            };
            *p += size * rng.random_range(-1.0..1.0) + pull;
        }
        closest.sample(&gauge, &psi);
        exact = exact.min(gauge.min_gap(&psi));
        assert_eq!(closest.smallest().to_bits(), exact.to_bits(), "step {step}");
    }
    assert!(
        exact < 1.6 - 2.0 * alpha,
        "the weights never came closer than at the start"
    );
}

/// Beyond eight weights the bound runs over the neighbour pairs of the last
/// sample measured: a pack resting in contact with free weights moving
/// around it, mixed sizes, weights that pass through each other (the gauge
/// does not stop them, so the neighbours change) and two planes.
#[test]
fn the_closest_approach_of_a_pack_is_that_of_every_sample() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(23);
    for (n, planes) in [(16_usize, 1_usize), (40, 1), (24, 2)] {
        let cargo: Vec<Cargo> = (0..n)
            .map(|j| Cargo {
                radius: 0.004 + 0.002 * (j % 3) as f64,
                plane: j % planes,
                ..Cargo::point(0.03, 0.05, 0.1, 1.4)
            })
            .collect();
        let gauge = GapGauge::new(&cargo).unwrap();
        let pitch = 2.0 * 0.008 / 0.05;
        // The first half packed (overlapping a little), the rest spread out.
        let mut psi: Vec<f64> = (0..n)
            .map(|j| {
                let i = (j / planes) as f64;
                if j < n / 2 {
                    i * pitch * 0.99
                } else {
                    3.0 + 2.9 * (j - n / 2) as f64 / (n / 2) as f64
                }
            })
            .collect();
        let (mut closest, mut exact) = (ClosestApproach::default(), f64::INFINITY);
        for step in 0..20_000 {
            let drift = 1e-4 * rng.random_range(-1.0..1.0);
            let jostle = 10f64.powf(rng.random_range(-9.0..-5.0));
            for (j, p) in psi.iter_mut().enumerate() {
                *p += if j < n / 2 {
                    // The pack moves together, squeezing now and then (new
                    // minima) and jostling a little.
                    let squeeze = if step % 4000 < 1000 { 2e-7 } else { 0.0 };
                    drift - squeeze * (j as f64) + jostle * rng.random_range(-1.0..1.0)
                } else {
                    10f64.powf(rng.random_range(-5.0..-2.5)) * rng.random_range(-1.0..1.0)
                };
            }
            closest.sample(&gauge, &psi);
            exact = exact.min(gauge.min_gap(&psi));
            assert_eq!(
                closest.smallest().to_bits(),
                exact.to_bits(),
                "n = {n}, step {step}"
            );
        }
        assert!(exact < 0.0, "n = {n}: the pack must overlap");
    }
}
