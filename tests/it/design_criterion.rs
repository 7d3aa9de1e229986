//! Seed 003's empirical criterion: frequency equation, orderings, the extra
//! speed and the balancing speed ranges of long, spherical and short rotors,
//! each checked against an independent evaluation (roots of Δ, the sign of the
//! functional, a time average of eq 1).

use autobal::design::criterion::{
    CriterionError, RotorShape, TwoSupportParams, determinant, dynamic_ranges, extra_speed,
    forced_response, functional, partial_frequencies, resonances, static_functional, static_ranges,
    z_max,
};
use num_complex::Complex64;
use std::f64::consts::PI;

fn rotor(a: f64, c: f64) -> TwoSupportParams {
    TwoSupportParams {
        mass: 1.0,
        transverse_inertia: a,
        polar_inertia: c,
        k1: 1.0,
        l1: 0.6,
        k2: 1.5,
        l2: 0.5,
    }
}

fn long() -> TwoSupportParams {
    rotor(0.4, 0.2)
}

fn spherical() -> TwoSupportParams {
    rotor(0.4, 0.4)
}

fn short() -> TwoSupportParams {
    rotor(0.2, 0.5)
}

/// Speeds on a fine grid, skipping those within `margin` (relative) of any edge.
fn speeds_away_from(edges: &[f64], margin: f64) -> Vec<f64> {
    (1..4000)
        .map(|i| i as f64 * 0.002)
        .filter(|w| {
            edges
                .iter()
                .all(|e| !e.is_finite() || (w - e).abs() > margin * e)
        })
        .collect()
}

/// The closed-form ranges agree with the sign of the functional (eq 32) everywhere.
fn ranges_match_functional(p: &TwoSupportParams, z: f64) {
    let ranges = static_ranges(p, z).unwrap();
    let mut edges: Vec<f64> = ranges.0.iter().flat_map(|&(a, b)| [a, b]).collect();
    edges.push(resonances(p).unwrap().omega1);
    for w in speeds_away_from(&edges, 1e-3) {
        let f = static_functional(p, z, w);
        assert_eq!(
            ranges.contains(w),
            f < 0.0,
            "z = {z}, ω = {w}: ranges {ranges:?}, functional {f}"
        );
    }
}

#[test]
fn resonances_are_roots_of_the_frequency_equation() {
    for p in [long(), spherical(), short()] {
        let r = resonances(&p).unwrap();
        let scale = p.k1 * p.k2 * (p.l1 + p.l2).powi(2);
        for w in std::iter::once(r.omega1).chain(r.omega2) {
            let d = determinant(&p, w);
            assert!(d.abs() < 1e-12 * scale, "{:?}: Δ({w}) = {d}", r.shape);
        }
        // Δ has no other positive root: its sign changes only at these speeds.
        let edges: Vec<f64> = std::iter::once(r.omega1).chain(r.omega2).collect();
        let mut changes = 0;
        let mut last = determinant(&p, 1e-3).signum();
        for w in speeds_away_from(&edges, 1e-6) {
            let s = determinant(&p, w).signum();
            if s != last {
                changes += 1;
                last = s;
            }
        }
        assert_eq!(changes, edges.len(), "{:?}", r.shape);
    }
    // For a short rotor, eq 23's ω2 makes Δ = M(C − A)(ω1² − ω²)(ω2² + ω²).
    let p = short();
    let r = resonances(&p).unwrap();
    let w2 = r.omega2_aux.unwrap();
    for w in [0.3, 1.1, 2.7] {
        let factored = p.mass
            * (p.polar_inertia - p.transverse_inertia)
            * (r.omega1.powi(2) - w * w)
            * (w2 * w2 + w * w);
        assert!((determinant(&p, w) - factored).abs() < 1e-12);
    }
}

#[test]
fn short_rotor_root_has_the_sign_of_the_corrected_eq_21() {
    // k1 l1 = k2 l2 decouples translation and tilt (k14 = 0): the only
    // resonance is the translational one, √(k11/M); eq 21 as printed gives √(k33/(C−A)).
    let p = TwoSupportParams {
        mass: 2.0,
        transverse_inertia: 0.1,
        polar_inertia: 0.3,
        k1: 3.0,
        l1: 0.5,
        k2: 1.5,
        l2: 1.0,
    };
    assert_eq!(p.stiffness().k14, 0.0);
    let r = resonances(&p).unwrap();
    assert_eq!(r.shape, RotorShape::Short);
    assert!((r.omega1 - (4.5f64 / 2.0).sqrt()).abs() < 1e-12);
    let k33 = p.stiffness().k33;
    assert!((r.omega2_aux.unwrap() - (k33 / 0.2).sqrt()).abs() < 1e-12);
}

