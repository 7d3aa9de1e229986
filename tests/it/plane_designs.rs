//! `[[designs.per_plane]]` (src/study/plan/plane_designs.rs): on a rotor with two
//! balancer planes each plane may have its own kind, n, ρ and drag; the grid
//! is the product over the planes, the runs build each plane's balancer,
//! the capacity is the weaker plane's, every design meets the same draws,
//! runs.parquet and summary.parquet name every plane's design, and a bad
//! entry is refused naming its key.

use crate::couple_unbalance::LONG_ROTOR;
use autobal::study::plan::config::StudyFile;
use autobal::study::plan::plane_designs::column_names;
use autobal::study::results::io::read_parquet;
use autobal::study::run::{NoProgress, RunOptions, run_one, run_study, sample_simulation};
use std::path::Path;

/// A two-support rotor (the long rotor of the couple tests) with 2 balls in
/// plane 0 and, in plane 1, the table `per_plane` (empty: the same design).
fn study(dir: &Path, per_plane: &str) -> String {
    format!(
        r#"name = "planes"
output = "{}"
[scene.rotor]
{LONG_ROTOR}
planes = [-1.0, 1.0]
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
{per_plane}
[sampling]
samples = 3
unbalance = {{ distribution = "uniform", min = 0.2, max = 0.5, relative_to = "capacity" }}
[sampling.couple]
unbalance = {{ distribution = "uniform", min = 0.05, max = 0.3, relative_to = "capacity" }}
[metrics]
t_end_revs = 20
hold_revs = 10
"#,
        dir.display()
    )
}

const PLANE_ONE: &str = "[[designs.per_plane]]\nplane = 1\nn = [3, 4]\nrho = 0.12";

fn plan(text: &str) -> Result<autobal::study::plan::config::StudyPlan, String> {
    StudyFile::parse(text, "planes.toml")
        .and_then(|f| f.plan(text, "planes.toml"))
        .map_err(|e| e.to_string())
}

#[test]
fn the_grid_is_the_product_over_the_planes_and_each_run_builds_its_planes() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(&study(dir.path(), PLANE_ONE)).unwrap();
    // 2 drags (plane 0, tied in plane 1) × 2 counts of plane 1.
    assert_eq!(p.designs.len(), 4);
    let seen: Vec<(f64, u32, f64, f64)> = p
        .designs
        .iter()
        .map(|d| {
            let one = &d.plane_designs[0];
            (d.spec.drag, one.spec.n, one.rho, one.spec.drag)
        })
        .collect();
    assert_eq!(
        seen,
        [
            (0.01, 3, 0.12, 0.01),
            (0.01, 4, 0.12, 0.01),
            (0.02, 3, 0.12, 0.02),
            (0.02, 4, 0.12, 0.02)
        ]
    );
    for d in &p.designs {
        let one = &d.plane_designs[0];
        assert_eq!(one.spec.plane, 1);
        // The design's capacity is its weaker plane's.
        assert_eq!(d.capacity, d.plane_zero_capacity.min(one.capacity));
        assert!(d.capacity < one.capacity, "2 small balls limit it");
        // The run's scene puts each plane's balancer in its plane.
        let (sample, sim) = sample_simulation(&p, d, 0);
        let scene = &sim.scene;
        // Each plane's weights start as plane 0's do, with their own count.
        assert_eq!(sample.initial_angles.len(), 2 + one.spec.n as usize);
        assert_eq!(scene.balancer.as_ref().unwrap().n, 2);
        assert_eq!(scene.balancers.len(), 1);
        assert_eq!(scene.balancers[0].n, one.spec.n);
        assert_eq!(scene.balancers[0].plane, 1);
    }
}

#[test]
fn without_the_table_every_plane_has_plane_zeros_design() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(&study(dir.path(), "")).unwrap();
    assert_eq!(p.designs.len(), 2);
    for d in &p.designs {
        assert!(d.plane_designs.is_empty());
        assert_eq!(d.capacity, d.plane_zero_capacity);
        let (sample, sim) = sample_simulation(&p, d, 0);
        assert_eq!(sim.scene.balancers[0].n, 2);
        assert_eq!(sample.initial_angles.len(), 4);
    }
}

#[test]
fn designs_that_differ_in_one_plane_meet_the_same_draws() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(&study(dir.path(), PLANE_ONE)).unwrap();
    // Designs 0 and 1 have the same plane 0 and the same capacity (plane 0
    // is the weaker): the same unbalances, couples and starts in kg·m.
    assert_eq!(p.designs[0].capacity, p.designs[1].capacity);
    for s in 0..3 {
        let (a, b) = (run_one(&p, s), run_one(&p, 3 + s));
        assert_eq!(a.unbalance, b.unbalance);
        assert_eq!(a.direction_deg, b.direction_deg);
        assert_eq!(a.couple, b.couple);
    }
}

