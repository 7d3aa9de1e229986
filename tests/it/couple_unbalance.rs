//! `[sampling.couple]` (src/study/plan/couple.rs): a rotor on two supports draws
//! a couple unbalance beside the static one, each balancer plane takes
//! U_s e^{iθ_s} ± U_c e^{iθ_c}, the static draws stay those of the study
//! without the table, every design meets the same draws, and a bad table is
//! refused naming its key.

use autobal::model::rotor::RotorModel;
use autobal::study::plan::config::StudyFile;
use autobal::study::results::record::{COUPLE_COLUMNS, from_dataframe};
use autobal::study::run::{run_one, sample_simulation};
use num_complex::Complex64;

/// The long rotor of `fixtures::long_rotor` (ω1 = √2, ω2 = √10) as a
/// study's `[scene.rotor]`, without its `planes` key.
pub(crate) const LONG_ROTOR: &str = r#"model = "two_support"
mass = 1.0
transverse_inertia = 1.0
polar_inertia = 0.2
k1 = 1.0
l1 = 2.0
k2 = 1.0
l2 = 2.0
b1 = 0.05
b2 = 0.05"#;

fn study(sampling_extra: &str, rotor_model: &str) -> String {
    let rotor = if rotor_model == "two_support" {
        format!("{LONG_ROTOR}\nplanes = [-1.0, 1.0]")
    } else {
        "mass = 1.0\nkx = 1.0\nky = 1.0\nbx = 0.1\nby = 0.1".to_string()
    };
    format!(
        r#"name = "couple"
[scene.rotor]
{rotor}
[scene.speed]
mode = "constant"
omega = 6.3
[designs]
kind = "ball"
n = 2
rho = 0.1
race_radius = 1.0
density = 10.0
drag = [0.01, 0.02]
[sampling]
samples = 6
unbalance = {{ distribution = "uniform", min = 0.2, max = 0.6, relative_to = "capacity" }}
{sampling_extra}
[metrics]
t_end_revs = 20
hold_revs = 10
"#
    )
}

fn plan(text: &str) -> autobal::study::plan::config::StudyPlan {
    StudyFile::parse(text, "couple.toml")
        .unwrap()
        .plan(text, "couple.toml")
        .unwrap()
}

/// The point unbalances the run's rotor carries, as complex numbers in plane order.
fn rotor_planes(scene: &autobal::model::scene::Scene) -> Vec<Complex64> {
    match &scene.rotor {
        RotorModel::TwoSupport(r) => r
            .unbalances
            .iter()
            .map(|u| Complex64::from_polar(u.s, u.angle))
            .collect(),
        other => panic!("not a two-support rotor: {other:?}"),
    }
}

const DRAWN: &str = r#"[sampling.couple]
unbalance = { distribution = "uniform", min = 0.1, max = 0.5, relative_to = "capacity" }
phase = "uniform""#;

#[test]
fn each_plane_takes_the_static_part_plus_or_minus_the_couple() {
    let with = plan(&study(DRAWN, "two_support"));
    let without = plan(&study("", "two_support"));
    let mut couples = Vec::new();
    for design in &with.designs {
        for sample in 0..6 {
            let (s, sim) = sample_simulation(&with, design, sample);
            let (s0, sim0) = sample_simulation(&without, design, sample);
            // The static part is the study's without the table, to the bit.
            assert_eq!((s.unbalance, s.direction), (s0.unbalance, s0.direction));
            let c = s.couple.expect("a couple drawn");
            assert!((0.1..=0.5).contains(&c.fraction), "{c:?}");
            assert_eq!(c.unbalance, c.fraction * design.capacity);
            let st = Complex64::from_polar(s.unbalance, s.direction);
            let cp = Complex64::from_polar(c.unbalance, c.direction_deg.to_radians());
            let planes = rotor_planes(&sim.scene);
            assert_eq!(planes.len(), 2);
            assert!((planes[0] - (st + cp)).norm() <= 1e-15 * st.norm());
            assert!((planes[1] - (st - cp)).norm() <= 1e-15 * st.norm());
            // The per-plane equivalents of the rotor's unbalance (what ε per
            // plane measures) are these two, recovered from S and I.
            let rotor = sim.scene.rotor.as_rotor();
            let mut f = [0.0; autobal::model::rotor::MAX_DOF];
            rotor.unbalance_forces(0.0, 1.0, &mut f);
            let sizes = rotor.plane_unbalance_sizes(&f).expect("two planes");
            assert!((sizes[0] - (st + cp).norm()).abs() <= 1e-12 * st.norm());
            assert!((sizes[1] - (st - cp).norm()).abs() <= 1e-12 * st.norm());
            // Without the table every plane takes U_s, as before.
            for p in rotor_planes(&sim0.scene) {
                assert!((p - st).norm() <= 1e-15 * st.norm());
            }
            couples.push((design.id, sample, c));
        }
    }
    // Common random numbers: both designs (same capacity) meet the same couples.
    for (id, sample, c) in &couples {
        let twin = couples
            .iter()
            .find(|(i, s, _)| i != id && s == sample)
            .expect("the other design");
        assert_eq!(c, &twin.2);
    }
    // Not one couple for all: the draws vary.
    assert!(
        couples
            .windows(2)
            .any(|w| w[0].2.fraction != w[1].2.fraction)
    );
}