#[test]
fn long_rotor_orderings_of_eq_17_and_38() {
    let p = long();
    let r = resonances(&p).unwrap();
    let (wp1, wp2) = partial_frequencies(&p).unwrap();
    let wp2 = wp2.unwrap();
    assert!(wp1 < wp2, "this rotor is a 'real' one in the paper's sense");
    let w2 = r.omega2.unwrap();
    assert!(r.omega1 < wp1 && wp1 < wp2 && wp2 < w2, "eq 17");
    // In general ω1 ≤ min(ω_p1, ω_p2) and ω2 ≥ max(ω_p1, ω_p2).
    for a in [0.3, 0.5, 1.0, 3.0, 10.0] {
        let q = rotor(a, 0.2);
        let r = resonances(&q).unwrap();
        let (p1, p2) = partial_frequencies(&q).unwrap();
        let p2 = p2.unwrap();
        assert!(r.omega1 <= p1.min(p2) && r.omega2.unwrap() >= p1.max(p2));
    }
    // Eq 38: ω1 ≤ ω̃(z) ≤ ω2 for every z.
    for i in -300..=300 {
        let z = i as f64 * 0.01;
        let t = extra_speed(&p, z).unwrap();
        assert!(
            r.omega1 <= t * (1.0 + 1e-12) && t <= w2 * (1.0 + 1e-12),
            "z = {z}: ω̃ = {t}"
        );
    }
}

#[test]
fn long_rotor_balances_statically_below_the_extra_speed_and_above_omega2() {
    let p = long();
    let r = resonances(&p).unwrap();
    for z in [-1.0, -0.3, 0.0, 0.2, 0.7] {
        let ranges = static_ranges(&p, z).unwrap();
        let t = extra_speed(&p, z).unwrap();
        assert_eq!(
            ranges.0,
            vec![(r.omega1, t), (r.omega2.unwrap(), f64::INFINITY)],
            "eq 40"
        );
        ranges_match_functional(&p, z);
    }
    // Chosen-parameter values, computed by hand from eqs 3, 15, 37:
    // k11 = 2.5, k14 = 0.15, k33 = 0.735, A − C = 0.2 (ω1 ≈ 1.5527,
    // ω2 ≈ 1.9401, ω̃(0.5) ≈ 1.6398).
    let k = p.stiffness();
    assert!((k.k11 - 2.5).abs() < 1e-15 && (k.k14 - 0.15).abs() < 1e-15);
    assert!((k.k33 - 0.735).abs() < 1e-15);
    let d = 0.2;
    let b: f64 = d * 2.5 + 0.735;
    let root = (b * b - 4.0 * d * (2.5 * 0.735 - 0.0225)).sqrt();
    assert!((r.omega1 - ((b - root) / (2.0 * d)).sqrt()).abs() < 1e-12);
    assert!((r.omega2.unwrap() - ((b + root) / (2.0 * d)).sqrt()).abs() < 1e-12);
    assert!((r.omega1 - 1.5527).abs() < 1e-4 && (r.omega2.unwrap() - 1.9401).abs() < 1e-4);
    let t = extra_speed(&p, 0.5).unwrap();
    assert!((t - ((0.735f64 + 2.5 * 0.25 - 0.15) / (d + 0.25)).sqrt()).abs() < 1e-12);
    assert!((t - 1.6398).abs() < 1e-4);
}

#[test]
fn dynamic_balancing_only_for_a_long_rotor_above_omega2() {
    let p = long();
    let w2 = resonances(&p).unwrap().omega2.unwrap();
    assert_eq!(dynamic_ranges(&p).unwrap().0, vec![(w2, f64::INFINITY)]);
    assert!(dynamic_ranges(&spherical()).unwrap().is_empty());
    assert!(dynamic_ranges(&short()).unwrap().is_empty());
    // Above ω2 the functional is negative for every (S, I); below it some
    // combination makes it positive (the criterion fails).
    let combos: Vec<(Complex64, Complex64)> = (0..24)
        .flat_map(|i| {
            let a = i as f64 * PI / 12.0;
            [
                (Complex64::from_polar(1.0, a), Complex64::new(0.3, 0.0)),
                (Complex64::new(0.2, 0.1), Complex64::from_polar(1.0, a)),
                (Complex64::new(0.0, 0.0), Complex64::from_polar(0.5, a)),
            ]
        })
        .collect();
    for w in [1.02 * w2, 1.5 * w2, 4.0 * w2] {
        for &(s, i) in &combos {
            assert!(functional(&p, w, s, i) < 0.0, "ω = {w}");
        }
    }
    for w in [0.5, 0.98 * w2] {
        assert!(
            combos.iter().any(|&(s, i)| functional(&p, w, s, i) > 0.0),
            "ω = {w}"
        );
    }
}

