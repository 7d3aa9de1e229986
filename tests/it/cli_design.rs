//! `study design` from the outside: output formats and exit codes.

use std::process::Command;

fn study(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .args(args)
        .output()
        .expect("study runs")
}

#[test]
fn design_json_holds_table1() {
    let out = study(&["design", "--kind", "roller", "--n", "1..12", "--json"]);
    assert!(out.status.success());
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 12);
    for key in [
        "n",
        "kind",
        "rho_opt",
        "sector_deg",
        "s",
        "rho_max",
        "p_max",
        "a_tilde",
        "excess",
    ] {
        assert!(rows[0].get(key).is_some(), "missing key {key}");
    }
    let three = &rows[2];
    assert_eq!(three["n"], 3);
    assert_eq!(three["kind"], "roller");
    assert!((three["rho_opt"].as_f64().unwrap() - 1.0 / 3.0).abs() < 1e-12);
    assert!((three["s"].as_f64().unwrap() - 4.0 / 27.0).abs() < 1e-12);
    assert!((three["p_max"].as_f64().unwrap() - 2.0 / 3.0).abs() < 1e-9);
    assert!(rows[0]["sector_deg"].is_null());
    assert!((rows[4]["rho_opt"].as_f64().unwrap() - 0.251).abs() < 5e-4);
}

#[test]
fn design_csv_has_header_and_rows() {
    let out = study(&["design", "--kind", "ball", "--n", "2,3", "--csv"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "n,kind,rho_opt,sector_deg,s,rho_max,p_max,a_tilde,excess"
    );
    assert_eq!(lines.len(), 3);
    assert!(lines[1].starts_with("2,ball,0.428571428571"));
}

#[test]
fn design_at_a_given_rho() {
    let out = study(&[
        "design", "--kind", "ball", "--n", "3", "--rho", "0.3", "--json",
    ]);
    assert!(out.status.success());
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(rows[0]["rho_opt"], 0.3);
}

#[test]
fn zero_weights_exit_2_naming_the_value() {
    let out = study(&["design", "--n", "0"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("n = 0"), "{err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn weights_that_do_not_fit_exit_2_naming_the_value_and_limit() {
    let out = study(&["design", "--rho", "0.9", "--n", "5"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("ρ = 0.9") && err.contains("ρ_max(5)"), "{err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn help_shows_an_example() {
    let out = study(&["design", "--help"]);
    assert!(out.status.success());
    assert!(String::from_utf8(out.stdout).unwrap().contains("Examples:"));
}
