//! Manufacturing tolerances (`[sampling.tolerances]`) and the robust-design
//! objectives of `study optimize` (`residual_p95`, `p_residual_below`).

use autobal::model::balancer::Kind;
use autobal::optimize::evaluate::{Candidate, Evaluator};
use autobal::optimize::spec::OptimizeSpec;
use autobal::study::plan::config::{StudyFile, StudyPlan};
use autobal::study::results::io::read_parquet;
use autobal::study::results::record::{RunRecord, WEIGHT_COLUMNS, deterministic_columns};
use autobal::study::run::{NoProgress, RunOptions, Shard, run_one, run_study};
use polars::prelude::*;
use std::path::Path;

/// Two-, three-ball designs on the main job's rotor, absolute unbalances.
fn study(output: &Path, samples: u32, tolerances: &str, extra: &str) -> String {
    format!(
        r#"
name = "tol"
seed = 19
output = "{}"
[scene.rotor]
mass = 10.0
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
[scene.speed]
mode = "constant"
omega = 300.0
[designs]
kind = "ball"
n = [2, 3]
rho = 0.3
race_radius = 0.05
drag = 10.0
[sampling]
samples = {samples}
unbalance = {{ distribution = "log_uniform", min = 2e-5, max = 2e-3, relative_to = "absolute" }}
{tolerances}
[metrics]
t_end_revs = 300
stop_when_settled = false
{extra}
"#,
        output.display()
    )
}

const TOLERANCES: &str =
    "[sampling.tolerances]\nmass = { sigma = 0.02, relative = true }\nradius = { sigma = 2e-5 }";

fn plan(text: &str) -> StudyPlan {
    StudyFile::parse(text, "tol.toml")
        .unwrap()
        .plan(text, "tol.toml")
        .unwrap()
}

fn stable(path: &Path) -> DataFrame {
    let df = read_parquet(path).unwrap();
    let cols = deterministic_columns(&df);
    df.select(cols).unwrap()
}

#[test]
fn without_the_table_or_with_zero_spread_every_run_is_unchanged() {
    let tmp = tempfile::tempdir().unwrap();
    let off = plan(&study(tmp.path(), 3, "", ""));
    // σ = 0 takes the explicit-cargo path with the nominal weights: the
    // physics is the same to the bit, only the weight columns are added.
    let zero = plan(&study(
        tmp.path(),
        3,
        "[sampling.tolerances]\nmass = { sigma = 0.0 }\nradius = { sigma = 0.0, relative = true }",
        "",
    ));
    for id in 0..off.total_runs() {
        let (a, mut b) = (run_one(&off, id), run_one(&zero, id));
        assert!(a.weights.is_none());
        let w = b.weights.take().expect("sampled weights recorded");
        assert_eq!(w.masses, vec![a.weight_mass; a.n as usize]);
        assert_eq!((a.metrics, a.unbalance), (b.metrics, b.unbalance));
        // Without tolerances the record prints as it did before they existed.
        assert!(!format!("{:?}", run_one(&off, id)).contains("weights"));
    }
}

#[test]
fn each_weight_gets_its_own_draw_within_the_truncation_and_shared_across_designs() {
    let tmp = tempfile::tempdir().unwrap();
    let p = plan(&study(tmp.path(), 40, TOLERANCES, ""));
    let samples = u64::from(p.file.sampling.samples);
    let nominal_r = 0.3 * 0.05;
    let (mut z_mass, mut z_radius) = (Vec::new(), Vec::new());
    for s in 0..samples {
        let (two, three) = (run_one(&p, s), run_one(&p, samples + s));
        let (w2, w3) = (two.weights.unwrap(), three.weights.unwrap());
        assert_eq!((w2.masses.len(), w3.masses.len()), (2, 3));
        for (j, (&r, &l)) in w3.radii.iter().zip(&w3.track_radii).enumerate() {
            assert_eq!(l, 0.05 - r, "l = R − r for weight {j}");
            let zr = (r - nominal_r) / 2e-5;
            assert!(zr.abs() <= 3.0 + 1e-9, "radius draw {zr} σ");
            z_radius.push(zr);
            // The mass is the rebuilt ball's (∝ r³) times 1 + 0.02 z.
            let ball = 7850.0 * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
            let zm = (w3.masses[j] / ball - 1.0) / 0.02;
            assert!(zm.abs() <= 3.0 + 1e-9, "mass draw {zm} σ");
            z_mass.push(zm);
        }
        // Common random numbers: weights 1 and 2 of both designs drew the same.
        assert_eq!(w2.radii[..], w3.radii[..2]);
    }
    for z in [&z_mass, &z_radius] {
        let mean = z.iter().sum::<f64>() / z.len() as f64;
        let sd = (z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / z.len() as f64).sqrt();
        assert!(
            mean.abs() < 0.25 && (0.8..1.2).contains(&sd),
            "mean {mean}, sd {sd}"
        );
    }
}