#[test]
fn runs_and_summary_name_every_planes_design() {
    let dir = tempfile::tempdir().unwrap();
    let p = plan(&study(dir.path(), PLANE_ONE)).unwrap();
    let out = run_study(&p, &RunOptions::default(), &NoProgress).unwrap();
    for file in ["runs.parquet", "summary.parquet"] {
        let df = read_parquet(&out.dir.join(file)).unwrap();
        for name in column_names(2) {
            assert!(df.column(&name).is_ok(), "{file}: {name}");
        }
        let ids: Vec<u32> = df
            .column("design_id")
            .unwrap()
            .u32()
            .unwrap()
            .into_no_null_iter()
            .collect();
        let n1: Vec<u32> = df
            .column("n_plane1")
            .unwrap()
            .u32()
            .unwrap()
            .into_no_null_iter()
            .collect();
        let n0: Vec<u32> = df
            .column("n_plane0")
            .unwrap()
            .u32()
            .unwrap()
            .into_no_null_iter()
            .collect();
        for ((id, n0), n1) in ids.iter().zip(n0).zip(n1) {
            let d = &p.designs[*id as usize];
            assert_eq!(n0, d.spec.n, "{file}");
            assert_eq!(n1, d.plane_designs[0].spec.n, "{file}");
        }
        let cap1 = df.column("capacity_plane1").unwrap().f64().unwrap().get(0);
        assert!(cap1.is_some_and(|c| c > 0.0), "{file}");
    }
    // Per-plane statistics: a plane's settled share is at least the run's
    // (a run settles only when every plane has).
    let summary = read_parquet(&out.dir.join("summary.parquet")).unwrap();
    let overall = summary
        .column("settled_fraction")
        .unwrap()
        .f64()
        .unwrap()
        .clone();
    for p in 0..2 {
        for name in autobal::decide::plane_summary::column_names(p) {
            assert!(summary.column(&name).is_ok(), "{name}");
        }
        let plane = summary
            .column(&format!("settled_fraction_plane{p}"))
            .unwrap()
            .f64()
            .unwrap()
            .clone();
        for (o, q) in overall.iter().zip(plane.iter()) {
            assert!(q.unwrap() >= o.unwrap(), "plane {p}: {q:?} < {o:?}");
        }
    }
    // `study compare` names each plane's design and reports every plane.
    let shown = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["compare", out.dir.to_str().unwrap(), "--designs", "0,1"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&shown.stdout);
    assert!(shown.status.success(), "{text}");
    for needed in [
        "n=2/3",
        "n=2/4",
        "plane 0: settled",
        "plane 1: residual p95 (µm)",
    ] {
        assert!(text.contains(needed), "{needed}: {text}");
    }
    // A study without the table keeps its schema.
    let plain_dir = tempfile::tempdir().unwrap();
    let plain = plan(&study(plain_dir.path(), "")).unwrap();
    let out = run_study(&plain, &RunOptions::default(), &NoProgress).unwrap();
    let df = read_parquet(&out.dir.join("runs.parquet")).unwrap();
    assert!(df.column("n_plane0").is_err());
}

#[test]
fn a_bad_per_plane_entry_is_refused_naming_its_key() {
    let dir = tempfile::tempdir().unwrap();
    let two = |entry: &str| study(dir.path(), entry);
    let cases = [
        (
            two("[[designs.per_plane]]\nplane = 0\nn = 3"),
            "designs.per_plane[0].plane",
        ),
        (
            two("[[designs.per_plane]]\nplane = 2\nn = 3"),
            "designs.per_plane[0].plane",
        ),
        (
            two("[[designs.per_plane]]\nplane = 1\nn = 3\n[[designs.per_plane]]\nplane = 1\nn = 4"),
            "designs.per_plane[1].plane",
        ),
        (
            two("[[designs.per_plane]]\nplane = 1\nn = []"),
            "designs.per_plane[0].n",
        ),
        (
            two("[[designs.per_plane]]\nplane = 1\nn = 300"),
            "designs.per_plane[0].n",
        ),
        // Eight weights of ρ = 0.4 do not fit in the race.
        (
            two("[[designs.per_plane]]\nplane = 1\nn = 8\nrho = 0.4"),
            "designs.per_plane[0].rho",
        ),
        (two("[[designs.per_plane]]\nplane = 1\nsize = 3"), "size"),
        // The optimiser searches two planes' radius ratios, not one's.
        (
            two("[[designs.per_plane]]\nplane = 1\nn = 3")
                .replace("planes = [-1.0, 1.0]", "planes = [-1.0, 0.0, 1.0]")
                .replace(
                    "[sampling.couple]\n",
                    "[sampling.couple]\nat = [-1.0, 1.0]\n",
                )
                .replace(
                    "[sampling]",
                    "[optimize]\nobjective = \"capacity\"\n[sampling]",
                ),
            "optimize",
        ),
    ];
    for (text, key) in cases {
        let err = plan(&text).expect_err(key);
        assert!(err.contains(key), "{key}: {err}");
    }
    // A rotor with one balancer plane has no plane 1.
    let one_plane = two("[[designs.per_plane]]\nplane = 1\nn = 3")
        .replace("planes = [-1.0, 1.0]", "planes = [1.0]")
        .replace(
            "[sampling.couple]\n",
            "[sampling.couple]\nat = [-1.0, 1.0]\n",
        );
    let err = plan(&one_plane).expect_err("one plane");
    assert!(err.contains("designs.per_plane"), "{err}");
}

