//! Regression checks: the statistics against published values, Holm on a
//! textbook example, no false alarm with another seed, detection of a planted
//! physical change, refusal of a foreign baseline, and the CLI's exit codes.
//!
//! Reference values marked "scipy" were computed with SciPy 1.17.1 and
//! statsmodels 0.14 in a throwaway venv (`python3 -m venv /tmp/v &&
//! /tmp/v/bin/pip install scipy statsmodels`), on the samples [`golden`]
//! generates (the same arithmetic in Python: `((i*c) % 1.0)*scale + off`).

use autobal::check::baseline::{BaselineError, read_baseline, write_baseline};
use autobal::check::compare::{Metric, Verdict, compare};
use autobal::check::samples::design_samples;
use autobal::check::study::{CheckError, CheckOptions, check_study, record_baseline};
use autobal::stats::holm::{holm_adjust, holm_reject};
use autobal::stats::ks::ks_two_sample;
use autobal::stats::mood::mood_median_test;
use autobal::stats::proportion::fisher_two_proportions;
use autobal::study::plan::config::{StudyFile, StudyPlan};
use autobal::study::results::io::read_parquet;
use autobal::study::results::record::to_dataframe;
use autobal::study::run::{NoProgress, RunOptions, run_study};
use std::path::Path;
use std::process::Command;

/// Deterministic samples `((i·c) mod 1)·scale + off`, i = 1..=n.
fn golden(n: usize, c: f64, scale: f64, off: f64) -> Vec<f64> {
    (1..=n)
        .map(|i| ((i as f64 * c) % 1.0) * scale + off)
        .collect()
}

const PHI: f64 = 0.618_033_988_749_895;
const SQRT2_1: f64 = 0.414_213_562_373_095;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

#[test]
fn ks_exact_p_values_match_scipy() {
    // scipy.stats.ks_2samp(a, b, method="exact")
    let cases = [
        (
            golden(25, PHI, 1.0, 0.0),
            golden(30, SQRT2_1, 1.2, 0.05),
            0.2,
            0.576_696_632_096_119_1,
        ),
        (
            golden(40, PHI, 1.0, 0.0),
            golden(50, SQRT2_1, 1.0, 0.3),
            0.35,
            0.006_474_156_815_701_52,
        ),
    ];
    for (a, b, d, p) in cases {
        let r = ks_two_sample(&a, &b).unwrap();
        assert!(r.exact);
        assert!(close(r.statistic, d, 1e-12), "D {} vs {d}", r.statistic);
        assert!(close(r.p_value, p, 1e-6), "p {} vs {p}", r.p_value);
    }
}

#[test]
fn ks_asymptotic_p_values_match_the_kolmogorov_limit() {
    // m·n = 18 000 is beyond the exact method: Kolmogorov's limit with
    // n_e = mn/(m+n), i.e. R's ks.test(exact = FALSE); reference values are
    // scipy.stats.kstwobign.sf(D·√n_e). scipy's exact p-values are smaller
    // (0.2859 and 0.0474): the limit is conservative at these sizes.
    let a = golden(120, PHI, 1.0, 0.0);
    for (b, d, p) in [
        (
            golden(150, SQRT2_1, 1.1, 0.02),
            0.118_333_333_333_333_33,
            0.308_020_134_844_524_45,
        ),
        (
            golden(150, SQRT2_1, 1.0, 0.15),
            0.165,
            0.053_031_380_095_981_78,
        ),
    ] {
        let r = ks_two_sample(&a, &b).unwrap();
        assert!(!r.exact);
        assert!(close(r.statistic, d, 1e-12), "D {} vs {d}", r.statistic);
        assert!(close(r.p_value, p, 1e-6), "p {} vs {p}", r.p_value);
    }
}

#[test]
fn ks_handles_identical_empty_and_nan_samples() {
    // statrs's asymptotic series would never stop at D = 0.
    let a = golden(200, PHI, 1.0, 0.0);
    let r = ks_two_sample(&a, &a).unwrap();
    assert_eq!((r.statistic, r.p_value), (0.0, 1.0));
    assert!(ks_two_sample(&a, &[]).is_none());
    assert!(ks_two_sample(&[f64::NAN], &a).is_none());
}