#[test]
fn weight_columns_are_written_and_identical_for_threads_and_shards() {
    let (a, b, c) = (
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
    );
    let run = |dir: &Path, threads, shard| {
        let p = plan(&study(dir, 6, TOLERANCES, ""));
        let opts = RunOptions {
            threads: Some(threads),
            shard,
            ..RunOptions::default()
        };
        run_study(&p, &opts, &NoProgress).unwrap().dir
    };
    let (one, two) = (run(a.path(), 1, None), run(b.path(), 2, None));
    let whole = stable(&one.join("runs.parquet"));
    for column in WEIGHT_COLUMNS {
        assert!(whole.column(column).is_ok(), "{column} missing");
    }
    assert!(whole.equals_missing(&stable(&two.join("runs.parquet"))));
    let shards: Vec<_> = (1..=2)
        .map(|k| run(c.path(), 2, Some(Shard { index: k, count: 2 })))
        .collect();
    let merged = autobal::study::run::merge::merge(&shards, None, false).unwrap();
    assert!(whole.equals_missing(&stable(&merged.dir.join("runs.parquet"))));
    // Read back: the records carry the weights they were built with.
    let runs = merged.load_runs().unwrap();
    let p = plan(&study(a.path(), 6, TOLERANCES, ""));
    assert_eq!(runs[7].weights, run_one(&p, 7).weights);
    // A study without tolerances writes no weight columns at all.
    let d = tempfile::tempdir().unwrap();
    let p = plan(&study(d.path(), 2, "", ""));
    let dir = run_study(&p, &RunOptions::default(), &NoProgress)
        .unwrap()
        .dir;
    let df = read_parquet(&dir.join("runs.parquet")).unwrap();
    assert!(WEIGHT_COLUMNS.iter().all(|c| df.column(c).is_err()));
}

/// The objectives recomputed from the study's own rows, by a separate path:
/// sort the residuals (+∞ for a run without one) and interpolate by hand.
fn by_hand(runs: &[RunRecord], spec: f64) -> (f64, f64) {
    let mut r: Vec<f64> = runs
        .iter()
        .map(|r| match r.metrics.outcome.name() {
            "settled" | "censored" | "not_settled" => r.metrics.residual_abs,
            _ => f64::INFINITY,
        })
        .collect();
    r.sort_by(f64::total_cmp);
    let h = 0.95 * (r.len() - 1) as f64;
    let (i, f) = (h.floor() as usize, h - h.floor());
    let p95 = if f == 0.0 {
        r[i]
    } else {
        r[i] + f * (r[i + 1] - r[i])
    };
    let below = r.iter().filter(|&&v| v < spec).count() as f64 / r.len() as f64;
    (p95, below)
}

#[test]
fn robust_objectives_equal_an_independent_computation_on_the_study_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let samples = 24;
    let mut p = plan(&study(tmp.path(), samples, TOLERANCES, ""));
    // Every sample of both designs, as the evaluator runs them.
    p.file.sampling.racing = false;
    let runs = run_study(&p, &RunOptions::default(), &NoProgress)
        .unwrap()
        .load_runs()
        .unwrap();
    let spec = 2e-6;
    for (design, n) in [(0u32, 2u32), (1, 3)] {
        let rows: Vec<RunRecord> = runs
            .iter()
            .filter(|r| r.design_id == design)
            .cloned()
            .collect();
        let (p95, below) = by_hand(&rows, spec);
        // Two mismatched balls cannot cancel the smallest unbalances (and
        // settle slowly); three can: both objectives must tell them apart.
        if n == 2 {
            assert!(p95 > spec && below > 0.0 && below < 1.0, "{p95} {below}");
        } else {
            assert!(p95 < spec && below == 1.0, "{p95} {below}");
        }
        let candidate = Candidate {
            kind: Kind::Ball,
            n,
            rho: 0.3,
            drag: 10.0,
            plane1: None,
        };
        for (objective, want) in [("residual_p95", p95), ("p_residual_below", below)] {
            let spec_table: OptimizeSpec = toml::from_str(&format!(
                "objective = \"{objective}\"\nresidual_spec = {spec:e}"
            ))
            .unwrap();
            let e = Evaluator {
                plan: &p,
                spec: &spec_table,
                samples,
            }
            .evaluate(candidate, "test");
            assert_eq!(e.value, Some(want), "{objective} of n = {n}");
            assert!(e.std_err.is_finite(), "{objective} SE");
        }
    }
}

