//! `autobal::bench` and `study bench`: structure and exact counts only —
//! wall-clock figures are never asserted (the machine is shared and noisy).

use autobal::bench::{self, BenchConfig, CARGO_COUNTS, METHODS, RTOLS};
use autobal::integrate::Method;
use autobal::model::start::StartMode;
use autobal::scene_file::SceneFile;
use std::process::Command;

/// The quick configuration trimmed further: one batch, one repeat, 10 revolutions.
fn tiny() -> BenchConfig {
    BenchConfig {
        rhs_samples: 1,
        rhs_batch_us: 20,
        revolutions: 10.0,
        solve_repeats: 1,
        reference_rtol: Some(1e-11),
        ..BenchConfig::quick()
    }
}

#[test]
fn reference_scene_is_the_three_balls_scene_file() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/three_balls.toml");
    let file = SceneFile::read(std::path::Path::new(path)).unwrap();
    assert_eq!(file.scene(), bench::reference_scene(3));
    assert_eq!(file.start.mode, StartMode::LockedSteady);
    let angles: Vec<f64> = file
        .start
        .angles_deg
        .unwrap()
        .iter()
        .map(|d| d.to_radians())
        .collect();
    assert_eq!(angles, bench::reference_angles(3));
}

#[test]
fn bench_report_has_every_case_and_consistent_counts() {
    let report = bench::run(&tiny());

    let ns: Vec<usize> = report.rhs.points.iter().map(|p| p.cargoes).collect();
    assert_eq!(ns, CARGO_COUNTS);
    for p in &report.rhs.points {
        assert_eq!(p.dim, 2 * (2 + p.cargoes));
        assert!(p.calls_per_batch >= 1 && p.batches == 1);
        assert!(p.ns_per_call > 0.0 && p.ns_per_call.is_finite());
    }
    assert!(report.rhs.fit.is_some());

    assert_eq!(report.solves.len(), METHODS.len() * RTOLS.len());
    for (i, s) in report.solves.iter().enumerate() {
        assert_eq!(s.method, METHODS[i / RTOLS.len()]);
        assert_eq!(s.rtol, RTOLS[i % RTOLS.len()]);
        assert_eq!(s.status, "finished");
        // The solver's statistics agree with a wrapper that counts the calls.
        assert_eq!(s.counted_rhs_calls, s.stats.rhs_calls, "{s:?}");
        if s.method == Method::Dp5 {
            // f(t0), one call for the initial step guess, six per attempted step (FSAL).
            assert_eq!(
                s.stats.rhs_calls,
                2 + 6 * (s.stats.steps + s.stats.rejected),
                "{s:?}"
            );
            assert_eq!((s.stats.jacobians, s.stats.factorizations), (0, 0));
        }
        let err = s.error_vs_reference.unwrap();
        assert!(err < 100.0 * s.rtol, "error {err:e} at rtol {:e}", s.rtol);
    }
    for method in METHODS {
        let rows: Vec<_> = report
            .solves
            .iter()
            .filter(|s| s.method == *method)
            .collect();
        for w in rows.windows(2) {
            // RTOLS is decreasing: tighter tolerance, more steps, smaller error.
            assert!(w[1].stats.steps > w[0].stats.steps);
            assert!(w[1].error_vs_reference < w[0].error_vs_reference);
        }
    }
}

fn study(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .args(args)
        .output()
        .expect("study runs")
}

#[test]
fn study_bench_quick_json() {
    let out = study(&["bench", "--quick", "--json", "--revolutions", "5"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["config"]["revolutions"], 5.0);
    assert_eq!(
        v["rhs"]["points"].as_array().unwrap().len(),
        CARGO_COUNTS.len()
    );
    let solves = v["solves"].as_array().unwrap();
    assert_eq!(solves.len(), METHODS.len() * RTOLS.len());
    assert_eq!(solves[0]["method"], "dp5");
    for key in [
        "median_ms",
        "us_per_revolution",
        "stats",
        "counted_rhs_calls",
    ] {
        assert!(solves[0].get(key).is_some(), "missing {key}");
    }
}

#[test]
fn study_bench_rejects_bad_options_and_documents_itself() {
    let out = study(&["bench", "--repeats", "0"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--repeats"));
    let help = study(&["bench", "--help"]);
    assert!(String::from_utf8_lossy(&help.stdout).contains("Examples:"));
}
