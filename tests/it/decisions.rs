//! The decision printed on top of the numbers: no crown for a balancer that
//! does not work (and why), failed runs never absorbed, divergence judged
//! on a scale that covers the start, run-ups timed from the operating speed.

use autobal::decide::decision::{Crown, Recommendation, StoredVerdict, StudyDecision};
use autobal::decide::verdict::{Favours, Shortfall, favoured};
use autobal::study::plan::criterion::Criterion;
use autobal::study::results::io::read_parquet;
use std::path::Path;
use std::process::{Command, Output};

/// The issue's rotor: 8 kg at 1200 rpm on soft supports, steel balls in a
/// 25 mm race, clustered at the start.
fn drum_like(results: &Path, name: &str, unbalance: &str, extra: &str) -> String {
    format!(
        r#"name = "{name}"
output = "{}"
{}drag = [0.5, 2.0]
[sampling]
samples = 4
unbalance = {unbalance}
initial = "clustered"
[metrics]
hold_revs = 20
t_end_revs = 120
{extra}"#,
        results.display(),
        crate::fixtures::SOFT_ROTOR
    )
}

fn run(dir: &Path, text: &str, args: &[&str]) -> Output {
    let path = dir.join("study.toml");
    std::fs::write(&path, text).unwrap();
    Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("run")
        .arg(&path)
        .arg("--quiet")
        // Whole sentences, not wrapped to 80 columns, for the assertions.
        .arg("--wide")
        .args(args)
        .output()
        .unwrap()
}

fn outcomes(runs: &Path) -> Vec<String> {
    let df = read_parquet(runs).unwrap();
    df.column("outcome")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|o| o.unwrap_or_default().to_string())
        .collect()
}

#[test]
fn a_tiny_unbalance_against_clustered_weights_is_not_divergence() {
    let tmp = tempfile::tempdir().unwrap();
    // 2e-5 … 2e-4 of the capacity: A_ref is about 10 nm, while the clustered
    // weights alone throw the rotor about 90 µm, 10⁴ A_ref, at the start.
    let text = drum_like(
        &tmp.path().join("results"),
        "tiny",
        r#"{ distribution = "uniform", min = 2e-5, max = 2e-4, relative_to = "capacity" }"#,
        "",
    );
    let out = run(tmp.path(), &text, &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let outcomes = outcomes(&tmp.path().join("results/tiny/runs.parquet"));
    assert_eq!(outcomes.len(), 8);
    assert!(
        outcomes.iter().all(|o| o != "diverged"),
        "{outcomes:?}\n{stdout}"
    );
}

#[test]
fn a_dead_band_wider_than_the_settling_band_crowns_no_design_and_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let text = drum_like(
        &tmp.path().join("results"),
        "deadband",
        r#"{ distribution = "uniform", min = 2e-5, max = 2e-4, relative_to = "absolute" }"#,
        "[scene.effects.rolling_resistance]\ncoefficient = 1e-3\n",
    );
    let out = run(tmp.path(), &text, &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(
        stdout.contains("verdict: no design balances this rotor"),
        "{stdout}"
    );
    // μ_s·l = 1e-3 × 15.9 mm = 15.9 µm, against δ·A_ref below 1 µm: the
    // re-runs without rolling resistance settle, and the floor check
    // stays beside them as context.
    assert!(
        stdout.contains("cause: why 4 of 4 runs do not settle")
            && stdout.contains("rolling resistance — removing it settles 4 of 4")
            && stdout.contains("say: the dead band of rolling resistance μ_s·l = 15.906 µm"),
        "{stdout}"
    );
    assert!(
        stdout.contains("dead band μ_s·l (l the track radius) against the settling band δ·A_ref"),
        "{stdout}"
    );
    assert!(!stdout.contains("recommendation: design"), "{stdout}");
    assert!(!stdout.contains("is better than"), "{stdout}");
    // When no design balances: the share worse than none, and, with the
    // dead band beyond A_ref, that the weights never break away and by how
    // much the friction must fall (dead band over the band δ·A_ref).
    assert!(
        stdout.contains("of its runs end worse than with no balancer"),
        "{stdout}"
    );
    // Here the dead band (15.9 µm) is below A_ref (18.7 µm): a wider band
    // could still be met, so nothing says the weights never break away.
    assert!(!stdout.contains("never break away"), "{stdout}");
    let doubled = text.replace("coefficient = 1e-3", "coefficient = 2e-3");
    let out = run(tmp.path(), &doubled, &["--overwrite"]);
    let twice = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        twice.contains("at this friction the weights never break away"),
        "{twice}"
    );
    let summary = read_parquet(&tmp.path().join("results/deadband/summary.parquet")).unwrap();
    let at_best = |name: &str| {
        let rank = summary.column("rank").unwrap().u32().unwrap().clone();
        let row = (0..summary.height())
            .find(|&i| rank.get(i) == Some(1))
            .unwrap();
        summary
            .column(name)
            .unwrap()
            .f64()
            .unwrap()
            .get(row)
            .unwrap()
    };
    assert!(at_best("dead_band_m") > at_best("a_ref_median"));
    let lower = at_best("dead_band_m") / at_best("settling_band_m");
    assert!(
        twice.contains(&format!(
            "at least {lower:.0}× lower would bring the dead band inside"
        )),
        "{lower}: {twice}"
    );
    run(tmp.path(), &text, &["--overwrite"]);
    let summary = read_parquet(&tmp.path().join("results/deadband/summary.parquet")).unwrap();
    // The same decision, typed.
    let decision = StudyDecision::from_summary(&summary).unwrap();
    assert_eq!(decision.recommendation, Recommendation::NoneBalances);
    match &decision.crown {
        Crown::NoneBalances { cause_key, .. } => {
            assert_eq!(cause_key.as_deref(), Some("dead_band"));
        }
        other => panic!("{other:?}"),
    }
    let verdicts: Vec<&str> = summary
        .column("vs_best_verdict")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .flatten()
        .collect();
    assert!(!verdicts.contains(&"best"), "{verdicts:?}");
    assert!(verdicts.contains(&"no_design_balances"), "{verdicts:?}");
}

