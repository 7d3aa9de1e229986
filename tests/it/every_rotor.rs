//! Every effect on every rotor (issue 41, item 1), each combination checked
//! against something independent of the code under test:
//! - a reduction: a two-support rotor whose supports do not couple
//!   translation with tilt (k1 l1 = k2 l2 per direction, b likewise), with
//!   its balancer and unbalance at the centre of mass, is the plane rotor on
//!   supports k1 + k2, effect by effect and all together;
//! - an analytic limit: three or more weights centre an off-centre race on
//!   the axis, leaving the race's plane whirling at exactly r = e_r, on the
//!   plane, two-support and flexible rotors alike (docs/model.md);
//! - closed forms for the critical speeds and the anisotropic orbit.

use crate::fixtures::assert_same_trajectory;
use autobal::scene_file::SceneFile;
use autobal::simulation::RunResult;

/// The dimensionless plane rotor on supports (kx, ky, bx, by) with three
/// point weights of radius 0.15 on a unit track, at ω = 4.
fn plane(kx: f64, ky: f64, bx: f64, by: f64) -> String {
    format!(
        "[rotor]\nmass = 1.0\neccentricity = 0.01\nunbalance_angle_deg = 17.188733853924695\nkx = {kx}\nky = {ky}\nbx = {bx}\nby = {by}\n{}",
        tail()
    )
}

/// The two-support rotor that reduces to [`plane`]: supports at l1 = 0.5
/// and l2 = 0.75 share k and b as 3 : 2, so k1 l1 = k2 l2 and nothing
/// couples x with β or y with α; the balancer and the unbalance sit at the
/// centre of mass.
fn decoupled_two_support(kx: f64, ky: f64, bx: f64, by: f64) -> String {
    let (a, b) = (0.6, 0.4);
    format!(
        "[rotor]\nmodel = \"two_support\"\nmass = 1.0\ntransverse_inertia = 0.5\npolar_inertia = 0.3\nl1 = 0.5\nl2 = 0.75\nk1 = {}\nk2 = {}\nb1 = {}\nb2 = {}\nk1y = {}\nk2y = {}\nb1y = {}\nb2y = {}\nplanes = [0.0]\nstatic_unbalance = 0.01\nstatic_angle_deg = 17.188733853924695\n{}",
        a * kx,
        b * kx,
        a * bx,
        b * bx,
        a * ky,
        b * ky,
        a * by,
        b * by,
        tail()
    )
}

/// Three point weights (radius 0.15: they touch at 17.3° apart), a constant
/// ω = 4, a locked start and a fixed horizon.
fn tail() -> String {
    let weight =
        "[[cargo]]\nmass = 0.01\ntrack_radius = 1.0\ndrag = 0.01\nkappa = 1.4\nradius = 0.15\n";
    format!(
        "{weight}{weight}{weight}[speed]\nmode = \"constant\"\nomega = 4.0\n[start]\nmode = \"locked_steady\"\nangles_deg = [60, 120, 180]\n[metrics]\nt_end_revs = 250\nstop_when_settled = false\n[solver]\nrtol = 1e-9\n"
    )
}

/// Effect tables, each alone and all together: race eccentricity, gravity
/// on a horizontal axis with rolling resistance (whose normal force gravity
/// changes), and contact (on by default: the weights are solid).
const EFFECTS: &[(&str, &str)] = &[
    ("contact only", ""),
    (
        "race eccentricity",
        "[effects.race_eccentricity]\noffset = 2e-4\nangle_deg = 40\n",
    ),
    (
        "gravity and rolling resistance",
        "[effects.gravity]\ng = 0.8\n[effects.rolling_resistance]\ncoefficient = 0.002\nslip_rate = 1e-4\n",
    ),
    (
        "all together",
        "[effects.race_eccentricity]\noffset = 2e-4\nangle_deg = 40\n[effects.gravity]\ng = 0.8\n[effects.rolling_resistance]\ncoefficient = 0.002\nslip_rate = 1e-4\n",
    ),
];

