//! Stability at the extremes of the design space: every case finishes without
//! NaN or panic and meets a physical expectation.

use autobal::design::geometry::rho_max;
use autobal::metrics::MetricOptions;
use autobal::metrics::{Outcome, RunMetrics};
use autobal::model::balancer::{Geometry, Kind, cargoes};
use autobal::model::cargo::Cargo;
use autobal::model::effect::Effects;
use autobal::model::rotor::{PlaneRotor, RotorModel};
use autobal::model::scene::Scene;
use autobal::model::speed::SpeedLaw;
use autobal::model::start::StartMode;
use autobal::simulation::{Fidelity, Simulation, SolverSettings};

/// M = 1, k = 1 (ω_n ≈ 1), ζ = 0.05; unbalance U = M e at 0°.
fn rotor(e: f64) -> PlaneRotor {
    PlaneRotor::isotropic(1.0, e, 1.0, 0.1)
}

fn sim(
    rotor: PlaneRotor,
    cargo: Vec<Cargo>,
    omega: f64,
    angles_deg: &[f64],
    revs: f64,
) -> Simulation {
    Simulation {
        scene: Scene {
            rotor: RotorModel::Plane(rotor),
            balancer: None,
            balancers: Vec::new(),
            cargo,
            speed: SpeedLaw::Constant { omega },
            effects: Effects::default(),
        },
        start: StartMode::LockedSteady,
        initial_angles: angles_deg.iter().map(|d| d.to_radians()).collect(),
        solver: SolverSettings::default(),
        metrics: MetricOptions {
            t_end_revs: revs,
            ..MetricOptions::default()
        },
    }
}

/// Run and check what every extreme case must satisfy: finite numbers, no failure.
fn run(s: &Simulation) -> RunMetrics {
    let m = s.run(false).expect("valid scene").metrics;
    assert_ne!(m.outcome, Outcome::SolverFailed, "{}", m.reason);
    assert_ne!(m.outcome, Outcome::Diverged, "{}", m.reason);
    for v in [
        m.residual_abs,
        m.residual_rel,
        m.a_ref,
        m.balancing_error,
        m.peak_r,
        m.p_final,
    ] {
        assert!(v.is_finite(), "non-finite metric in {m:?}");
    }
    assert!(m.final_rel_angles_deg.iter().all(|a| a.is_finite()));
    m
}

fn point(mass: f64, drag: f64) -> Cargo {
    Cargo::point(mass, 1.0, drag, 1.4)
}

/// Signed angle wrapped to (−180°, 180°].
fn wrap(a: f64) -> f64 {
    let w = a.rem_euclid(360.0);
    if w > 180.0 { w - 360.0 } else { w }
}

#[test]
fn one_cargo_heavier_than_the_unbalance_overshoots_opposite() {
    // A single weight can only sit opposite the unbalance: with m l = 2 M e the
    // balancing error is (m l − M e)/(M e) = 1 and balancing never occurs.
    let m = run(&sim(
        rotor(0.01),
        vec![point(0.02, 0.02)],
        4.0,
        &[90.0],
        400.0,
    ));
    // Never settles: run to the horizon, or certified early not to.
    assert!(
        matches!(m.outcome, Outcome::Censored | Outcome::NotSettled),
        "{}",
        m.reason
    );
    // Opposite the unbalance, shifted by the rotor's phase lag
    // atan(bω/(Mω² − k)) = 1.5° here.
    let lag = (0.1f64 * 4.0).atan2(1.0 * 16.0 - 1.0).to_degrees();
    assert!(
        (wrap(m.final_rel_angles_deg[0]).abs() - (180.0 - lag)).abs() < 0.5,
        "{:?}",
        m.final_rel_angles_deg
    );
    assert!(
        (m.balancing_error - 1.0).abs() < 0.01,
        "ε = {}",
        m.balancing_error
    );
}

#[test]
fn sixty_four_cargoes_balance() {
    let n = 64;
    let cargo = vec![point(0.03 / n as f64, 0.03 / n as f64); n];
    let angles: Vec<f64> = (0..n).map(|j| 60.0 + j as f64).collect();
    let m = run(&sim(rotor(0.01), cargo, 4.0, &angles, 600.0));
    assert_eq!(m.outcome, Outcome::Settled, "{}", m.reason);
    assert!(m.balancing_error < 0.05);
}

#[test]
fn tiny_weights_gather_opposite_an_unbalance_they_cannot_cancel() {
    // ρ = 1e-4: the weights' capacity is negligible against the rotor's usual
    // unbalance (e = 0.01). Far from balance their drift rate does not depend
    // on their mass (β ∝ m), so they gather opposite and leave ε = 1 − Σ m l / U.
    let g = Geometry {
        race_radius: 1.0,
        rho: 1e-4,
        density: 1000.0,
        roller_height: 0.0,
        drag: 0.0,
    };
    let mut cargo = cargoes(Kind::Ball, 3, &g).unwrap();
    for c in &mut cargo {
        c.drag = c.mass;
    }
    let total: f64 = cargo.iter().map(Cargo::unbalance).sum();
    let m = run(&sim(rotor(0.01), cargo, 4.0, &[60.0, 90.0, 120.0], 400.0));
    // Never settles: run to the horizon, or certified early not to.
    assert!(
        matches!(m.outcome, Outcome::Censored | Outcome::NotSettled),
        "{}",
        m.reason
    );
    assert!(
        (m.balancing_error - (1.0 - total / 0.01)).abs() < 1e-9,
        "ε = {}",
        m.balancing_error
    );
    for a in &m.final_rel_angles_deg {
        assert!((wrap(*a).abs() - 180.0).abs() < 3.0, "{a}");
    }
}