#[test]
fn a_couple_that_follows_the_static_part_is_one_load_at_one_axial_position() {
    // c = 0.5: a load at z = −0.5 between planes at −1 and 1 splits 3:1.
    let tied = plan(&study(
        "[sampling.couple]\nfollows_static = 0.5",
        "two_support",
    ));
    let design = &tied.designs[0];
    let (s, sim) = sample_simulation(&tied, design, 3);
    let planes = rotor_planes(&sim.scene);
    let u = Complex64::from_polar(s.unbalance, s.direction);
    assert!((planes[0] - 1.5 * u).norm() <= 1e-15 * u.norm());
    assert!((planes[1] - 0.5 * u).norm() <= 1e-15 * u.norm());
    // Physics: that is the one point unbalance 2U at z = −0.5 (static 2U,
    // moment −U), as the rotor itself sums point unbalances.
    if let RotorModel::TwoSupport(r) = &sim.scene.rotor {
        let (st, moment) = r.unbalance();
        assert!((st - 2.0 * u).norm() <= 1e-14 * u.norm());
        assert!((moment - (-0.5) * 2.0 * u).norm() <= 1e-14 * u.norm());
    }
}

#[test]
fn runs_parquet_carries_the_couple_and_each_planes_unbalance() {
    let p = plan(&study(DRAWN, "two_support"));
    let rows: Vec<_> = (0..p.total_runs()).map(|id| run_one(&p, id)).collect();
    let df = autobal::study::results::record::to_dataframe(&rows).unwrap();
    for name in COUPLE_COLUMNS {
        assert!(df.column(name).is_ok(), "{name}");
    }
    let back = from_dataframe(&df).unwrap();
    assert_eq!(back.len(), rows.len());
    for (a, b) in rows.iter().zip(&back) {
        assert_eq!(a.couple, b.couple, "run {}", a.run_id);
    }
    // A study without the table keeps its schema.
    let plain = plan(&study("", "two_support"));
    let df = autobal::study::results::record::to_dataframe(&[run_one(&plain, 0)]).unwrap();
    assert!(df.column(COUPLE_COLUMNS[0]).is_err());
}

#[test]
fn a_bad_couple_table_is_refused_naming_its_key() {
    let cases = [
        (study(DRAWN, "plane"), "sampling.couple"),
        (
            study(
                "[sampling.couple]\nfollows_static = 0.5\nunbalance = { distribution = \"fixed\", value = 0.1, relative_to = \"capacity\" }",
                "two_support",
            ),
            "sampling.couple.follows_static",
        ),
        (
            study("[sampling.couple]\n", "two_support"),
            "sampling.couple",
        ),
        (
            study(
                "[sampling.couple]\nunbalance = { distribution = \"fixed\", value = 0.1 }",
                "two_support",
            ),
            "sampling.couple.unbalance.relative_to",
        ),
        (
            study(
                "[sampling.couple]\nunbalance = { distribution = \"uniform\", min = -1.0, max = 0.1, relative_to = \"capacity\" }",
                "two_support",
            ),
            "sampling.couple.unbalance.min",
        ),
        (
            study(
                "[sampling.couple]\nfollows_static = 0.5\nphase = { fixed = 10.0 }",
                "two_support",
            ),
            "sampling.couple.phase",
        ),
    ];
    for (text, key) in cases {
        let err = StudyFile::parse(&text, "couple.toml")
            .and_then(|f| f.plan(&text, "couple.toml"))
            .expect_err(key)
            .to_string();
        assert!(err.contains(key), "{key}: {err}");
    }
}