#[test]
fn p_residual_below_needs_its_spec_and_other_objectives_refuse_it() {
    let tmp = tempfile::tempdir().unwrap();
    for (optimize, needle) in [
        ("objective = \"p_residual_below\"", "residual_spec"),
        (
            "objective = \"p_residual_below\"\nresidual_spec = -1e-6",
            "residual_spec",
        ),
        (
            "objective = \"residual_p95\"\nresidual_spec = 1e-6",
            "only used by",
        ),
    ] {
        let p = plan(&study(
            tmp.path(),
            2,
            "",
            &format!("[optimize]\n{optimize}"),
        ));
        let err = autobal::optimize::optimize(&p).unwrap_err().to_string();
        assert!(err.contains(needle), "{optimize}: {err}");
    }
}

#[test]
fn race_eccentricity_is_drawn_per_run_recorded_and_leaves_r_at_the_offset() {
    use autobal::study::results::record::RACE_COLUMNS;
    let a = tempfile::tempdir().unwrap();
    let b = tempfile::tempdir().unwrap();
    let table = "[sampling.tolerances]\neccentricity = { sigma = 2e-6 }";
    let run = |dir: &Path, threads| {
        let p = plan(&study(dir, 8, table, ""));
        let opts = RunOptions {
            threads: Some(threads),
            ..RunOptions::default()
        };
        run_study(&p, &opts, &NoProgress).unwrap().dir
    };
    let (one, two) = (run(a.path(), 1), run(b.path(), 2));
    let df = stable(&one.join("runs.parquet"));
    assert!(df.equals_missing(&stable(&two.join("runs.parquet"))));
    let offsets: Vec<f64> = df
        .column(RACE_COLUMNS[0])
        .unwrap()
        .f64()
        .unwrap()
        .no_null_iter()
        .collect();
    assert_eq!(offsets.len(), 16);
    // Rayleigh-sized, within the ±3σ box, not all alike.
    assert!(
        offsets
            .iter()
            .all(|&e| e > 0.0 && e <= 3.0 * 2e-6 * 2f64.sqrt())
    );
    assert!(offsets.iter().any(|&e| (e - offsets[0]).abs() > 1e-8));
    // Common random numbers: sample k of both designs meets the same race.
    assert_eq!(offsets[..8], offsets[8..]);
    // Three balls centre the race: by the end (300 revolutions, no early
    // stop) every run of the n = 3 design is left whirling at r = e_r, also
    // the ones whose band δ·A_ref is below e_r and so never settle. Two
    // balls need not (they are on one line through w + e_r e^{iθ}): measured
    // 0.87–95 e_r.
    let residual: Vec<f64> = df
        .column("residual_abs")
        .unwrap()
        .f64()
        .unwrap()
        .no_null_iter()
        .collect();
    for (r, e) in residual[8..].iter().zip(&offsets[8..]) {
        assert!(
            (r / e - 1.0).abs() < 1e-3,
            "residual {r:.4e} against e_r {e:.4e}"
        );
    }
    // A motor-driven study is refused, naming the key.
    let motor = study(a.path(), 2, table, "").replace(
        "mode = \"constant\"\nomega = 300.0",
        "mode = \"motor\"\nstall_torque = 20.0\nomega_sync = 300.0",
    );
    let err = StudyFile::parse(&motor, "m.toml")
        .unwrap()
        .plan(&motor, "m.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("sampling.tolerances.eccentricity"), "{err}");
}
