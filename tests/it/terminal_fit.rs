//! Output fits a terminal (issue 34): off a terminal every verb's text is
//! at most 80 columns (or `$COLUMNS`), tables drop their least important
//! columns and say so, notes wrap at words, and `--wide` prints everything
//! on one line each.

use std::path::Path;
use std::process::{Command, Output};

fn study(dir: &Path, args: &[&str], columns: Option<&str>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_study"));
    cmd.args(args).current_dir(dir).env_remove("COLUMNS");
    if let Some(c) = columns {
        cmd.env("COLUMNS", c);
    }
    cmd.output().unwrap()
}

/// The widest line, error lines aside: off a terminal an error stays on one
/// line, for logs and scripts that search it.
fn widest(text: &[u8]) -> usize {
    String::from_utf8_lossy(text)
        .lines()
        .filter(|l| !l.starts_with("error: "))
        .map(|l| l.chars().count())
        .max()
        .unwrap_or(0)
}

#[test]
fn the_ranking_compare_and_help_fit_80_columns_and_wide_keeps_every_column() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let text = crate::bad_input::study(Path::new("results"))
        .replace("n = 3\n", "n = [3, 4]\n")
        .replace("drag = 10.0\n", "drag = [2.0, 10.0]\n");
    std::fs::write(dir.join("s.toml"), text).unwrap();
    let run = study(dir, &["run", "s.toml"], None);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        widest(&run.stdout) <= 80,
        "{}",
        String::from_utf8_lossy(&run.stdout)
    );
    assert!(
        widest(&run.stderr) <= 80,
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let out = String::from_utf8_lossy(&run.stdout);
    assert!(out.contains("left out at this width"), "{out}");
    assert!(
        out.contains("finished:") || String::from_utf8_lossy(&run.stderr).contains("finished:")
    );
    // --wide: every column, notes on one line each.
    let wide = study(
        dir,
        &["merge", "results/corpus", "--out", "merged", "--wide"],
        None,
    );
    assert!(
        wide.status.success(),
        "{}",
        String::from_utf8_lossy(&wide.stderr)
    );
    let wide_out = String::from_utf8_lossy(&wide.stdout);
    assert!(widest(&wide.stdout) > 80);
    for column in ["p90", "failed", "Δ vs #1"] {
        assert!(
            wide_out.contains(column),
            "{column} missing with --wide: {wide_out}"
        );
    }
    assert!(!wide_out.contains("left out at this width"));
    // A wider terminal keeps more.
    let at_120 = study(
        dir,
        &["compare", "results/corpus", "--designs", "0,1"],
        Some("120"),
    );
    assert!(widest(&at_120.stdout) <= 120);
    let scenes = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes");
    let two_support = format!("{scenes}/two_support_single.toml");
    let three_balls = format!("{scenes}/three_balls.toml");
    let baseline = concat!(env!("CARGO_MANIFEST_DIR"), "/results/baselines/regression/");
    for args in [
        vec!["compare", "results/corpus", "--designs", "0,1"],
        vec!["--help"],
        vec!["run", "--help"],
        vec!["simulate", "--help"],
        vec!["simulate", &three_balls],
        vec!["sweep", &two_support, "--omega", "0.5..8", "--points", "4"],
        vec!["criterion", &two_support],
        vec!["linear", &three_balls],
        vec!["design", "--kind", "ball", "--n", "1..8"],
        vec!["design", "--kind", "ball", "--n", "1..8", "--rho", "0.3"],
        vec!["check", "s.toml", "--baseline", baseline],
    ] {
        let out = study(dir, &args, None);
        assert!(
            widest(&out.stdout) <= 80 && widest(&out.stderr) <= 80,
            "{args:?}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