fn run(text: &str) -> RunResult {
    let file = SceneFile::parse(text, "scene.toml").unwrap_or_else(|e| panic!("{e}\n{text}"));
    file.simulation("scene.toml")
        .expect("simulation")
        .run(true)
        .expect("runs")
}

#[test]
fn a_decoupled_two_support_rotor_is_the_plane_rotor_under_every_effect() {
    // Isotropic and anisotropic supports (x stiffer than y, as on rigs).
    for (kx, ky, bx, by) in [(2.0, 2.0, 0.2, 0.2), (2.0, 1.6, 0.2, 0.16)] {
        for (name, effects) in EFFECTS {
            let a = run(&format!("{}{effects}", plane(kx, ky, bx, by)));
            let b = run(&format!(
                "{}{effects}",
                decoupled_two_support(kx, ky, bx, by)
            ));
            let what = format!("{name}, kx {kx} ky {ky}");
            assert_eq!(a.metrics.outcome, b.metrics.outcome, "{what}");
            assert!(
                (a.metrics.a_ref / b.metrics.a_ref - 1.0).abs() < 1e-9,
                "{what}: A_ref {} vs {}",
                a.metrics.a_ref,
                b.metrics.a_ref
            );
            assert_same_trajectory(&a, &b, 1e-5, &what);
        }
    }
}

/// The race's plane's final whirl radius over e_r, for a scene whose
/// rotor table is `rotor` (balancer plane 0 carries the weights).
fn whirl_over_offset(rotor: &str, weights: &str, omega: f64, offset: f64) -> f64 {
    let text = format!(
        "{rotor}{weights}[speed]\nmode = \"constant\"\nomega = {omega}\n[start]\nmode = \"locked_steady\"\nangles_deg = [100, 170, 260]\n[metrics]\nt_end_revs = 1500\nstop_when_settled = false\n[solver]\nrtol = 1e-10\n[effects.contact]\nenabled = false\n[effects.race_eccentricity]\noffset = {offset}\nangle_deg = 130\n"
    );
    let series = run(&text).series.expect("recorded");
    series.r[series.r.len() - 1] / offset
}

#[test]
fn an_off_centre_race_leaves_its_plane_whirling_at_the_offset_on_every_rotor() {
    let weight = "[[cargo]]\nmass = 0.01\ntrack_radius = 1.0\ndrag = 0.01\nkappa = 1.4\n";
    let weights = weight.repeat(3);
    // Unbalance in the balancer plane, so that the watched plane is the race's.
    let rotors = [
        (
            "plane",
            "[rotor]\nmass = 1.0\neccentricity = 0.01\nkx = 1.0\nky = 1.0\nbx = 0.1\nby = 0.1\n",
            4.0,
        ),
        (
            "two_support, one plane off the centre of mass",
            "[rotor]\nmodel = \"two_support\"\nmass = 1.0\ntransverse_inertia = 1.0\npolar_inertia = 0.2\nk1 = 1.0\nl1 = 2.0\nk2 = 1.0\nl2 = 2.0\nb1 = 0.05\nb2 = 0.05\nplanes = [1.0]\n[[rotor.unbalances]]\ns = 0.01\nz = 1.0\n",
            6.0,
        ),
        (
            "flexible",
            "[rotor]\nmodel = \"flexible\"\nmass = 1.0\ntransverse_inertia = 0.25\npolar_inertia = 0.5\nei = 0.16666666666666666\nlength = 2.0\nc_t = 0.05\nc_r = 0.03\neccentricity = 0.01\n",
            2.0,
        ),
    ];
    for (name, rotor, omega) in rotors {
        for offset in [1e-4, 5e-4] {
            let ratio = whirl_over_offset(rotor, &weights, omega, offset);
            assert!(
                (ratio - 1.0).abs() < 2e-3,
                "{name}, e_r {offset}: r/e_r = {ratio}"
            );
        }
    }
}

