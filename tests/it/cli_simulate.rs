//! `study simulate` from the outside: JSON keys, series files.

use std::process::Command;

fn simulate(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("simulate")
        .arg(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/three_balls.toml"
        ))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn json_has_every_documented_key() {
    let out = simulate(&["--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for key in [
        "settled",
        "settling_time",
        "settling_revs",
        "settling_time_err",
        "residual_abs",
        "residual_rel",
        "a_ref",
        "balancing_error",
        "peak_r",
        "final_rel_angles_deg",
        "p_final",
        "outcome",
        "steps",
        "rhs_calls",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["outcome"], "settled");
    assert_eq!(v["final_rel_angles_deg"].as_array().unwrap().len(), 3);
}

#[test]
fn series_is_written_as_csv_or_parquet() {
    let tmp = tempfile::tempdir().unwrap();
    let csv = tmp.path().join("run.csv");
    assert!(
        simulate(&["--series", csv.to_str().unwrap()])
            .status
            .success()
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("t,x,y,r,eps,psi_0,psi_1,psi_2\n"));
    // At least 32 samples per revolution over the simulated revolutions.
    assert!(text.lines().count() > 32 * 50);
    let pq = tmp.path().join("run.parquet");
    assert!(
        simulate(&["--series", pq.to_str().unwrap()])
            .status
            .success()
    );
    let df = autobal::study::results::io::read_parquet(&pq).unwrap();
    assert_eq!(df.height(), text.lines().count() - 1);
    let missing = tmp.path().join("no/such/dir/run.csv");
    let out = simulate(&["--series", missing.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
}