#[test]
fn static_plus_couple_beyond_capacity_in_kilogram_metres_is_refused() {
    let capacity = plan(&study("", "two_support")).designs[0].capacity;
    let text = study(
        &format!(
            "[sampling.couple]\nunbalance = {{ distribution = \"fixed\", value = {}, relative_to = \"absolute\" }}",
            0.6 * capacity
        ),
        "two_support",
    );
    // The static part may reach 0.6 of capacity: 1.2 in the worse plane.
    let err = StudyFile::parse(&text, "couple.toml")
        .and_then(|f| f.plan(&text, "couple.toml"))
        .expect_err("beyond capacity")
        .to_string();
    // A `fixed` draw has `value`, not `max`: the refusal names the key the file has.
    assert!(err.contains("sampling.couple.unbalance.value"), "{err}");
    let allowed = text.replace(
        "[sampling.couple]",
        "require_balanceable = false\n[sampling.couple]",
    );
    assert!(
        StudyFile::parse(&allowed, "couple.toml")
            .and_then(|f| f.plan(&allowed, "couple.toml"))
            .is_ok()
    );
}

/// A drum-like rotor above both rigid-body critical speeds with the load
/// drawn as static plus couple, balanced by 3 balls in each end plane, or
/// by one balancer at z = 1 alone (`at` keeps the load's planes at ±1).
fn drum(single: bool) -> String {
    let planes = if single { "[1.0]" } else { "[-1.0, 1.0]" };
    let at = if single { "at = [1.0, -1.0]" } else { "" };
    format!(
        r#"name = "drum"
[scene.rotor]
{LONG_ROTOR}
planes = {planes}
[scene.speed]
mode = "constant"
omega = 6.3
[designs]
kind = "ball"
n = 3
rho = 0.1
race_radius = 1.0
density = 10.0
drag = 0.05
[sampling]
samples = 12
unbalance = {{ distribution = "uniform", min = 0.1, max = 0.4, relative_to = "capacity" }}
[sampling.couple]
unbalance = {{ distribution = "uniform", min = 0.1, max = 0.4, relative_to = "capacity" }}
{at}
[metrics]
t_end_revs = 400
hold_revs = 20
"#
    )
}

#[test]
fn a_single_balancer_fails_where_two_succeed_on_the_same_samples() {
    let (two, one) = (plan(&drum(false)), plan(&drum(true)));
    let (mut settled_two, mut settled_one) = (0, 0);
    let mut residual_one = Vec::new();
    for id in 0..two.total_runs() {
        let a = run_one(&two, id);
        let b = run_one(&one, id);
        // The same load: static and couple parts equal run by run.
        assert_eq!(
            (a.unbalance, a.direction_deg),
            (b.unbalance, b.direction_deg)
        );
        assert_eq!(a.couple, b.couple);
        settled_two += usize::from(a.metrics.settled);
        settled_one += usize::from(b.metrics.settled);
        residual_one.push(b.metrics.residual_rel);
    }
    // Seed 003: one plane cannot cancel a couple; the far end whirls on
    // (r counts the load's planes too).
    assert_eq!(settled_one, 0, "a single balancer settled");
    residual_one.sort_by(f64::total_cmp);
    assert!(residual_one[6] > 0.1, "{residual_one:?}");
    assert!(
        settled_two >= 10,
        "two balancers settled only {settled_two} of 12"
    );
}