#[test]
fn the_race_of_one_plane_only_is_off_centre_when_named() {
    let text = std::fs::read_to_string("scenes/two_support_long.toml").expect("scene");
    let with = |extra: &str| {
        SceneFile::parse(
            &format!("{text}\n[effects.race_eccentricity]\noffset = 1e-4\n{extra}"),
            "s.toml",
        )
        .and_then(|f| f.simulation("s.toml").map(|_| ()))
    };
    assert!(with("plane = 1\n").is_ok());
    let message = with("plane = 2\n").expect_err("no third plane").to_string();
    assert!(
        message.contains("effects.race_eccentricity.plane"),
        "{message}"
    );
}

/// The system of a scene file's text.
fn system(text: &str) -> autobal::model::system::RotorSystem {
    SceneFile::parse(text, "scene.toml")
        .expect("valid scene")
        .simulation("scene.toml")
        .expect("simulation")
        .scene
        .build()
        .expect("builds")
}

#[test]
fn critical_speeds_match_their_closed_forms() {
    use autobal::model::critical_speeds::critical_speeds;
    let close = |got: &[f64], want: &[f64]| {
        got.len() == want.len()
            && got
                .iter()
                .zip(want)
                .all(|(g, w)| (g / w - 1.0).abs() < 1e-9)
    };
    // Plane rotor: √(k_x/M_Σ) and √(k_y/M_Σ), M_Σ with the three weights.
    let m = 1.03;
    let got = critical_speeds(&system(&plane(2.0, 1.6, 0.2, 0.16)), 5.0).unwrap();
    let want = [(1.6f64 / m).sqrt(), (2.0f64 / m).sqrt()];
    assert!(close(&got, &want), "{got:?} vs {want:?}");
    // Two-support rotor, k1 l1 = k2 l2: translation √(k11/M_Σ) per
    // direction, uncoupled from the tilt; the tilt, with spin Ω and polar
    // inertia C, has natural frequencies with ω(A ω ∓ C Ω) = k33 on
    // isotropic supports — the backward one crosses Ω at √(k33/(A + C)),
    // the forward one at √(k33/(A − C)) (A > C here). A and k33 include
    // nothing of the weights, which sit at the centre of mass.
    let k33 = |k: f64| 0.6 * k * 0.25 + 0.4 * k * 0.5625;
    let (a, c) = (0.5, 0.3);
    let iso = critical_speeds(&system(&decoupled_two_support(2.0, 2.0, 0.2, 0.2)), 5.0).unwrap();
    let mut want = vec![
        (2.0f64 / m).sqrt(),
        (2.0f64 / m).sqrt(),
        (k33(2.0) / (a + c)).sqrt(),
        (k33(2.0) / (a - c)).sqrt(),
    ];
    want.sort_by(f64::total_cmp);
    assert!(close(&iso, &want), "{iso:?} vs {want:?}");
    // Anisotropic: the tilt mixes its two planes through the gyroscopic
    // terms (no closed form), but the translations stay apart and exact.
    let aniso = critical_speeds(&system(&decoupled_two_support(2.0, 1.6, 0.2, 0.16)), 5.0).unwrap();
    assert_eq!(aniso.len(), 4, "{aniso:?}");
    for k in [1.6f64, 2.0] {
        let w = (k / m).sqrt();
        assert!(
            aniso.iter().any(|g| (g / w - 1.0).abs() < 1e-9),
            "{aniso:?} lacks {w}"
        );
    }
}