#[test]
fn fisher_matches_published_values() {
    // Fisher's lady tasting tea (1935): 3 of 4 cups right each way, p = 34/70.
    let tea = fisher_two_proportions(3, 4, 1, 4).unwrap();
    assert!(close(tea.p_value, 34.0 / 70.0, 1e-9), "{}", tea.p_value);
    // scipy.stats.fisher_exact([[s_a, f_a], [s_b, f_b]]).pvalue
    for (sa, na, sb, nb, p) in [
        (490, 500, 470, 500, 0.001_808_349_319_097_833_3),
        (500, 500, 480, 500, 1.571_330_520_449_315_5e-6),
        (61, 179, 2, 3, 0.275_350_616_234_594_17),
        (200, 200, 200, 200, 1.0),
    ] {
        let r = fisher_two_proportions(sa, na, sb, nb).unwrap();
        assert!(
            close(r.p_value, p, 1e-6),
            "{sa}/{na} vs {sb}/{nb}: {}",
            r.p_value
        );
    }
    let r = fisher_two_proportions(490, 500, 470, 500).unwrap();
    assert!(close(r.difference, -0.04, 1e-12));
    assert!(fisher_two_proportions(0, 0, 1, 2).is_none());
}

#[test]
fn mood_median_test_matches_scipy() {
    // scipy.stats.median_test(a, b, ties="below") gives the grand median and
    // the table [[12, 23], [19, 17]]; p is scipy.stats.fisher_exact(table).
    let a = golden(31, PHI, 1.0, 0.0);
    let b = golden(40, SQRT2_1, 1.0, 0.2);
    let r = mood_median_test(&a, &b).unwrap();
    assert!(close(r.grand_median, 0.614_213_562_373_095, 1e-12));
    assert_eq!(r.above, [12, 23]);
    assert!(
        close(r.p_value, 0.152_789_290_753_341_77, 1e-6),
        "{}",
        r.p_value
    );
    assert!(close(r.median_a, 0.506_577_808_748_215_1, 1e-12));
    assert!(close(r.median_b, 0.691_378_028_648_447_4, 1e-12));
    assert!(mood_median_test(&a, &[]).is_none());
}

#[test]
fn holm_on_the_textbook_example() {
    // Holm's procedure as taught (e.g. Wikipedia, "Holm–Bonferroni method"):
    // p = (0.01, 0.04, 0.03, 0.005) at α = 0.05 rejects H1 and H4 only;
    // adjusted values from statsmodels.stats.multitest.multipletests(method="holm").
    let p = [0.01, 0.04, 0.03, 0.005];
    assert_eq!(holm_reject(&p, 0.05), [true, false, false, true]);
    let adj = holm_adjust(&p);
    for (a, e) in adj.iter().zip([0.03, 0.06, 0.06, 0.02]) {
        assert!(close(*a, e, 1e-12), "{adj:?}");
    }
    let p = [0.2, 0.001, 0.011, 0.04, 0.0125, 0.9];
    let adj = holm_adjust(&p);
    for (a, e) in adj.iter().zip([0.4, 0.006, 0.055, 0.12, 0.055, 0.9]) {
        assert!(close(*a, e, 1e-12), "{adj:?}");
    }
    // At 0.06 Bonferroni (threshold 0.01) rejects only the second; Holm also the third and fifth.
    assert_eq!(
        holm_reject(&p, 0.06),
        [false, true, true, false, true, false]
    );
    assert!(holm_adjust(&[]).is_empty());
}

/// A small study whose settling times spread little: two n = 4 designs at one
/// unbalance from an evenly spaced start (the idea of studies/regression.toml).
fn small_study(output: &Path, drag: f64) -> String {
    format!(
        r#"
name = "small"
seed = 11
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
kind = ["ball", "roller"]
n = 4
rho = "optimal"
race_radius = 0.05
roller_height = 0.01
drag = {drag:?}

[sampling]
samples = 150
unbalance = {{ distribution = "fixed", value = 0.5, relative_to = "capacity" }}
initial = "even"

[metrics]
t_end_revs = 400
"#,
        output.display()
    )
}