#[test]
fn nearly_packed_weights_balance() {
    for n in [3_u32, 5] {
        let g = Geometry {
            race_radius: 1.0,
            rho: 0.999 * rho_max(n).unwrap(),
            density: 1000.0,
            roller_height: 0.0,
            drag: 0.0,
        };
        let mut cargo = cargoes(Kind::Ball, n, &g).unwrap();
        for c in &mut cargo {
            c.drag = c.mass;
        }
        let total: f64 = cargo.iter().map(Cargo::unbalance).sum();
        let angles: Vec<f64> = (0..n).map(|j| 60.0 + 20.0 * f64::from(j)).collect();
        // With contact off (weights pass through each other, as the theory
        // assumes) half their total unbalance can be cancelled; these starts
        // overlap, which solid weights could not do.
        let mut s = sim(rotor(0.5 * total), cargo, 4.0, &angles, 800.0);
        s.scene.effects.contact = None;
        let m = run(&s);
        assert_eq!(m.outcome, Outcome::Settled, "n={n}: {}", m.reason);
        assert!(m.balancing_error < 0.05, "n={n}");
    }
}

#[test]
fn extreme_mass_ratios_balance_on_their_own_time_scale() {
    // Near balance the weights' drift rate scales with their mass (the slow
    // root c n (1 − p)/2 with c = m² ω² |H| / β and β ∝ m): a cargo-to-rotor
    // mass ratio of 1e-6 settles ~1e4 times later than 0.03 — hundreds of
    // thousands of revolutions, which the rotating frame crosses in few steps.
    for (ratio, revs) in [(1e-6, 5e6), (0.5, 800.0)] {
        let cargo = vec![point(ratio / 3.0, ratio / 3.0); 3];
        let m = run(&sim(
            rotor(0.5 * ratio),
            cargo,
            4.0,
            &[60.0, 90.0, 120.0],
            revs,
        ));
        assert_eq!(
            m.outcome,
            Outcome::Settled,
            "mass ratio {ratio}: {}",
            m.reason
        );
        assert!(m.balancing_error < 0.05);
    }
}

#[test]
fn nearly_undamped_weights_settle_slower_than_damped_ones() {
    let angles = [60.0, 90.0, 120.0];
    let damped = run(&sim(
        rotor(0.01),
        vec![point(0.01, 0.01); 3],
        4.0,
        &angles,
        600.0,
    ));
    let undamped = run(&sim(
        rotor(0.01),
        vec![point(0.01, 1e-6); 3],
        4.0,
        &angles,
        600.0,
    ));
    assert_eq!(damped.outcome, Outcome::Settled);
    match undamped.settling_revs {
        Some(t) => assert!(
            t > 3.0 * damped.settling_revs.unwrap(),
            "β = 1e-6 settled in {t} rev"
        ),
        None => assert_eq!(undamped.outcome, Outcome::Censored),
    }
}

#[test]
fn overdamped_stiff_weights_switch_to_the_implicit_method() {
    // β/(κ m) = 1e3/0.014 ≈ 7e4 1/s ≫ ω = 4: stiff. In the inertial frame DP5
    // stalls and the run continues with Radau5; overdamped weights creep.
    let angles = [60.0, 90.0, 120.0];
    let mut s = sim(rotor(0.01), vec![point(0.01, 1e3); 3], 4.0, &angles, 300.0);
    s.solver.fidelity = Fidelity::Full;
    let m = run(&s);
    assert!(m.method.contains("radau5"), "method {}", m.method);
    let fast = run(&sim(
        rotor(0.01),
        vec![point(0.01, 0.01); 3],
        4.0,
        &angles,
        300.0,
    ));
    // Heavy drag slows the weights: either no settling in 300 rev or a much later one.
    assert!(
        m.settling_revs
            .is_none_or(|t| t > 3.0 * fast.settling_revs.unwrap()),
        "{:?}",
        m.settling_revs
    );
    assert!(m.balancing_error > fast.balancing_error);
}

#[test]
fn undamped_supports_still_balance_the_unbalance() {
    // Without support damping the free whirl is not damped by the supports, but
    // the weights still cancel the unbalance (ε → 0).
    let mut r = rotor(0.01);
    r.bx = 0.0;
    r.by = 0.0;
    let m = run(&sim(
        r,
        vec![point(0.01, 0.01); 3],
        4.0,
        &[60.0, 90.0, 120.0],
        800.0,
    ));
    assert!(m.balancing_error < 0.05, "ε = {}", m.balancing_error);
}

