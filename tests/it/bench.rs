//! `autobal::bench` and `study bench`: structure and exact counts only —
//! wall-clock figures are never asserted (the machine is shared and noisy).

use autobal::bench::{
    self, BenchConfig, CARGO_COUNTS, METHODS, PEER_METHODS, PEER_RTOLS, PeerConfig, RTOLS,
    ThreadConfig,
};
use autobal::integrate::Method;
use autobal::integrate::OdeSystem;
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

#[test]
fn peer_cases_export_what_the_scipy_peer_needs() {
    let config = PeerConfig {
        revolutions: 5.0,
        repeats: 1,
        ..PeerConfig::quick()
    };
    let r = bench::peer_cases(&config);
    let dim = 2 * (2 + config.cargoes);
    assert_eq!((r.y0.len(), r.scale.len()), (dim, dim));
    assert_eq!(r.cases.len(), PEER_METHODS.len() * PEER_RTOLS.len());
    for (i, c) in r.cases.iter().enumerate() {
        assert_eq!(c.method, PEER_METHODS[i / PEER_RTOLS.len()]);
        assert_eq!(c.rtol, PEER_RTOLS[i % PEER_RTOLS.len()]);
        assert_eq!(c.status, "finished");
        assert_eq!(
            (c.atol.len(), c.y_final.len(), c.times_ms.len()),
            (dim, dim, 1)
        );
        // atol is rtol/100 on the scales that the peer recomputes.
        for (a, s) in c.atol.iter().zip(&r.scale) {
            assert!((a / (c.rtol * bench::ATOL_PER_RTOL * s) - 1.0).abs() < 1e-12);
        }
        assert!(c.error_vs_reference < 100.0 * c.rtol, "{c:?}");
    }
    assert!(
        r.reference.cross_check < 1e-9,
        "{:?}",
        r.reference.cross_check
    );
    // The exported RHS samples are the system's own values (the peer checks against them).
    let system = bench::reference_scene(config.cargoes).build().unwrap();
    assert_eq!(r.rhs_samples.len(), 3);
    assert_eq!(r.rhs_samples[0].y, r.y0);
    assert_eq!(r.rhs_samples[2].t, r.t_end);
    for s in &r.rhs_samples {
        let mut d = vec![0.0; dim];
        system.rhs(s.t, &s.y, &mut d);
        assert_eq!(d, s.dydt);
    }
}

#[test]
fn thread_scaling_reports_every_thread_count_with_identical_results() {
    let dir = tempfile::tempdir().unwrap();
    let config = ThreadConfig {
        samples: 1,
        thread_counts: vec![1, 2],
        repeats: 2,
    };
    let r = bench::measure_threads(&config, dir.path()).unwrap();
    assert_eq!(r.runs, r.designs as u64);
    assert!(r.designs >= 2 && r.rhs_calls > 0);
    assert!(r.identical_results);
    let threads: Vec<usize> = r.timings.iter().map(|t| t.threads).collect();
    assert_eq!(threads, [1, 2]);
    for t in &r.timings {
        assert_eq!(t.times_s.len(), 2);
        assert!(t.median_s > 0.0 && t.speedup.is_finite() && t.paired_speedup.is_finite());
        if cfg!(target_os = "linux") {
            assert_eq!(t.cpu_s.len(), 2);
            assert!(t.cores_used.is_some_and(|c| c >= 0.0));
        }
    }
    assert_eq!(r.timings[0].speedup, 1.0);
}

#[test]
fn study_bench_peer_cases_and_thread_scaling_json() {
    let out = study(&["bench", "--peer-cases", "--quick", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in ["y0", "scale", "t_end", "rhs_samples", "reference", "cases"] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["cases"][0]["method"], "dp5");

    let out = study(&["bench", "--thread-scaling", "--quick", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["identical_results"], true);
    assert_eq!(v["timings"].as_array().unwrap().len(), 2);

    let both = study(&["bench", "--peer-cases", "--thread-scaling"]);
    assert_eq!(both.status.code(), Some(2));
}

#[test]
fn rotating_frame_needs_ten_times_fewer_rhs_calls_over_a_long_run() {
    // Counts, not times: deterministic for a given build.
    let rows = autobal::bench::measure_fidelities(10_000.0, 1e-6, 1);
    let (full, rotating) = (&rows[0], &rows[1]);
    assert_eq!(
        (full.fidelity.as_str(), rotating.fidelity.as_str()),
        ("full", "rotating")
    );
    assert_eq!(full.settling_revs, rotating.settling_revs, "same answer");
    let ratio = full.rhs_calls as f64 / rotating.rhs_calls as f64;
    assert!(ratio >= 10.0, "only {ratio:.1}× fewer RHS calls");
}