fn plan(text: &str) -> StudyPlan {
    StudyFile::parse(text, "small.toml")
        .unwrap()
        .plan(text, "small.toml")
        .unwrap()
}

fn options(seed: Option<u64>) -> CheckOptions {
    CheckOptions {
        seed,
        alpha: 0.01,
        runs: None,
        output_root: None,
        run: RunOptions::default(),
    }
}

#[test]
fn same_seed_reproduces_and_another_seed_raises_no_false_alarm() {
    let tmp = tempfile::tempdir().unwrap();
    let p = plan(&small_study(tmp.path(), 20.0));
    let dir = tmp.path().join("baseline");
    let manifest = record_baseline(&p, &dir, &RunOptions::default(), &NoProgress).unwrap();
    assert_eq!(manifest.runs, 300);
    assert_eq!(manifest.seed, 11);
    assert_eq!(
        manifest.study_sha256,
        autobal::study::results::io::sha256_hex(&p.text)
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("study.toml")).unwrap(),
        p.text
    );
    // The committed runs file keeps only what a check reads.
    let stored = read_parquet(&dir.join("runs.parquet")).unwrap();
    assert_eq!(stored.width(), autobal::check::samples::COLUMNS.len());
    assert!(dir.join("summary.parquet").is_file());

    let same = check_study(&p, &dir, &options(None), &NoProgress).unwrap();
    assert!(same.report.passed());
    assert!(same.report.identical);
    assert_eq!(same.seed, 11);
    assert_eq!(same.report.tested, 6);
    assert!(same.report.rows.iter().all(|r| r.p_value == Some(1.0)));

    let other = check_study(&p, &dir, &options(Some(12)), &NoProgress).unwrap();
    assert!(!other.report.identical);
    assert_eq!(other.seed, 12);
    let regressions: Vec<_> = other
        .report
        .rows
        .iter()
        .filter(|r| r.verdict == Verdict::Regression)
        .collect();
    assert!(regressions.is_empty(), "false alarm: {regressions:?}");
    // Independent inputs do move the statistics: the tests are live.
    assert!(
        other
            .report
            .rows
            .iter()
            .any(|r| r.metric == Metric::SettlingTime && r.statistic.unwrap() > 0.0)
    );
}

#[test]
fn planted_drag_change_of_five_percent_is_detected() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("baseline");
    let before = plan(&small_study(tmp.path(), 20.0));
    record_baseline(&before, &dir, &RunOptions::default(), &NoProgress).unwrap();
    let baseline = read_baseline(&dir).unwrap();
    // The same study with every weight's drag 5 % stronger: what a change in
    // the drag law would do to the unchanged study file.
    let mut after = plan(&small_study(&tmp.path().join("after"), 21.0));
    // Every sample, as `study check` runs them.
    after.file.sampling.racing = false;
    for seed in [11, 12] {
        after.file.seed = seed;
        // Both seeds write the same folder: the second replaces the first.
        let replace = RunOptions {
            overwrite: true,
            ..RunOptions::default()
        };
        let out = run_study(&after, &replace, &NoProgress).unwrap();
        let now = design_samples(&to_dataframe(&out.load_runs().unwrap()).unwrap()).unwrap();
        let report = compare(&baseline.samples, &now, 0.01).unwrap();
        assert!(!report.passed(), "seed {seed}: not detected");
        let flagged: Vec<_> = report
            .rows
            .iter()
            .filter(|r| r.verdict == Verdict::Regression)
            .collect();
        // Settling slows down in both designs: the KS test sees it.
        assert!(
            flagged
                .iter()
                .any(|r| r.metric == Metric::SettlingTime && r.effect.unwrap() > 0.0),
            "seed {seed}: {flagged:?}"
        );
    }
}