#[test]
fn check_tests_every_plane_against_a_baseline() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("planes.toml");
    std::fs::write(&file, study(dir.path(), PLANE_ONE)).unwrap();
    let study_cmd = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_study"))
            .args(args)
            .output()
            .unwrap()
    };
    let base = dir.path().join("base");
    let made = study_cmd(&[
        "baseline",
        file.to_str().unwrap(),
        "--out",
        base.to_str().unwrap(),
    ]);
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    let checked = study_cmd(&[
        "check",
        file.to_str().unwrap(),
        "--baseline",
        base.to_str().unwrap(),
        "--json",
    ]);
    let text = String::from_utf8_lossy(&checked.stdout);
    assert!(checked.status.success(), "{text}");
    let report: serde_json::Value = serde_json::from_str(&text).unwrap();
    let metrics: Vec<String> = report["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["metric"].to_string())
        .collect();
    // Both watched planes of every design are tested, beside the design's own metrics.
    for needed in ["plane_settled_fraction", "plane_settling_time"] {
        let count = metrics.iter().filter(|m| m.contains(needed)).count();
        assert_eq!(count, 2 * 4, "{needed}: {metrics:?}");
    }
    assert_eq!(report["identical"], true, "{text}");
}

#[test]
fn tolerances_rebuild_each_planes_weights_from_its_own_design() {
    let dir = tempfile::tempdir().unwrap();
    let text = study(dir.path(), PLANE_ONE).replace(
        "[sampling.couple]",
        "[sampling.tolerances]\nradius = { sigma = 0.01, relative = true }\n[sampling.couple]",
    );
    let p = plan(&text).unwrap();
    for d in &p.designs {
        let run = run_one(&p, d.id as u64 * 3);
        let w = run.weights.expect("tolerances drawn");
        let n1 = d.plane_designs[0].spec.n as usize;
        assert_eq!(w.radii.len(), 2 + n1);
        // Plane 0: ρ = 0.1 of R = 1; plane 1: ρ = 0.12; each within 3 σ (1 %).
        for (j, r) in w.radii.iter().enumerate() {
            let nominal = if j < 2 { 0.1 } else { 0.12 };
            assert!((r / nominal - 1.0).abs() <= 0.03 + 1e-12, "weight {j}: {r}");
        }
    }
}

#[test]
fn the_optimiser_treats_each_planes_count_and_radius_as_free() {
    use autobal::design::optimum::optimal_rho;
    use autobal::optimize::evaluate::{Candidate, Evaluator, PlaneChoice};
    let dir = tempfile::tempdir().unwrap();
    let text = study(dir.path(), "[[designs.per_plane]]\nplane = 1\nn = [3, 4]").replace(
        "[sampling]",
        "[optimize]\nobjective = \"capacity\"\nmax_evaluations = 40\n[sampling]",
    );
    let p = plan(&text).unwrap();
    let out = autobal::optimize::optimize(&p).unwrap();
    // One search per plane-1 count, each naming both planes.
    let scopes: Vec<&str> = out.best.iter().map(|b| b.scope.as_str()).collect();
    assert!(scopes.contains(&"ball_2_plane1_ball_3"), "{scopes:?}");
    assert!(scopes.contains(&"ball_2_plane1_ball_4"), "{scopes:?}");
    // The capacity of a design is its weaker plane's: the optimum is the
    // smaller of each plane's capacity at its own Table-1 radius.
    let spec = p.file.optimize.clone().unwrap();
    let evaluator = Evaluator {
        plan: &p,
        spec: &spec,
        samples: 1,
    };
    let at_optimum = |n: u32| {
        let rho = optimal_rho(autobal::design::Shape::Ball, n).unwrap().rho;
        (rho, n)
    };
    for n1 in [3, 4] {
        let (rho0, _) = at_optimum(2);
        let (rho1, _) = at_optimum(n1);
        let best_possible = evaluator
            .evaluate(
                Candidate {
                    kind: autobal::model::balancer::Kind::Ball,
                    n: 2,
                    rho: rho0,
                    drag: 0.01,
                    plane1: Some(PlaneChoice {
                        kind: autobal::model::balancer::Kind::Ball,
                        n: n1,
                        rho: rho1,
                    }),
                },
                "check",
            )
            .value
            .unwrap();
        let found = out
            .best
            .iter()
            .find(|b| b.scope == format!("ball_2_plane1_ball_{n1}"))
            .unwrap();
        let value = found.evaluation.value.unwrap();
        assert!(
            (value / best_possible - 1.0).abs() < 1e-6,
            "n1 = {n1}: {value} against {best_possible}"
        );
        assert_eq!(found.evaluation.candidate.plane1.unwrap().n, n1);
    }
    let optimum = read_parquet(&out.dir.join("optimum.parquet")).unwrap();
    assert!(optimum.column("n_plane1").is_ok());
}