#[test]
fn a_ref_on_anisotropic_supports_is_the_orbit_s_major_semi_axis() {
    use autobal::metrics::reference::a_ref;
    // Undamped, away from resonance: x and y answer in or out of phase, so
    // the orbit is an ellipse with semi-axes U ω²/|k − M_Σ ω²| per axis.
    // Between the two resonances (√(1.2/1.03) and √(2/1.03)) the soft y
    // axis answers more than x: the old A_ref, x alone, fell short of it.
    let (kx, ky, omega) = (2.0, 1.2, 1.2);
    let s = system(&plane(kx, ky, 0.0, 0.0));
    let m = 1.03;
    let u = 0.01;
    let axis = |k: f64| u * omega * omega / (k - m * omega * omega).abs();
    let want = axis(kx).max(axis(ky));
    let got = a_ref(&s, omega);
    assert!(axis(ky) > 1.5 * axis(kx));
    assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}");
}

#[test]
fn the_shipped_bristol_rig_has_the_measured_resonances() {
    // Rodrigues et al. (2011) measured 1415, 1675, 1944 and 2310 rpm; the
    // scene's supports are calibrated to them (scripts/calibrate-bristol-rig.py)
    // and this checks the calibration with autobal's own eigen-analysis.
    let text = std::fs::read_to_string("scenes/bristol_rig.toml").expect("shipped scene");
    let speeds = autobal::model::critical_speeds::critical_speeds_in_range(&system(&text))
        .expect("computed");
    let rpm: Vec<f64> = speeds
        .iter()
        .map(|w| w * 60.0 / std::f64::consts::TAU)
        .collect();
    let measured = [1415.0, 1675.0, 1944.0, 2310.0];
    assert_eq!(rpm.len(), 4, "{rpm:?}");
    for (got, want) in rpm.iter().zip(measured) {
        assert!((got - want).abs() < 1.0, "{rpm:?} vs {measured:?}");
    }
}

/// The extra unbalance an off-centre race asks of the weights, from the
/// effect and the planes' compliance: on the plane rotor the closed form
/// e_r·|M − (k + ibω)/ω²| (the stiffer axis when anisotropic), and the same
/// on the two-support rotor that reduces to it. Before, only the plane rotor
/// had a demand (0 elsewhere, so an over-capacity study ran).
#[test]
fn an_off_centre_race_asks_the_same_capacity_on_every_rotor_that_is_the_plane_rotor() {
    use autobal::model::effect::EffectSpec;
    use autobal::model::effect::race_eccentricity::RaceEccentricity;
    use autobal::model::forced::plane_compliance;
    let offset = 2e-4;
    let effect = RaceEccentricity {
        offset,
        angle_deg: 40.0,
        plane: None,
    };
    let demand = |text: &str| {
        let s = system(text);
        let omega = 4.0;
        effect.capacity_demand(s.rotor().planes(), &|p| plane_compliance(&s, p, omega))
    };
    let closed = |kx: f64, ky: f64, bx: f64, by: f64| {
        let axis = |k: f64, b: f64| (1.0 - k / 16.0).hypot(b / 4.0);
        offset * axis(kx, bx).max(axis(ky, by))
    };
    for (kx, ky, bx, by) in [
        (3.0, 3.0, 0.2, 0.2),
        (3.0, 7.0, 0.0, 0.0),
        (40.0, 25.0, 0.0, 0.0),
    ] {
        let want = closed(kx, ky, bx, by);
        for (name, text) in [
            ("plane", plane(kx, ky, bx, by)),
            ("two-support", decoupled_two_support(kx, ky, bx, by)),
        ] {
            let got = demand(&text);
            assert!(
                (got / want - 1.0).abs() < 1e-9,
                "{name} k = ({kx}, {ky}), b = ({bx}, {by}): demand {got:e}, closed form {want:e}"
            );
        }
    }
}

