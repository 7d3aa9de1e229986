//! Position parameter p, p_max, transient measures and the slowest root (seed 000).

use autobal::design::Shape;
use autobal::design::geometry::{half_angle, pressed_angles, rho_half_race, rho_max};
use autobal::design::optimum::optimal_rho;
use autobal::design::transient::{
    a_tilde, p_max, p_max_half_race, position_parameter, slowest_root, transient_measure,
};
use proptest::prelude::*;
use std::f64::consts::PI;

/// Eq 2 written out as the paper's double sum, for comparison with the O(n) form.
fn p_double_sum(angles: &[f64]) -> f64 {
    let mut sum = 0.0;
    for a in angles {
        for b in angles {
            sum += (2.0 * (a - b)).cos();
        }
    }
    sum.max(0.0).sqrt() / angles.len() as f64
}

#[test]
fn p_max_of_three_weights_filling_half_the_race_is_two_thirds() {
    let rho = rho_half_race(3).unwrap();
    assert!((p_max(3, rho).unwrap() - 2.0 / 3.0).abs() < 1e-12);
    assert!((p_max_half_race(3).unwrap() - 2.0 / 3.0).abs() < 1e-12);
}

#[test]
fn p_max_at_half_race_tends_to_two_over_pi() {
    for n in [1000_u32, 1001, 100_000, 100_001] {
        let p = p_max_half_race(n).unwrap();
        assert!(
            (p - 2.0 / PI).abs() < 1e-5 * (1000.0 / f64::from(n)).max(1.0),
            "n={n}: {p}"
        );
        assert!(p > 2.0 / PI, "approached from above");
    }
}

#[test]
fn general_p_max_agrees_with_half_race_forms() {
    for n in 2..=40 {
        let rho = rho_half_race(n).unwrap();
        let general = p_max(n, rho).unwrap();
        let half = p_max_half_race(n).unwrap();
        assert!((general - half).abs() < 1e-12, "n={n}: {general} vs {half}");
    }
}

#[test]
fn p_max_is_the_p_of_two_opposite_pressed_groups() {
    // Build the configuration of Fig. 5 explicitly: ⌈n/2⌉ weights pressed at the
    // bottom, ⌊n/2⌋ pressed diametrically opposite, and evaluate eq 2 directly.
    for n in 2..=12_u32 {
        let rho = 0.8 * rho_half_race(n).unwrap();
        let alpha = half_angle(rho).unwrap();
        let lower = n.div_ceil(2);
        let upper = n / 2;
        let group = |k: u32, centre: f64| {
            (0..k).map(move |j| centre + alpha * (2.0 * f64::from(j) - f64::from(k - 1)))
        };
        let angles: Vec<f64> = group(lower, -PI / 2.0)
            .chain(group(upper, PI / 2.0))
            .collect();
        let direct = p_double_sum(&angles);
        assert!((direct - p_max(n, rho).unwrap()).abs() < 1e-12, "n={n}");
    }
}

#[test]
fn regular_polygon_has_p_zero() {
    for n in 3..=20 {
        let angles: Vec<f64> = (0..n)
            .map(|i| 2.0 * PI * f64::from(i) / f64::from(n))
            .collect();
        assert!(position_parameter(&angles) < 1e-12, "n={n}");
    }
    // Two weights are the exception: opposite weights give p = 1 (the critical case).
    assert!((position_parameter(&[0.0, PI]) - 1.0).abs() < 1e-12);
}

proptest! {
    #[test]
    fn p_lies_in_unit_interval_and_equals_the_double_sum(
        angles in proptest::collection::vec(-10.0..10.0_f64, 1..24)
    ) {
        let p = position_parameter(&angles);
        prop_assert!((0.0..=1.0).contains(&p));
        prop_assert!((p - p_double_sum(&angles)).abs() < 1e-6);
    }
}

#[test]
fn p_max_decreases_with_rho_for_more_than_two_weights() {
    // Remark 1 of seed 000.
    for n in 3..=12 {
        let upper = rho_max(n).unwrap();
        let mut last = f64::INFINITY;
        for i in 1..100 {
            let value = p_max(n, upper * f64::from(i) / 100.0).unwrap();
            assert!(value < last, "n={n}");
            last = value;
        }
    }
}