#[test]
fn a_single_plane_rotor_needs_the_loads_planes() {
    for (text, key) in [
        (
            drum(true).replace("at = [1.0, -1.0]", ""),
            "sampling.couple.at",
        ),
        (
            drum(true).replace("at = [1.0, -1.0]", "at = [1.0, 1.0]"),
            "sampling.couple.at",
        ),
    ] {
        let err = StudyFile::parse(&text, "drum.toml")
            .and_then(|f| f.plan(&text, "drum.toml"))
            .expect_err(key)
            .to_string();
        assert!(err.contains(key), "{key}: {err}");
    }
}

/// The locked forced response to static plus couple unbalance, against the
/// closed form: with symmetric supports (k1 = k2 = k, l1 = l2 = l)
/// translation and tilt decouple, and a synchronous forward whirl answers
/// the static part S = U1 + U2 with X = S ω²/(2k − M ω² + 2ibω) and the
/// moment I = z1 U1 + z2 U2 with W = I ω²/(2k l² − (A − C) ω² + 2ibl²ω)
/// (the polar inertia C lightens the tilt); plane z moves by X + z W.
#[test]
fn the_locked_response_to_static_plus_couple_is_the_closed_form() {
    use autobal::model::scene::Scene;
    use autobal::study::plan::couple::{SampledCouple, apply, plane_unbalances};
    let base = crate::fixtures::long_rotor(vec![-1.0, 1.0]);
    let (m, a, c, k, l, b) = (
        base.mass,
        base.transverse_inertia,
        base.polar_inertia,
        base.k1,
        base.l1,
        base.b1,
    );
    let couple = SampledCouple {
        unbalance: 0.004,
        fraction: 0.0,
        direction_deg: 70.0,
    };
    let planes = plane_unbalances((0.01, 0.3), &couple);
    let mut rotor = RotorModel::TwoSupport(base);
    apply(&mut rotor, None, &planes);
    let u: Vec<Complex64> = planes
        .iter()
        .map(|&(s, angle)| Complex64::from_polar(s, angle))
        .collect();
    let (s, i) = (u[0] + u[1], -u[0] + u[1]);
    // Below ω1 = √2, between the criticals, above ω2 = √10.
    for omega in [0.7, 2.0, 6.3] {
        let scene = Scene {
            rotor: rotor.clone(),
            balancer: None,
            balancers: Vec::new(),
            // A scene needs weights: one of 1e-15 kg (its mass enters A_ref at 1e-15).
            cargo: vec![autobal::model::cargo::Cargo::point(1e-15, 1.0, 0.0, 1.4)],
            speed: autobal::model::speed::SpeedLaw::Constant { omega },
            effects: Default::default(),
        };
        let system = scene.build().unwrap();
        let w2 = omega * omega;
        let x = s * w2 / Complex64::new(2.0 * k - m * w2, 2.0 * b * omega);
        let w = i * w2 / Complex64::new(2.0 * k * l * l - (a - c) * w2, 2.0 * b * l * l * omega);
        let closed = [-1.0, 1.0]
            .iter()
            .map(|z| (x + *z * w).norm())
            .fold(0.0, f64::max);
        let model = autobal::metrics::reference::a_ref(&system, omega);
        assert!(
            (model / closed - 1.0).abs() < 1e-10,
            "ω = {omega}: A_ref {model} against the closed form {closed}"
        );
    }
}

/// Seed 003's criterion over a speed sweep, with couple unbalance drawn:
/// two balancers balance the load only above ω₂ (below ω₁ and between the
/// criticals they cannot), one balancer never does. The speeds come from
/// the criterion (`design::criterion`), the shares from the simulations.
#[test]
fn a_speed_sweep_with_couple_unbalance_follows_seed_003s_criterion() {
    use autobal::design::criterion::resonances;
    let r = resonances(&crate::fixtures::long_rotor(vec![-1.0, 1.0]).criterion_params()).unwrap();
    let (w1, w2) = (r.omega1, r.omega2.expect("a second critical speed"));
    let settled = |single: bool, omega: f64| {
        let text = drum(single).replace("omega = 6.3", &format!("omega = {omega}"));
        let p = plan(&text);
        (0..p.total_runs())
            .filter(|&id| run_one(&p, id).metrics.settled)
            .count()
    };
    for (omega, two_at_least, two_at_most) in [
        (0.6 * w1, 0, 1),
        (0.5 * (w1 + w2), 0, 1),
        (2.0 * w2, 10, 12),
    ] {
        let two = settled(false, omega);
        assert!(
            (two_at_least..=two_at_most).contains(&two),
            "ω = {omega:.3} (ω1 {w1:.3}, ω2 {w2:.3}): two balancers settled {two} of 12"
        );
        assert_eq!(
            settled(true, omega),
            0,
            "ω = {omega:.3}: one balancer settled"
        );
    }
}