/// An off-centre race leaves its plane whirling at e_r whatever the weights
/// do: a floor above the settling band is named as the cause (before, the
/// diagnosis said "none of the usual causes applies").
#[test]
fn a_race_eccentricity_above_the_settling_band_is_named_as_the_cause() {
    let tmp = tempfile::tempdir().unwrap();
    // e_r = 10 µm against δ·A_ref of about 2 µm (U = 0.2–0.4 of capacity).
    let text = drum_like(
        &tmp.path().join("results"),
        "runout",
        r#"{ distribution = "uniform", min = 0.2, max = 0.4, relative_to = "capacity" }"#,
        "[scene.effects.race_eccentricity]\noffset = 1e-5\n",
    );
    let out = run(tmp.path(), &text, &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(
        stdout.contains("verdict: no design balances this rotor"),
        "{stdout}"
    );
    // Re-run without the eccentricity, the runs settle; the floor check
    // stays beside them as context.
    assert!(
        stdout.contains("race eccentricity — removing it settles")
            && stdout.contains("say: the race eccentricity e_r (effects.race_eccentricity.offset)")
            && stdout.contains("r = e_r = 10.000 µm"),
        "{stdout}"
    );
    assert!(!stdout.contains("recommendation: design"), "{stdout}");
}

/// A crowned design that settles in under 90 % of its runs is recommended
/// with its shortfall stated beside it (before, without a word).
#[test]
fn a_marginal_winner_is_recommended_with_its_shortfall_stated() {
    let tmp = tempfile::tempdir().unwrap();
    // A horizon of 60 rev (hold 20): about half the runs settle in time.
    let text = drum_like(
        &tmp.path().join("results"),
        "marginal",
        r#"{ distribution = "uniform", min = 0.2, max = 0.9, relative_to = "capacity" }"#,
        "",
    )
    .replace("samples = 4", "samples = 12")
    .replace("t_end_revs = 120", "t_end_revs = 60");
    let out = run(tmp.path(), &text, &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let summary = read_parquet(&tmp.path().join("results/marginal/summary.parquet")).unwrap();
    let settled: Vec<f64> = summary
        .column("settled_fraction")
        .unwrap()
        .f64()
        .unwrap()
        .iter()
        .flatten()
        .collect();
    let best = settled.iter().copied().fold(0.0, f64::max);
    assert!((0.5..0.9).contains(&best), "{settled:?}\n{stdout}");
    match StudyDecision::from_summary(&summary)
        .unwrap()
        .recommendation
    {
        Recommendation::Build { shortfalls, .. } => {
            assert_eq!(shortfalls, vec![Shortfall::SettlesTooRarely(best)]);
        }
        other => panic!("{other:?}"),
    }
    assert!(
        stdout.contains(&format!(
            "with a caution: it settles in only {:.1} % of its runs (a design that works settles in at least 90 %)",
            100.0 * best
        )),
        "{stdout}"
    );
    let worse = summary
        .column("worse_than_none_fraction")
        .unwrap()
        .f64()
        .unwrap()
        .clone();
    assert!(worse.iter().flatten().all(|w| (0.0..=1.0).contains(&w)));
}

/// An estimate rung measures no residual: the summary's residual columns
/// are null and the ranking says its numbers are predictions (before, the
/// analytic rung printed "residual p95 0.00 µm" as if measured).
#[test]
fn estimates_never_pass_for_measurements() {
    let tmp = tempfile::tempdir().unwrap();
    let text = drum_like(
        &tmp.path().join("results"),
        "estimate",
        r#"{ distribution = "uniform", min = 0.2, max = 0.8, relative_to = "capacity" }"#,
        "[solver]\nfidelity = \"analytic\"\n",
    );
    let out = run(tmp.path(), &text, &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(stdout.contains("(estimates, not measurements:"), "{stdout}");
    let summary = read_parquet(&tmp.path().join("results/estimate/summary.parquet")).unwrap();
    for column in [
        "residual_rel_p95",
        "residual_abs_p95",
        "residual_rel_median",
    ] {
        let c = summary.column(column).unwrap();
        assert_eq!(c.null_count(), c.len(), "{column} should be null");
    }
    assert!(summary.column("estimated").unwrap().bool().unwrap().all());
}

#[test]
fn runs_out_of_budget_make_the_study_exit_1_naming_max_steps_after_writing_everything() {
    let tmp = tempfile::tempdir().unwrap();
    let text = crate::bad_input::study(&tmp.path().join("results"))
        .replace("[solver]\n", "[solver]\nmax_steps = 150\n");
    let out = run(tmp.path(), &text, &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("raise [solver] max_steps (now 150)"),
        "{stderr}"
    );
    let dir = tmp.path().join("results/corpus");
    assert!(dir.join("runs.parquet").exists() && dir.join("summary.parquet").exists());
    // The ranking's "failed" column shows each design's failed runs: the
    // sum of its cells is the count of failed runs in runs.parquet.
    let stdout = String::from_utf8_lossy(&out.stdout);
    let failed_runs = outcomes(&dir.join("runs.parquet"))
        .iter()
        .filter(|o| *o == "budget_exceeded" || *o == "solver_failed")
        .count();
    assert!(failed_runs > 0);
    let lines: Vec<Vec<char>> = stdout.lines().map(|l| l.chars().collect()).collect();
    let header = &lines[1];
    let end = (0..header.len())
        .find(|&i| header[i..].starts_with(&['f', 'a', 'i', 'l', 'e', 'd']))
        .expect("a failed column")
        + 6;
    let shown: usize = lines[3..]
        .iter()
        .take_while(|l| l.first().is_some_and(|c| c.is_ascii_digit()))
        .map(|l| {
            let cell: String = l[..end].iter().collect();
            cell.split_whitespace()
                .last()
                .unwrap()
                .parse::<usize>()
                .unwrap()
        })
        .sum();
    assert_eq!(shown, failed_runs, "{stdout}");
    assert!(
        outcomes(&dir.join("runs.parquet"))
            .iter()
            .any(|o| o == "budget_exceeded")
    );
    // Run as two shards, the merge says the same.
    for shard in ["1/2", "2/2"] {
        let out = run(tmp.path(), &text, &["--overwrite", "--shard", shard]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let merged = tmp.path().join("merged");
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["merge", "--out", merged.to_str().unwrap()])
        .arg(dir.join("shard-1-of-2"))
        .arg(dir.join("shard-2-of-2"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("raise [solver] max_steps (now 150)"),
        "{stderr}"
    );
    assert!(merged.join("summary.parquet").exists());
}

#[test]
fn a_run_up_is_timed_from_the_operating_speed() {
    let tmp = tempfile::tempdir().unwrap();
    let text = crate::bad_input::study(&tmp.path().join("results"))
        .replace(
            "mode = \"constant\"\nomega = 300.0",
            "mode = \"ramp\"\nomega_start = 150.0\nomega_end = 300.0\nduration = 0.5",
        )
        .replace("t_end_revs = 100", "t_end_revs = 200");
    let out = run(tmp.path(), &text, &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    assert!(
        stdout.contains("counted from the moment the operating speed was reached"),
        "{stdout}"
    );
    assert!(stdout.contains("median from t = 0"), "{stdout}");
    let summary = read_parquet(&tmp.path().join("results/corpus/summary.parquet")).unwrap();
    let from_speed = summary
        .column("settling_revs_median_km")
        .unwrap()
        .f64()
        .unwrap()
        .get(0)
        .unwrap();
    let from_start = summary
        .column("settling_revs_median_km_from_start")
        .unwrap()
        .f64()
        .unwrap()
        .get(0)
        .unwrap();
    // The ramp takes 0.5 s = 23.9 rev of 300 rad/s, and settling is only
    // judged at speed: the two clocks differ by the ramp.
    assert!(from_start - from_speed > 23.0, "{from_start} {from_speed}");
    // Revolutions of the operating speed, in seconds after reaching it.
    let period = summary
        .column("seconds_per_rev")
        .unwrap()
        .f64()
        .unwrap()
        .get(0)
        .unwrap();
    assert_eq!(period, std::f64::consts::TAU / 300.0);
    assert!(
        stdout.contains("(at the operating speed one revolution takes 20.94 ms"),
        "{stdout}"
    );
    assert!(stdout.contains("s after the rotor reached it)"), "{stdout}");
}

/// One clock on a run-up: the horizon τ counts only the revolutions
/// observable after the ramp (t_end − hold − ramp), every run that did not
/// settle is censored there, and the restricted mean stays inside it
/// (before 2026-12-07 τ counted the ramp too, and a design's restricted
/// mean read 171 rev where 113 were observable).
#[test]
fn a_run_up_is_censored_at_the_revolutions_observable_after_the_ramp() {
    let tmp = tempfile::tempdir().unwrap();
    let text = crate::bad_input::study(&tmp.path().join("results"))
        .replace(
            "mode = \"constant\"\nomega = 300.0",
            "mode = \"ramp\"\nomega_start = 150.0\nomega_end = 300.0\nduration = 0.5",
        )
        .replace("drag = 10.0", "drag = [10.0, 400.0]")
        .replace("samples = 2", "samples = 8");
    let out = run(tmp.path(), &text, &[]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = read_parquet(&tmp.path().join("results/corpus/summary.parquet")).unwrap();
    let column = |name: &str| -> Vec<f64> {
        let c = summary.column(name).unwrap().f64().unwrap().clone();
        c.iter().map(|v| v.unwrap()).collect()
    };
    // 0.5 s of ramp is 0.5 · 300 / 2π = 23.87 rev of the operating speed.
    let ramp = 0.5 * 300.0 / std::f64::consts::TAU;
    let tau = column("settling_horizon_revs")[0];
    assert!((tau - (100.0 - 50.0 - ramp)).abs() < 1e-9, "τ = {tau}");
    let settled = column("settled_fraction");
    assert!(
        settled.iter().any(|&f| f < 1.0),
        "no run was censored: {settled:?}"
    );
    for rmst in column("settling_revs_rmst") {
        assert!(
            (0.0..=tau + 1e-9).contains(&rmst),
            "RMST {rmst} beyond τ = {tau}"
        );
    }
    // The figures count on the same clock, and say so on their axes.
    let figures = tmp.path().join("figures");
    let plotted = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["plot", "study"])
        .arg(tmp.path().join("results/corpus"))
        .arg("--out")
        .arg(&figures)
        .output()
        .unwrap();
    assert_eq!(
        plotted.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&plotted.stderr)
    );
    for figure in ["settling_time.svg", "settling_vs_unbalance.svg"] {
        let svg = std::fs::read_to_string(figures.join(figure)).unwrap();
        assert!(
            svg.contains("revolutions after reaching the operating speed"),
            "{figure}"
        );
    }
}

/// The diagnosis' typed cause, as `summary.parquet` stores it, of the one
/// design that has one.
fn diagnosis_cause(summary: &Path) -> Option<String> {
    let df = read_parquet(summary).unwrap();
    df.column("diagnosis_cause")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .flatten()
        .next()
        .map(str::to_string)
}

/// Settled share of each design in a summary.
fn settled_fractions(summary: &Path) -> Vec<f64> {
    read_parquet(summary)
        .unwrap()
        .column("settled_fraction")
        .unwrap()
        .f64()
        .unwrap()
        .iter()
        .flatten()
        .collect()
}

/// A small optical-drive rotor with four light balls and little drag: the
/// symmetric fan of its balanced family is unstable, yet other positions of
/// the family are stable and the runs settle there within about 1 000 rev.
pub(crate) fn optical_drive(results: &Path, name: &str, t_end_revs: u32) -> String {
    format!(
        r#"name = "{name}"
output = "{}"
seed = 7
[scene]
start = "locked_steady"
[scene.rotor]
mass = 0.01
kx = 1800.0
ky = 1800.0
bx = 0.3
by = 0.3
[scene.speed]
mode = "constant"
omega = 754.0
[designs]
kind = "ball"
n = 4
rho = 0.067
race_radius = 0.015
density = 7850.0
drag = 3e-5
[sampling]
samples = 4
unbalance = {{ distribution = "uniform", min = 0.1, max = 0.9, relative_to = "capacity" }}
initial = "clustered"
[metrics]
hold_revs = 50
t_end_revs = {t_end_revs}
"#,
        results.display()
    )
}

/// A horizon too short is named as such, not as instability, when the
/// symmetric fan is unstable but other balanced positions are stable
/// (before, the diagnosis linearised at the fan alone and said "the
/// balanced state is linearly unstable"); raising the horizon as the
/// diagnosis says makes every run settle.
#[test]
fn a_short_horizon_is_not_called_instability_when_the_family_is_stable_elsewhere() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let out = run(tmp.path(), &optical_drive(&results, "short", 300), &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        diagnosis_cause(&results.join("short/summary.parquet")).as_deref(),
        Some("horizon_too_short"),
        "{stdout}"
    );
    assert!(
        stdout.contains("the symmetric fan is unstable, but"),
        "{stdout}"
    );
    let out = run(tmp.path(), &optical_drive(&results, "long", 3000), &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let settled = settled_fractions(&results.join("long/summary.parquet"));
    assert_eq!(settled, vec![1.0], "{stdout}");
}

/// The gravity test bounds the whirl the weights' swing leaves at twice the
/// speed, (g/(l ω²))/2 · C/U · |H(2ω)|/|H(ω)|, against δ: at 80 rad/s it is
/// below the band, the runs settle at a long horizon, and a short horizon is
/// named as the cause (before, g/(l ω²) = 0.048 ≥ δ·U/C = 0.031 named gravity).
#[test]
fn gravity_below_the_band_is_not_named_as_the_cause() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let study = |name: &str, t_end: u32| {
        format!(
            r#"name = "{name}"
output = "{}"
seed = 20261122
[scene]
start = "locked_steady"
[scene.rotor]
mass = 10.0
kx = 1.0e3
ky = 1.0e3
bx = 10.0
by = 10.0
[scene.speed]
mode = "constant"
omega = 80.0
[scene.effects.gravity]
g = 9.81
axis_inclination_deg = 0.0
[designs]
kind = "pendulum"
n = 3
rho = "optimal"
race_radius = 0.05
density = 7850.0
drag = 1.0
[sampling]
samples = 4
unbalance = {{ distribution = "uniform", min = 0.1, max = 0.9, relative_to = "capacity" }}
initial = "clustered"
[metrics]
hold_revs = 10
t_end_revs = {t_end}
"#,
            results.display()
        )
    };
    let out = run(tmp.path(), &study("short", 25), &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        diagnosis_cause(&results.join("short/summary.parquet")).as_deref(),
        Some("horizon_too_short"),
        "{stdout}"
    );
    let out = run(tmp.path(), &study("long", 300), &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        settled_fractions(&results.join("long/summary.parquet")),
        vec![1.0],
        "{stdout}"
    );
}

/// The typed decision agrees with the summary it was read from, on the
/// rules of docs/statistics.md: designs that balance rank first, #1 is
/// recommended with the Pareto set that contains it, and every design named
/// better than #1 on another measure is so by the one rule ([`favoured`]).
#[test]
fn the_decision_is_typed_and_follows_the_rules_on_a_many_design_study() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let text = drum_like(
        &results,
        "grid",
        r#"{ distribution = "uniform", min = 0.2, max = 0.9, relative_to = "capacity" }"#,
        "",
    )
    .replace("drag = [0.5, 2.0]", "drag = [0.5, 1.0, 2.0, 4.0]")
    .replace("samples = 4", "samples = 10");
    let out = run(tmp.path(), &text, &[]);
    assert_eq!(out.status.code(), Some(0));
    let summary = read_parquet(&results.join("grid/summary.parquet")).unwrap();
    let decision = StudyDecision::from_summary(&summary).unwrap();
    assert_eq!(decision.ranked.len(), 4);
    // Designs that balance come first.
    if let Some(k) = decision.ranked.iter().position(|d| !d.balances) {
        assert!(decision.ranked[k..].iter().all(|d| !d.balances));
    }
    let best = &decision.ranked[0];
    assert!(best.balances, "{decision:?}");
    assert_eq!(best.verdict, Some(StoredVerdict::Best));
    match &decision.recommendation {
        Recommendation::Build {
            design,
            pareto,
            part,
            ..
        } => {
            assert_eq!(*design, best.id);
            assert!(pareto.contains(design));
            assert!(
                part.as_deref().is_some_and(|p| p.contains("3 balls")),
                "{part:?}"
            );
        }
        other => panic!("{other:?}"),
    }
    match &decision.crown {
        Crown::Best {
            better_than,
            not_distinguishable,
            other_better,
            ..
        } => assert_eq!(
            better_than.len() + not_distinguishable.len() + other_better.len(),
            3
        ),
        other => panic!("{other:?}"),
    }
    // A restricted mean's difference is judged against the settled runs'
    // mean time of the two designs, every other against the larger value.
    let settled_mean = |id: u32| -> Option<f64> {
        let row = decision.ranked.iter().find(|r| r.id == id)?.row;
        summary
            .column("settling_revs_mean_settled")
            .unwrap()
            .f64()
            .unwrap()
            .get(row)
    };
    for d in &decision.disagreements {
        assert_ne!(d.measure, decision.criterion);
        let (a, b) = (d.values.0.unwrap_or(0.0), d.values.1.unwrap_or(0.0));
        let scale = match d.measure {
            Criterion::Mean => settled_mean(d.design)
                .into_iter()
                .chain(settled_mean(best.id))
                .reduce(f64::max)
                .unwrap_or(a.abs().max(b.abs())),
            _ => a.abs().max(b.abs()),
        };
        let difference = autobal::stats::paired_measures::Difference {
            a,
            b,
            scale,
            difference: d.difference,
            interval: (f64::NEG_INFINITY, f64::INFINITY),
            p_value: d.p_holm,
            test: "",
        };
        assert_eq!(
            favoured(d.measure, &difference, d.p_holm, decision.alpha),
            Some(Favours::A)
        );
    }
    assert_eq!(decision.leading(2)[0], best.id);
}

/// The default output in an engineer's terms: units in the settling
/// headers, ρ explained, the part to build in mm and g, the paired Δ named
/// as such, no "certified hold" or "touching angle" jargon, and stderr's
/// lines kept apart (before: "failures 0wrote results/…").
#[test]
fn the_ranking_speaks_in_an_engineers_terms() {
    let tmp = tempfile::tempdir().unwrap();
    let text = drum_like(
        &tmp.path().join("results"),
        "terms",
        r#"{ distribution = "uniform", min = 0.2, max = 0.9, relative_to = "capacity" }"#,
        "",
    );
    let path = tmp.path().join("study.toml");
    std::fs::write(&path, text).unwrap();
    // Not --quiet: the closing progress line is on stderr.
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", path.to_str().unwrap(), "--wide"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    let header: String = stdout.lines().take(2).collect::<Vec<_>>().join("\n");
    for unit in ["rev", "N·s/m", "µm", "%"] {
        assert!(header.contains(unit), "{unit}: {header}");
    }
    assert!(stdout.contains("ρ = r/R"), "{stdout}");
    assert!(
        stdout.contains("mm diameter,") && stdout.contains(" g each, in a race of radius 25 mm"),
        "{stdout}"
    );
    assert!(
        stdout.contains("angle at which two weights touch"),
        "{stdout}"
    );
    assert!(!stdout.contains("touching angle"), "{stdout}");
    assert!(!stderr.contains("certified hold"), "{stderr}");
    assert!(!stderr.contains("failures 0wrote"), "{stderr}");
    assert!(stderr.lines().any(|l| l.starts_with("wrote ")), "{stderr}");
    // --wide keeps the exact terms; the default (80 columns) says them in
    // words (the finished study reprints its ranking on --resume).
    assert!(
        stdout.contains("horizon τ = ")
            && stdout.contains("t_end − hold")
            && stdout.contains("(2α)"),
        "{stdout}"
    );
    let again = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", path.to_str().unwrap(), "--resume"])
        .output()
        .unwrap();
    assert_eq!(again.status.code(), Some(0));
    let default = String::from_utf8_lossy(&again.stdout).replace("\n  ", " ");
    assert!(
        default.contains("the run's length less its hold window (τ)"),
        "{default}"
    );
    for jargon in ["t_end − hold", "(2α)"] {
        assert!(!default.contains(jargon), "{jargon}: {default}");
    }
}

/// `study run --quiet --wide` in `dir` on the main job's rotor with balls
/// at ρ 0.25 (`designs`: the n and drag lines), 20 samples, ranked by the
/// restricted mean, runs of `t_end_revs`.
fn run_main_rotor(dir: &Path, designs: &str, t_end_revs: u32) -> Output {
    let text = format!(
        r#"name = "main_rotor"
seed = 5
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
rho = 0.25
race_radius = 0.05
{designs}
[sampling]
samples = 20
unbalance = {{ distribution = "uniform", min = 0.1, max = 0.9, relative_to = "capacity" }}
[summary]
rank_by = "mean"
[metrics]
t_end_revs = {t_end_revs}
"#,
        dir.join("results").display()
    );
    let study = dir.join("study.toml");
    std::fs::write(&study, text).unwrap();
    Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", study.to_str().unwrap(), "--quiet", "--wide"])
        .output()
        .unwrap()
}

/// A design none of whose runs settled has a restricted mean equal to the
/// horizon τ: the ranking prints it as a bound ("≥ τ, none settled"), not
/// as an interval of zero width ("50.0 [50.0, 50.0]") that reads as precision.
#[test]
fn a_design_that_never_settles_prints_a_bound_not_a_zero_width_interval() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_main_rotor(dir.path(), "n = 3\ndrag = [10.0, 1000.0]", 100);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("≥ 50.0, none settled"), "{stdout}");
    // The residual the findings compare is named as relative to A_ref.
    assert!(
        stdout.contains(
            "p90 and residual p95/A_ref (the residual relative to each run's A_ref, not in µm)"
        ),
        "{stdout}"
    );
    // The contact line names how contact was modelled.
    assert!(
        stdout.contains("contact between the weights: on (rigid contact)"),
        "{stdout}"
    );
    assert!(!stdout.contains("[50.0, 50.0]"), "{stdout}");
}

/// A two-plane rotor with one design in both planes (the shipped drum, three
/// samples a design): the recommendation says the part goes in each plane,
/// and the summary records how many planes the rotor carries.
#[test]
fn one_design_in_two_planes_is_recommended_for_each_plane() {
    let dir = tempfile::tempdir().unwrap();
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("studies/drum.toml"))
            .unwrap();
    let text: String = text
        .lines()
        .map(|l| {
            if l.starts_with("samples = ") {
                "samples = 3"
            } else {
                l
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let study = dir.path().join("drum.toml");
    std::fs::write(&study, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .current_dir(dir.path())
        .args(["run", "drum.toml", "--quiet", "--wide"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("per weight, in each of 2 planes"),
        "{stdout}"
    );
    let summary = read_parquet(&dir.path().join("results/drum/summary.parquet")).unwrap();
    let planes: Vec<Option<u32>> = summary
        .column("balancer_planes")
        .unwrap()
        .u32()
        .unwrap()
        .iter()
        .collect();
    assert!(planes.iter().all(|p| *p == Some(2)), "{planes:?}");
}

/// A raced study says that the designs that left rest on fewer runs, their
/// flags included, and that the ranks below #1 are not the full study's.
#[test]
fn a_raced_ranking_says_its_lower_ranks_rest_on_fewer_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_main_rotor(dir.path(), "n = [2, 3]\ndrag = [10.0, 300.0]", 400);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("left the race after that many samples"),
        "{stdout}"
    );
    assert!(
        stdout.contains("its flags (balances, the shortfalls)")
            && stdout.contains("the ranks below #1 are not those the full study would give"),
        "{stdout}"
    );
}

/// A two-plane grinder on soft supports, 3 or 4 balls per plane, with
/// rolling resistance and a race `offset` (m): each plane settles into its
/// own band δ·A_ref of the plane, far narrower than the rotor's where the
/// couple and the static part nearly cancel.
fn two_plane_grinder(results: &Path, name: &str, offset: f64) -> String {
    format!(
        r#"name = "{name}"
output = "{}"
seed = 7
[scene.rotor]
model = "two_support"
mass = 2.0
transverse_inertia = 0.01
polar_inertia = 0.003
k1 = 2.0e4
l1 = 0.06
k2 = 2.0e4
l2 = 0.06
b1 = 30.0
b2 = 30.0
planes = [-0.05, 0.05]
[scene.speed]
mode = "constant"
omega = 700.0
[scene.effects.race_eccentricity]
offset = {offset:e}
[scene.effects.rolling_resistance]
coefficient = 5e-5
[designs]
kind = "ball"
n = [3, 4]
rho = 0.15
race_radius = 0.04
density = 7850.0
drag = 0.05
[sampling]
samples = 6
unbalance = {{ distribution = "uniform", min = 0.1, max = 0.5, relative_to = "capacity" }}
[sampling.couple]
unbalance = {{ distribution = "uniform", min = 0.05, max = 0.3, relative_to = "capacity" }}
phase = "uniform"
[metrics]
t_end_revs = 400
hold_revs = 50
"#,
        results.display()
    )
}

/// A race eccentricity between plane 0's own band and the rotor's: the
/// runs it stops name the plane (the rotor's r/A_ref is inside its band),
/// the caution names the floor, and the dead band is compared plane by
/// plane (before, every comparison used the whole rotor's band).
#[test]
fn a_floor_above_one_planes_band_is_named_per_plane() {
    let tmp = tempfile::tempdir().unwrap();
    let text = two_plane_grinder(&tmp.path().join("results"), "grinder", 5e-6);
    let out = run(tmp.path(), &text, &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    let runs = read_parquet(&tmp.path().join("results/grinder/runs.parquet")).unwrap();
    let reasons: Vec<String> = runs
        .column("reason")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .flatten()
        .filter(|r| r.starts_with("censored"))
        .map(str::to_string)
        .collect();
    assert!(!reasons.is_empty(), "{stdout}");
    for r in &reasons {
        assert!(
            r.starts_with("censored: plane 0 whirls") && r.contains("the whole rotor's r/A_ref"),
            "{r}"
        );
    }
    assert!(
        stdout.contains("with a caution: it settles in only")
            && stdout.contains("runs that did not settle have plane 0's own settling band δ·A_ref")
            && stdout.contains(
                "at or below a whirl no balancer removes, 5.000 µm: the race eccentricity"
            ),
        "{stdout}"
    );
    assert!(
        stdout.contains("against each plane's own settling band")
            && stdout.contains("plane 0 1.70 µm vs")
            && stdout.contains("plane 1 1.70 µm vs"),
        "{stdout}"
    );
}

/// Where no design works, the diagnosis compares the floor with each
/// plane's own band (median A_ref of the plane) and names the plane.
#[test]
fn a_floor_that_stops_every_design_is_diagnosed_against_the_planes_band() {
    let tmp = tempfile::tempdir().unwrap();
    let text = two_plane_grinder(&tmp.path().join("results"), "floor", 1.3e-5);
    let out = run(tmp.path(), &text, &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("verdict: no design balances this rotor")
            && stdout.contains("e_r = 13.000 µm, as large as plane 0's own settling band δ·A_ref"),
        "{stdout}"
    );
    assert_eq!(
        diagnosis_cause(&tmp.path().join("results/floor/summary.parquet")).as_deref(),
        Some("whirl_floor")
    );
}

/// Subset selection with a declared tie-break: the study of eight designs
/// (studies/tied_designs.toml), run under five seeds, names as its part the
/// lightest design of its indistinguishable set every time, and so the same
/// part whenever the set contains the same lightest design; #1 by the point
/// estimate changes with the seed, which is why it is not the part.
#[test]
fn the_part_does_not_change_with_the_seed_when_designs_tie() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let study = std::fs::read_to_string(root.join("studies/tied_designs.toml")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let (mut picks, mut firsts, mut ties) = (Vec::new(), Vec::new(), 0);
    for seed in 1..=5 {
        let head = format!(
            "seed = {seed}\nname = \"tied_designs\"\noutput = {:?}\n",
            results.display().to_string()
        );
        let out = run(
            tmp.path(),
            &study.replace("seed = 1\n", &head),
            &["--overwrite"],
        );
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stdout = String::from_utf8_lossy(&out.stdout).to_string();
        let summary = read_parquet(&results.join("tied_designs/summary.parquet")).unwrap();
        let decision = StudyDecision::from_summary(&summary).unwrap();
        let Recommendation::Build {
            design,
            first,
            indistinguishable,
            unsettled_risk,
            ..
        } = &decision.recommendation
        else {
            panic!("{:?}", decision.recommendation);
        };
        // Every weight of the design: n × one weight's mass.
        let mass = |id: u32| {
            let row = decision.ranked.iter().find(|d| d.id == id).unwrap().row;
            let n = summary
                .column("n")
                .unwrap()
                .u32()
                .unwrap()
                .get(row)
                .unwrap();
            let m = summary.column("weight_mass").unwrap().f64().unwrap();
            f64::from(n) * m.get(row).unwrap()
        };
        let lightest = |ids: &mut dyn Iterator<Item = u32>| {
            ids.min_by(|&a, &b| mass(a).total_cmp(&mass(b)).then(a.cmp(&b)))
                .unwrap()
        };
        assert_eq!(
            *design,
            lightest(&mut indistinguishable.iter().copied()),
            "seed {seed}: {decision:?}"
        );
        let (unsettled, runs, upper) = unsettled_risk.unwrap();
        assert!(
            runs == 24 && upper > unsettled as f64 / runs as f64,
            "{unsettled_risk:?}"
        );
        assert!(stdout.contains("risk of not settling at most"), "{stdout}");
        if indistinguishable.len() > 1 {
            ties += 1;
            assert!(
                stdout.contains("part by least mass: design"),
                "seed {seed}: {stdout}"
            );
        }
        let all = lightest(&mut decision.ranked.iter().map(|d| d.id));
        picks.push((*design, indistinguishable.contains(&all), all));
        firsts.push(*first);
    }
    // The designs tie under most seeds, or the test says nothing.
    assert!(ties >= 3, "designs tied under only {ties} of 5 seeds");
    assert!(
        picks.iter().filter(|p| p.1).all(|p| p.0 == p.2),
        "{picks:?}"
    );
    // #1 by the point estimate is not the same under every seed: the
    // question the tie-break answers is a real one here.
    assert!(firsts.iter().any(|&f| f != firsts[0]), "{firsts:?}");
}

/// Weights that circulate are counted, named and never called balancing:
/// on studies/washer_circulating.toml the thinnest oil's pack runs about
/// 100 rad/s behind the drum, several times worse than no balancer. The
/// summary's `circulating_runs` are the runs.parquet rows that did not
/// settle and slipped ≥ 10 % of the rotor's speed; the ranking names them
/// with how much worse than none they ended; and a design whose share
/// worse than none is significantly above 5 % (its Wilson interval's lower
/// end) does not balance.
#[test]
fn weights_that_circulate_are_counted_and_never_called_balancing() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let study = std::fs::read_to_string(root.join("studies/washer_circulating.toml")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let head = format!(
        "name = \"washer\"\noutput = {:?}\nseed =",
        results.display().to_string()
    );
    let out = run(tmp.path(), &study.replacen("seed =", &head, 1), &[]);
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert_eq!(out.status.code(), Some(0), "{stdout}");
    let summary = read_parquet(&results.join("washer/summary.parquet")).unwrap();
    let runs = read_parquet(&results.join("washer/runs.parquet")).unwrap();
    let ids = summary.column("design_id").unwrap().u32().unwrap().clone();
    let counted = summary
        .column("circulating_runs")
        .unwrap()
        .u64()
        .unwrap()
        .clone();
    let balances = summary.column("balances").unwrap().bool().unwrap().clone();
    let lo = summary
        .column("worse_than_none_lo")
        .unwrap()
        .f64()
        .unwrap()
        .clone();
    let (design, settled) = (
        runs.column("design_id").unwrap().u32().unwrap().clone(),
        runs.column("settled").unwrap().bool().unwrap().clone(),
    );
    let slip = runs
        .column("pack_slip_rate")
        .unwrap()
        .f64()
        .unwrap()
        .clone();
    let spin = runs
        .column("final_spin_rate")
        .unwrap()
        .f64()
        .unwrap()
        .clone();
    let mut any = false;
    for row in 0..summary.height() {
        let id = ids.get(row).unwrap();
        let recomputed = (0..runs.height())
            .filter(|&i| design.get(i) == Some(id) && settled.get(i) == Some(false))
            .filter(|&i| slip.get(i).unwrap().abs() >= 0.1 * spin.get(i).unwrap().abs())
            .count() as u64;
        assert_eq!(counted.get(row), Some(recomputed), "design {id}");
        if recomputed > 0 {
            any = true;
            let named = format!("design {id}: weights circulate in {recomputed} of ");
            assert!(stdout.contains(&named), "{named} missing: {stdout}");
        }
        if lo.get(row).unwrap() > 0.05 {
            assert_eq!(balances.get(row), Some(false), "design {id}");
        }
    }
    assert!(any, "no pack circulated: {stdout}");
    assert!(stdout.contains("× worse than no balancer"), "{stdout}");
}