#[test]
fn a_baseline_of_another_study_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("baseline");
    let p = plan(&small_study(tmp.path(), 20.0));
    record_baseline(&p, &dir, &RunOptions::default(), &NoProgress).unwrap();
    // The baseline's own run sits in the check's scratch folder; a refused
    // check must leave it as it was.
    let snapshot = || -> Vec<(std::path::PathBuf, std::time::SystemTime)> {
        let mut files: Vec<_> = walk(&tmp.path().join("check"))
            .into_iter()
            .map(|f| {
                let modified = std::fs::metadata(&f).unwrap().modified().unwrap();
                (f, modified)
            })
            .collect();
        files.sort();
        files
    };
    let before = snapshot();
    let other = plan(&small_study(tmp.path(), 21.0));
    let err = check_study(&other, &dir, &options(None), &NoProgress).unwrap_err();
    assert!(matches!(
        err,
        CheckError::Baseline(BaselineError::DifferentStudy { .. })
    ));
    assert!(err.is_user_error());
    assert!(err.to_string().contains("different study file"), "{err}");
    // Nothing was run for the refused check.
    assert_eq!(snapshot(), before);
}

/// Every file under `dir` (none if it does not exist).
fn walk(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .flatten()
        .flat_map(|e| {
            let path = e.path();
            if path.is_dir() {
                walk(&path)
            } else {
                vec![path]
            }
        })
        .collect()
}