/// Per-plane results: with one balancer at z = 1 against a static and
/// couple load at ±1, its own plane calms and the far plane keeps whirling;
/// with two, both calm. runs.parquet carries each plane's A_ref and residual.
#[test]
fn each_plane_reports_its_residual_and_the_far_end_of_a_single_balancer_whirls() {
    let (two, one) = (plan(&drum(false)), plan(&drum(true)));
    for id in 0..4 {
        let a = run_one(&two, id).metrics;
        let b = run_one(&one, id).metrics;
        // Watched planes: two's balancers at −1 and 1; one's balancer at 1, then the load's −1.
        let (ra, rb) = (a.plane_residual_abs.unwrap(), b.plane_residual_abs.unwrap());
        let (aa, ab) = (a.plane_a_ref.unwrap(), b.plane_a_ref.unwrap());
        assert_eq!((ra.len(), rb.len(), aa.len(), ab.len()), (2, 2, 2, 2));
        // The overall A_ref is the largest plane's; the overall residual at least each plane's.
        assert_eq!(a.a_ref, aa.iter().copied().fold(0.0, f64::max));
        for (r, ar) in rb.iter().zip(&ab) {
            assert!(*r <= b.residual_abs * (1.0 + 1e-12) && *ar > 0.0);
        }
        let rel = |r: &[f64], a: &[f64], p: usize| r[p] / a[p];
        assert!(
            rel(&rb, &ab, 0) < 0.5 * rel(&rb, &ab, 1),
            "run {id}: the balancer's plane {} against the far plane {}",
            rel(&rb, &ab, 0),
            rel(&rb, &ab, 1)
        );
        // Settled: every plane settled into its own band δ·A_ref of the
        // plane, no later than the run (a plane's hold is met within the
        // run's); its residual inside that band.
        let (sa, sb) = (
            a.plane_settling_revs.clone().unwrap(),
            b.plane_settling_revs.clone().unwrap(),
        );
        assert_eq!((sa.len(), sb.len()), (2, 2));
        if a.settled {
            let run = a.settling_revs.unwrap();
            for ((s, r), ar) in sa.iter().zip(&ra).zip(&aa) {
                let s = s.unwrap_or_else(|| panic!("run {id}: settled with a plane unsettled"));
                assert!(s <= run + 1e-9, "run {id}: plane at {s}, run at {run}");
                assert!(*r < 0.05 * ar, "run {id}: {ra:?} {aa:?}");
            }
        }
        // The single balancer's far plane never settles.
        assert!(!b.settled && sb[1].is_none(), "run {id}: {sb:?}");
        // ε per balancer plane: two planes on two supports, small in both
        // where they settled; one balancer plane has no such split.
        let ea = a
            .plane_balancing_error
            .clone()
            .expect("two balancer planes");
        assert_eq!(ea.len(), 2);
        if a.settled {
            assert!(ea.iter().all(|e| *e < 0.05), "run {id}: {ea:?}");
        }
        assert!(b.plane_balancing_error.is_none());
    }
    let rows: Vec<_> = (0..2).map(|id| run_one(&one, id)).collect();
    let df = autobal::study::results::record::to_dataframe(&rows).unwrap();
    let back = from_dataframe(&df).unwrap();
    for (x, y) in rows.iter().zip(&back) {
        assert_eq!(x.metrics.plane_residual_abs, y.metrics.plane_residual_abs);
        assert_eq!(x.metrics.plane_a_ref, y.metrics.plane_a_ref);
        assert_eq!(x.metrics.plane_settling_revs, y.metrics.plane_settling_revs);
        assert_eq!(
            x.metrics.plane_balancing_error,
            y.metrics.plane_balancing_error
        );
    }
}