#[test]
fn at_resonance_no_balancing_far_above_it_balancing() {
    let angles = [60.0, 90.0, 120.0];
    let at = run(&sim(
        rotor(0.01),
        vec![point(0.01, 0.01); 3],
        1.001,
        &angles,
        400.0,
    ));
    assert_eq!(at.outcome, Outcome::Censored, "{}", at.reason);
    let far = run(&sim(
        rotor(0.01),
        vec![point(0.01, 0.01); 3],
        50.0,
        &angles,
        4000.0,
    ));
    assert_eq!(far.outcome, Outcome::Settled, "{}", far.reason);
    assert!(far.balancing_error < 0.05);
}

#[test]
fn strong_anisotropy_balances_along_the_soft_axis_and_is_stiff() {
    // k_y/k_x = 1e4: along Y the rotor is practically rigid (ω_y = 100 ≫ ω = 4),
    // so it moves along X only, above that axis's resonance: the weights still
    // cancel the unbalance. The stiff Y mode stalls DP5, which hands over to Radau5.
    let mut r = rotor(0.01);
    r.ky = 1e4;
    let s = sim(
        r,
        vec![point(0.01, 0.01); 3],
        4.0,
        &[60.0, 90.0, 120.0],
        400.0,
    );
    assert_eq!(
        s.resolved_fidelity(),
        Fidelity::Full,
        "anisotropy needs the inertial frame"
    );
    let m = run(&s);
    assert_eq!(m.outcome, Outcome::Settled, "{}", m.reason);
    assert!(m.balancing_error < 0.05);
    assert!(m.method.contains("radau5"), "{}", m.method);
}

#[test]
fn zero_eccentricity_spreads_clustered_weights_evenly() {
    let m = run(&sim(
        rotor(0.0),
        vec![point(0.01, 0.01); 3],
        4.0,
        &[80.0, 90.0, 100.0],
        800.0,
    ));
    assert_eq!(m.outcome, Outcome::Settled, "{}", m.reason);
    // Balanced with no unbalance: the three weights form an equilateral triangle (p = 0).
    assert!(
        m.p_final < 0.05 && m.balancing_error < 0.05,
        "p = {}, ε = {}",
        m.p_final,
        m.balancing_error
    );
}

#[test]
fn ten_times_capacity_cannot_balance() {
    // Σ m l = 0.03, U = 0.3: the weights gather opposite, ε = (U − Σ m l)/U = 0.9.
    let m = run(&sim(
        rotor(0.3),
        vec![point(0.01, 0.01); 3],
        4.0,
        &[60.0, 90.0, 120.0],
        400.0,
    ));
    // Never settles: run to the horizon, or certified early not to.
    assert!(
        matches!(m.outcome, Outcome::Censored | Outcome::NotSettled),
        "{}",
        m.reason
    );
    assert!(!m.reason.is_empty());
    assert!(
        (m.balancing_error - 0.9).abs() < 0.01,
        "ε = {}",
        m.balancing_error
    );
    for a in &m.final_rel_angles_deg {
        assert!((wrap(*a).abs() - 180.0).abs() < 2.0, "{a}");
    }
}

#[test]
fn a_hundred_thousand_revolutions() {
    let mut s = sim(
        rotor(0.01),
        vec![point(0.01, 0.01); 3],
        4.0,
        &[60.0, 90.0, 120.0],
        1e5,
    );
    s.metrics.stop_when_settled = false;
    let m = run(&s);
    assert_eq!(m.outcome, Outcome::Settled);
    assert!((m.t_final - 1e5 * 2.0 * std::f64::consts::PI / 4.0).abs() < 1e-6 * m.t_final);
    // The rotating frame steps across the balanced fixed point in large steps.
    assert!(m.steps < 10_000, "{} steps for 1e5 revolutions", m.steps);
    assert!(m.residual_rel < 1e-3);
}

#[test]
fn runs_that_exhaust_a_budget_are_recorded_as_such() {
    use autobal::metrics::Outcome;
    let angles = [60.0, 90.0, 120.0];
    // A step budget the run cannot meet, with no fallback to switch to.
    let mut s = sim(rotor(0.01), vec![point(0.01, 0.01); 3], 4.0, &angles, 300.0);
    s.solver.max_steps = 50;
    s.solver.implicit_fallback = false;
    let m = run(&s);
    assert_eq!(m.outcome, Outcome::BudgetExceeded, "{}", m.reason);
    assert!(m.reason.contains("too many steps"), "{}", m.reason);
    // A wall-time budget far below what the run needs.
    let mut s = sim(rotor(0.01), vec![point(0.01, 0.01); 3], 4.0, &angles, 300.0);
    s.solver.max_wall_seconds = 1e-9;
    let m = run(&s);
    assert_eq!(m.outcome, Outcome::BudgetExceeded, "{}", m.reason);
    assert!(m.reason.contains("wall-time budget"), "{}", m.reason);
}