#[test]
fn half_race_p_max_decreases_with_n_within_each_parity_and_remark_2_holds() {
    for start in [2_u32, 3] {
        let mut last = f64::INFINITY;
        for n in (start..60).step_by(2) {
            let v = p_max_half_race(n).unwrap();
            assert!(v < last, "n={n}");
            last = v;
        }
    }
    // Remark 2: n1 = 2q + 1 and n2 = 2(2q + 1) give the same p_max.
    for q in 1..10 {
        let a = p_max_half_race(2 * q + 1).unwrap();
        let b = p_max_half_race(2 * (2 * q + 1)).unwrap();
        assert!((a - b).abs() < 1e-12, "q={q}");
    }
}

#[test]
fn a_tilde_equals_the_printed_eqs_15_and_16() {
    for n in 2..=12_u32 {
        let nf = f64::from(n);
        for i in 1..50 {
            let rho = rho_max(n).unwrap().min(0.4999) * f64::from(i) / 50.0;
            let sin_na = (nf * (rho / (1.0 - rho)).asin()).sin();
            let roller = if n % 2 == 1 {
                rho * (nf * rho - (1.0 - rho) * sin_na)
            } else {
                rho * (nf * rho - (1.0 - rho).powi(2) * sin_na / (1.0 - 2.0 * rho).sqrt())
            };
            let r = a_tilde(Shape::Roller, n, rho).unwrap();
            let b = a_tilde(Shape::Ball, n, rho).unwrap();
            assert!((r - roller).abs() < 1e-12, "n={n} ρ={rho}: {r} vs {roller}");
            assert!((b - rho * roller).abs() < 1e-12);
        }
    }
}

#[test]
fn a_tilde_increases_with_rho_up_to_half() {
    // Seed 000: functions (15), (16) increase monotonically in ρ for fixed n > 2.
    for shape in Shape::ALL {
        for n in 3..=10 {
            let upper = rho_max(n).unwrap().min(0.5);
            let mut last = 0.0;
            for i in 1..100 {
                let v = a_tilde(shape, n, upper * f64::from(i) / 100.0).unwrap();
                assert!(v > last, "{shape} n={n}");
                last = v;
            }
        }
    }
}

#[test]
fn fastest_transients_come_from_three_balls_or_five_rollers() {
    // Fig. 7 of seed 000, evaluated at the Table 1 radii.
    let best = |shape| {
        (2..=8)
            .max_by(|&a, &b| {
                let f = |n| a_tilde(shape, n, optimal_rho(shape, n).unwrap().rho).unwrap();
                f(a).total_cmp(&f(b))
            })
            .unwrap()
    };
    assert_eq!(best(Shape::Ball), 3);
    assert_eq!(best(Shape::Roller), 5);
}

#[test]
fn slowest_root_limits() {
    // p = 1: the root is zero (balancing may never start).
    let r = slowest_root(1.0, 1.0, 0.1, 2, 1.0).unwrap();
    assert_eq!(r.re, 0.0);
    // Real case: λ solves λ² + b̃λ + a b_cr²/4 = 0 (the quadratic behind eq 1).
    let (b, p, m, n, bcr) = (2.0, 0.3, 0.05, 3, 1.5);
    let r = slowest_root(b, p, m, n, bcr).unwrap();
    let a = transient_measure(p, m, n).unwrap();
    assert!(r.is_real());
    assert!((r.re * r.re + b * r.re + a * bcr * bcr / 4.0).abs() < 1e-14);
    // Complex case: real part −b̃/2, never NaN.
    let r = slowest_root(0.01, 0.0, 1.0, 4, 1.0).unwrap();
    assert!(!r.is_real() && r.re == -0.005 && r.im.is_finite() && r.im > 0.0);
    // Larger a (more, heavier weights, smaller p) makes the slowest root faster.
    let slow = slowest_root(2.0, 0.6, 0.05, 3, 1.0).unwrap().re;
    let fast = slowest_root(2.0, 0.2, 0.05, 3, 1.0).unwrap().re;
    assert!(fast < slow);
}

#[test]
fn pressed_angles_are_symmetric_and_two_alpha_apart() {
    let rho = 0.2;
    let angles = pressed_angles(5, rho).unwrap();
    let alpha = half_angle(rho).unwrap();
    assert!((angles[0] + 4.0 * alpha).abs() < 1e-15 && (angles[4] - 4.0 * alpha).abs() < 1e-15);
    for w in angles.windows(2) {
        assert!((w[1] - w[0] - 2.0 * alpha).abs() < 1e-15);
    }
}