fn study_cli(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn cli_exit_codes_are_pass_regression_and_bad_input() {
    let tmp = tempfile::tempdir().unwrap();
    let study = tmp.path().join("small.toml");
    let text = small_study(tmp.path(), 20.0);
    std::fs::write(&study, &text).unwrap();
    let s = study.to_str().unwrap();
    let baseline = tmp.path().join("baseline");
    let b = baseline.to_str().unwrap();

    // No baseline yet: bad input.
    let out = study_cli(&["check", s, "--baseline", b]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no baseline"));

    let out = study_cli(&["baseline", s, "--out", b]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(baseline.join("manifest.toml").is_file());

    // Pass: exit 0 and a verdict table.
    let out = study_cli(&["check", s, "--baseline", b]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for word in ["settling_revs", "settled_fraction", "residual_rel", "pass"] {
        assert!(stdout.contains(word), "{word}: {stdout}");
    }
    // A finished runs file of the same study can be compared without re-running.
    let runs = tmp.path().join("check/small/runs.parquet");
    let out = study_cli(&[
        "check",
        s,
        "--baseline",
        b,
        "--runs",
        runs.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));

    // Another study file: refused with exit 2 and a clear message.
    let other = tmp.path().join("other.toml");
    std::fs::write(&other, small_study(tmp.path(), 21.0)).unwrap();
    let out = study_cli(&["check", other.to_str().unwrap(), "--baseline", b]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("different study file"));
    let out = study_cli(&["check", s, "--baseline", b, "--alpha", "1.5"]);
    assert_eq!(out.status.code(), Some(2));

    // A baseline recorded before a physics change (drag 5 % weaker than now):
    // the unchanged study file now regresses, exit 1.
    let p = plan(&text);
    let mut weaker = plan(&small_study(&tmp.path().join("weaker"), 20.0 / 1.05));
    weaker.file.seed = p.file.seed;
    // Every sample, as `study baseline` runs them.
    weaker.file.sampling.racing = false;
    let old = run_study(&weaker, &RunOptions::default(), &NoProgress).unwrap();
    write_baseline(&baseline, &p, &old.load_runs().unwrap()).unwrap();
    let out = study_cli(&["check", s, "--baseline", b]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains("REGRESSION"));
    assert!(String::from_utf8_lossy(&out.stderr).contains("regression detected"));
    let out = study_cli(&["check", s, "--baseline", b, "--json"]);
    assert_eq!(out.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["rows"].as_array().unwrap().len(), 6);
}

/// Planting works as documented: times stretched (and pushed past the
/// horizon: no longer settled), the slowest settled runs turned unsettled.
#[test]
fn planted_changes_do_what_they_say() {
    use autobal::check::plant::{Planted, plant};
    use autobal::check::samples::DesignSample;
    let s = DesignSample {
        design_id: 0,
        label: "x".into(),
        runs: 10,
        settled: 4,
        settling_revs: vec![10.0, 40.0, 95.0, 20.0],
        residual_rel: vec![0.01; 10],
        planes: Vec::new(),
    };
    let slower = &plant(std::slice::from_ref(&s), Planted::SettlingTime(0.1), 100.0)[0];
    assert_eq!(slower.settling_revs, vec![11.0, 44.0, 22.0]);
    assert_eq!((slower.settled, slower.runs), (3, 10));
    let fewer = &plant(
        std::slice::from_ref(&s),
        Planted::SettledFraction(0.2),
        100.0,
    )[0];
    assert_eq!(fewer.settling_revs, vec![10.0, 20.0]);
    assert_eq!((fewer.settled, fewer.runs), (2, 10));
    assert_eq!(
        plant(std::slice::from_ref(&s), Planted::Nothing, 100.0)[0],
        s
    );
}

/// The nightly study, shrunk to 50 runs per design and run with 12 seeds:
/// checked every seed against every other, the false-alarm rate stays within
/// sampling noise of α (66 checks, counted as the 6 independent replicates
/// that disjoint pairs give), and a 5 % slower settling time or 30 points
/// fewer settled runs (at 50 runs a design) are caught. Measured when
/// written: 4/66 false alarms (0/66 would also pass), 58/66 uncorrected;
/// detection 12/12 paired, 126/132 and 132/132 independent. α = 0.2 makes a missing Holm
/// correction visible: uncorrected, 24 tests per check would alarm in most
/// checks. The full table is docs/regression-checks.md's
/// (`cargo run --example check_error_rate`).
#[test]
fn false_alarm_rate_is_within_its_interval_of_alpha_and_planted_shifts_are_caught() {
    use autobal::check::plant::{Planted, alarms_independent, alarms_paired};
    use autobal::decide::verdict::settling_horizon;
    use autobal::stats::interval::wilson_interval;
    let shipped = autobal::study::plan::config::load(Path::new("studies/regression.toml")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let seeds = 12_u64;
    let mut runs = Vec::new();
    let mut horizon = 0.0;
    for k in 0..seeds {
        let mut file = shipped.file.clone();
        file.seed += k;
        file.sampling.samples = 50;
        file.output = tmp.path().display().to_string();
        let p = file.plan(&shipped.text, "regression.toml").unwrap();
        horizon = settling_horizon(&p);
        let opts = RunOptions {
            overwrite: true,
            ..RunOptions::default()
        };
        let out = run_study(&p, &opts, &NoProgress).unwrap();
        runs.push(design_samples(&read_parquet(&out.dir.join("runs.parquet")).unwrap()).unwrap());
    }
    let alpha = 0.2;
    let null = alarms_independent(&runs, Planted::Nothing, horizon, alpha).unwrap();
    assert_eq!(null.checks, 66);
    let replicates = seeds / 2;
    let (lo, _) = wilson_interval((null.rate() * replicates as f64).round() as u64, replicates);
    assert!(
        lo <= alpha,
        "false-alarm rate {} ({}/{}) above α = {alpha}",
        null.rate(),
        null.alarms,
        null.checks
    );
    // The test has teeth: the same checks without Holm's correction (a row
    // alarms at raw p ≤ α) raise significantly more alarms than α.
    let mut uncorrected = 0;
    for i in 0..runs.len() {
        for j in i + 1..runs.len() {
            let report = compare(&runs[i], &runs[j], alpha).unwrap();
            uncorrected += usize::from(
                report
                    .rows
                    .iter()
                    .any(|r| r.p_value.is_some_and(|p| p <= alpha)),
            );
        }
    }
    let (lo, _) = wilson_interval(
        (uncorrected as f64 / null.checks as f64 * replicates as f64).round() as u64,
        replicates,
    );
    assert!(
        lo > alpha,
        "uncorrected: {uncorrected}/{} alarms",
        null.checks
    );
    for change in [Planted::SettlingTime(0.05), Planted::SettledFraction(0.3)] {
        let paired = alarms_paired(&runs, change, horizon, alpha).unwrap();
        assert_eq!(
            paired.alarms, paired.checks,
            "{change:?} missed with the same seed"
        );
        let other = alarms_independent(&runs, change, horizon, alpha).unwrap();
        assert!(other.rate() >= 0.9, "{change:?}: {other:?}");
    }
}