#[test]
fn spherical_rotor_balances_between_omega1_and_the_extra_speed() {
    let p = spherical();
    let r = resonances(&p).unwrap();
    assert_eq!(r.shape, RotorShape::Spherical);
    let k = p.stiffness();
    assert!((r.omega1 - ((k.k11 * k.k33 - k.k14 * k.k14) / k.k33).sqrt()).abs() < 1e-12);
    for z in [-0.8, -0.2, 0.1, 0.5, 2.0] {
        let t = extra_speed(&p, z).unwrap();
        // Eq 41 and the identity ω̃² − ω1² = (k33 − k14 z)²/(M k33 z²).
        let expected = ((k.k33 + k.k11 * z * z - 2.0 * z * k.k14) / (z * z)).sqrt();
        assert!((t - expected).abs() < 1e-12 * expected);
        let gap = (k.k33 - k.k14 * z).powi(2) / (k.k33 * z * z);
        assert!((t * t - r.omega1 * r.omega1 - gap).abs() < 1e-10);
        assert_eq!(
            static_ranges(&p, z).unwrap().0,
            vec![(r.omega1, t)],
            "eq 43"
        );
        ranges_match_functional(&p, z);
    }
    // A plane at the centre of mass: no extra speed, balancing at every speed above ω1.
    assert_eq!(extra_speed(&p, 0.0).unwrap(), f64::INFINITY);
    assert_eq!(
        static_ranges(&p, 0.0).unwrap().0,
        vec![(r.omega1, f64::INFINITY)]
    );
    // The extra speed grows without limit as the plane nears the centre of mass.
    assert!(extra_speed(&p, 0.01).unwrap() > extra_speed(&p, 0.1).unwrap());
}

#[test]
fn short_rotor_ranges_depend_on_z_max() {
    let p = short();
    let r = resonances(&p).unwrap();
    let zm = z_max(&p).unwrap();
    assert!((zm - (0.3f64).sqrt()).abs() < 1e-15, "eq 36");
    // Inside z_max: every speed above ω1 (eq 48).
    for z in [0.0f64, 0.2, -0.5, 0.54] {
        assert!(z.abs() < zm);
        assert_eq!(
            static_ranges(&p, z).unwrap().0,
            vec![(r.omega1, f64::INFINITY)],
            "z = {z}"
        );
        ranges_match_functional(&p, z);
    }
    // Outside: between ω1 and the extra speed (eq 45), which grows as z → z_max.
    let mut last = f64::INFINITY;
    for z in [0.56, 0.6, 0.8, 1.5] {
        let t = extra_speed(&p, z).unwrap();
        assert!(t > r.omega1 && t < last, "z = {z}: ω̃ = {t}");
        last = t;
        assert_eq!(static_ranges(&p, z).unwrap().0, vec![(r.omega1, t)]);
        ranges_match_functional(&p, z);
    }
    // High-speed limits (eqs 33–35): balanced for C > A + Mz², not for A < C < A + Mz².
    assert!(static_functional(&p, 0.3, 1e4) < 0.0);
    assert!(static_functional(&p, 0.8, 1e4) > 0.0);
}

#[test]
fn functional_is_the_time_average_of_eq_1() {
    // Two planes with elementary unbalances s_j at angles φ_j: average
    // Σ s_j·r_j over one revolution from the forced response (eqs 24–26).
    let p = long();
    let planes = [(-0.4, 0.3, 0.5), (0.7, 0.2, 2.0)]; // (z, s, φ)
    let s: Complex64 = planes
        .iter()
        .map(|&(_, s, a)| Complex64::from_polar(s, a))
        .sum();
    let i: Complex64 = planes
        .iter()
        .map(|&(z, s, a)| Complex64::from_polar(s * z, a))
        .sum();
    for w in [0.5, 1.3, 2.9] {
        let (d, e) = forced_response(&p, w, s, i).unwrap();
        let n = 64;
        let mut avg = 0.0;
        for k in 0..n {
            let t = 2.0 * PI / w * k as f64 / n as f64;
            let rot = Complex64::from_polar(1.0, w * t);
            for &(z, sj, a) in &planes {
                let rho = (d - Complex64::i() * z * e) * rot;
                let sv = Complex64::from_polar(sj, a) * rot;
                avg += (sv.re * rho.re + sv.im * rho.im) / n as f64;
            }
        }
        let f = functional(&p, w, s, i);
        assert!(
            (avg - f).abs() < 1e-12 * f.abs().max(1.0),
            "ω = {w}: {avg} vs {f}"
        );
    }
}

#[test]
fn invalid_parameters_are_typed_errors() {
    let mut p = long();
    p.mass = -1.0;
    assert!(matches!(
        resonances(&p),
        Err(CriterionError::NotPositive { name: "M", .. })
    ));
    let mut p = long();
    p.l1 = -0.5;
    assert_eq!(resonances(&p), Err(CriterionError::CoincidentSupports(0.0)));
    assert!(matches!(
        z_max(&long()),
        Err(CriterionError::NotShort { .. })
    ));
    assert!(matches!(
        extra_speed(&long(), f64::NAN),
        Err(CriterionError::NotFinite { name: "z", .. })
    ));
}

#[test]
fn study_criterion_prints_the_ranges_of_a_scene() {
    let run = |scene: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_study"))
            .args([
                "criterion",
                &format!("{}/scenes/{scene}", env!("CARGO_MANIFEST_DIR")),
                // Whole lines, not wrapped to 80 columns, for the assertions.
                "--wide",
            ])
            .output()
            .unwrap()
    };
    let out = run("two_support_single.toml");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("(1.4142, 2.3570) ∪ (3.1623, ∞)"), "{text}");
    let out = run("flexible_meraz.toml");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("study sweep"));
}