/// `study map` linearises in the rotating frame, like `study linear`: a
/// scene whose equations there depend on time is refused (exit 2, the key
/// named, no file written) instead of a map of "beyond capacity" with exit 0.
#[test]
fn the_stability_map_refuses_what_the_rotating_frame_cannot_hold() {
    let map = |text: &str| {
        let dir = tempfile::tempdir().unwrap();
        let (scene, out) = (
            dir.path().join("scene.toml"),
            dir.path().join("map.parquet"),
        );
        std::fs::write(&scene, text).unwrap();
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
            .args(["map", scene.to_str().unwrap(), "--omega", "3..5"])
            .args(["--unbalance", "0.005..0.02", "--points", "3x2"])
            .args(["--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&run.stderr).to_string();
        (run.status.code(), err, out.exists())
    };
    let (code, err, wrote) = map(&plane(3.0, 3.0, 0.2, 0.2));
    assert_eq!((code, wrote), (Some(0), true), "{err}");
    for (text, key) in [
        (
            plane(3.0, 7.0, 0.2, 0.2),
            "rotor = plane: anisotropic supports",
        ),
        (
            decoupled_two_support(3.0, 7.0, 0.2, 0.2),
            "rotor = two_support: anisotropic",
        ),
        (
            plane(3.0, 3.0, 0.2, 0.2) + "[effects.gravity]\ng = 0.8\n",
            "effects = enabled: gravity",
        ),
    ] {
        let (code, err, wrote) = map(&text);
        assert_eq!((code, wrote), (Some(2), false), "{err}");
        assert!(err.contains(key), "{key}: {err}");
    }
}

/// The bearings' orbit after a run, against the frequency-domain answer:
/// below the first critical speed the weights gather on the heavy side and
/// stay, so the rotor whirls in the steady forced response to its own
/// unbalance plus the weights locked where they ended. On isotropic supports
/// each bearing's orbit is then a circle of radius |G_b q| (peak = RMS),
/// found here by the harmonic solver, a formulation the run does not use.
#[test]
fn the_bearing_orbits_after_a_run_are_the_forced_response_at_the_bearings() {
    use autobal::model::forced::{harmonic_response, plane_orbit_axes, unbalance_forcing};
    let text = std::fs::read_to_string("scenes/two_support_long.toml")
        .expect("shipped scene")
        .replace("omega = 6.32", "omega = 0.9")
        .replace(
            "t_end_revs = 1000",
            "t_end_revs = 150\nstop_when_settled = false\n[solver]\nrtol = 1e-10",
        );
    let m = run(&text).metrics;
    let (peak, rms) = (
        m.bearing_orbit_peak.clone().expect("two bearings"),
        m.bearing_orbit_rms.clone().expect("two bearings"),
    );
    let s = system(&text);
    let psi: Vec<f64> = m
        .final_rel_angles_deg
        .iter()
        .map(|d| d.to_radians())
        .collect();
    let (fc, fs) = unbalance_forcing(&s, &psi, true);
    let h = harmonic_response(&s, &fc, &fs, 0.9).expect("off resonance");
    let (l1, l2) = (2.0, 2.0);
    for (b, z) in [-l1, l2].into_iter().enumerate() {
        let map = [[1.0, 0.0, 0.0, z], [0.0, 1.0, -z, 0.0]];
        let (major, minor) = plane_orbit_axes(&h, &map);
        assert!((major / minor - 1.0).abs() < 1e-9, "isotropic: a circle");
        for (name, got) in [("peak", peak[b]), ("RMS", rms[b])] {
            assert!(
                (got / major - 1.0).abs() < 2e-3,
                "bearing {b} {name}: run {got:e}, forced response {major:e}"
            );
        }
    }
}

/// The flexible shaft (a disc on a cantilever) and a rigid rotor on two
/// supports share the kinetic energy and the form of the potential
/// ½k11(x² + y²) + ½k33(α² + β²) + k14(xβ − yα): supports at ±l with
/// l² = k33/k11 and k2 − k1 = k14/l give the shaft's k11, k14, k33, and
/// dampers b at both supports give c_t = 2b, c_r = 2b l². The two models,
/// written apart, must then run the same under every effect. (The sign of
/// k14 is a symmetry of both, (α, β) → −(α, β), so only its size shows;
/// a 10 % error in l or a factor 2 in c_r fails at A_ref.)
#[test]
fn the_flexible_shaft_is_its_equivalent_two_support_rotor_under_every_effect() {
    // EI = 1/12, L = 1: k11 = 12EI/L³ = 1, k14 = −6EI/L² = −0.5, k33 = 4EI/L = 1/3.
    let (k11, k14, k33) = (1.0f64, -0.5f64, 1.0f64 / 3.0);
    let l = (k33 / k11).sqrt();
    let (k1, k2) = ((k11 - k14 / l) / 2.0, (k11 + k14 / l) / 2.0);
    let c_t = 0.2;
    let angle = "17.188733853924695";
    let flexible = format!(
        "[rotor]\nmodel = \"flexible\"\nmass = 1.0\ntransverse_inertia = 0.25\npolar_inertia = 0.5\nei = {}\nlength = 1.0\nc_t = {c_t}\nc_r = {}\neccentricity = 0.01\nunbalance_angle_deg = {angle}\n{}",
        1.0 / 12.0,
        c_t * l * l,
        tail()
    );
    let two_support = format!(
        "[rotor]\nmodel = \"two_support\"\nmass = 1.0\ntransverse_inertia = 0.25\npolar_inertia = 0.5\nl1 = {l}\nl2 = {l}\nk1 = {k1}\nk2 = {k2}\nb1 = {b}\nb2 = {b}\nplanes = [0.0]\nstatic_unbalance = 0.01\nstatic_angle_deg = {angle}\n{}",
        tail(),
        b = c_t / 2.0
    );
    for (name, effects) in EFFECTS {
        let a = run(&format!("{flexible}{effects}"));
        let b = run(&format!("{two_support}{effects}"));
        assert_eq!(a.metrics.outcome, b.metrics.outcome, "{name}");
        assert!(
            (a.metrics.a_ref / b.metrics.a_ref - 1.0).abs() < 1e-9,
            "{name}: A_ref {} vs {}",
            a.metrics.a_ref,
            b.metrics.a_ref
        );
        assert_same_trajectory(&a, &b, 1e-5, name);
    }
}

#[test]
fn a_recorded_series_holds_each_bearings_orbit_as_a_rigid_rotor_moves() {
    // Supports at z = −l1 and +l2 of a rigid rotor: its centre of mass
    // (z = 0) lies on the line between them, x = (l2 x₀ + l1 x₁)/(l1 + l2),
    // at every sample; the plane rotor has no bearings of its own.
    // The balancer 0.3 from the centre of mass, so that the rotor tilts.
    let text =
        decoupled_two_support(1.0, 1.0, 0.1, 0.1).replace("planes = [0.0]", "planes = [0.3]");
    let series = run(&text).series.expect("recorded");
    assert_eq!(series.bearing_x.len(), 2);
    let (l1, l2) = (0.5, 0.75);
    let mut largest_tilt: f64 = 0.0;
    for k in 0..series.t.len() {
        let (x0, x1) = (series.bearing_x[0][k], series.bearing_x[1][k]);
        let (y0, y1) = (series.bearing_y[0][k], series.bearing_y[1][k]);
        assert!(
            (series.x[k] - (l2 * x0 + l1 * x1) / (l1 + l2)).abs() < 1e-15,
            "sample {k}"
        );
        assert!(
            (series.y[k] - (l2 * y0 + l1 * y1) / (l1 + l2)).abs() < 1e-15,
            "sample {k}"
        );
        largest_tilt = largest_tilt.max((x1 - x0).abs());
    }
    // The bearings are not the centre of mass: the rotor tilts.
    assert!(largest_tilt > 1e-6, "largest tilt {largest_tilt}");
    let plane = run(&plane(1.0, 1.0, 0.1, 0.1)).series.expect("recorded");
    assert!(plane.bearing_x.is_empty() && plane.bearing_y.is_empty());
}
