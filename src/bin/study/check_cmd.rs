//! `study check` and `study baseline`: statistical regression checks of a
//! study against its committed baseline.

use crate::UserError;
use crate::output::{dropped_note, fitted_table, text_width, wrap};
use autobal::check::baseline::default_dir;
use autobal::check::compare::{CheckReport, DEFAULT_ALPHA, Metric};
use autobal::check::study::{CheckError, CheckOptions, check_study, record_baseline};
use autobal::study::plan::config::load;
use autobal::study::run::{NoProgress, RunOptions};
use clap::Args;
use std::path::PathBuf;

/// Examples shown under `study check --help`.
pub const CHECK_EXAMPLES: &str =
    "Exit codes: 0 no regression; 1 regression detected (a significant change in
either direction); 2 bad input (no baseline, a baseline of another study, …);
3 internal failure (e.g. the fresh run could not be written).

Examples:
  study check studies/regression.toml --baseline results/baselines/regression/
  study check studies/regression.toml --seed 7           independent inputs: tests the noise model
  study check studies/regression.toml --runs results/regression/runs.parquet
  study check studies/regression.toml --json > verdicts.json";

/// Examples shown under `study baseline --help`.
pub const BASELINE_EXAMPLES: &str = "Examples:
  study baseline studies/regression.toml     writes results/baselines/regression/
  study baseline studies/regression.toml --out /tmp/baseline";

/// Arguments of `study check`.
#[derive(Args)]
pub struct CheckArgs {
    /// Study file (TOML); must be the very text the baseline was written from.
    study: PathBuf,
    /// Baseline folder written by `study baseline` (default: <output>/baselines/<name>/).
    #[arg(long)]
    baseline: Option<PathBuf>,
    /// Seed of the fresh run (default: the study's own, i.e. the baseline's inputs;
    /// another seed draws independent inputs and tests the noise model).
    #[arg(long, conflicts_with = "runs")]
    seed: Option<u64>,
    /// Compare this finished runs.parquet of the study instead of running it.
    #[arg(long)]
    runs: Option<PathBuf>,
    /// Family-wise false-alarm level (Holm-corrected over every design and metric).
    #[arg(long, default_value_t = DEFAULT_ALPHA, value_parser = crate::limits::alpha)]
    alpha: f64,
    /// Root folder of the fresh run (default: <output>/check).
    #[arg(long, conflicts_with = "runs")]
    out: Option<PathBuf>,
    /// Worker threads (default: all cores, or RAYON_NUM_THREADS).
    #[arg(long, value_parser = crate::limits::threads)]
    threads: Option<usize>,
    /// Print the verdict table as JSON.
    #[arg(long)]
    json: bool,
}

/// Arguments of `study baseline`.
#[derive(Args)]
pub struct BaselineArgs {
    /// Study file (TOML).
    study: PathBuf,
    /// Baseline folder (default: <output>/baselines/<name>/); an existing baseline there is replaced only with --overwrite.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace the baseline already in the folder.
    #[arg(long)]
    overwrite: bool,
    /// Worker threads (default: all cores, or RAYON_NUM_THREADS).
    #[arg(long, value_parser = crate::limits::threads)]
    threads: Option<usize>,
}

/// Exit code of an internal failure of `study check`: 1 is reserved for "regression detected".
const CHECK_INTERNAL: u8 = 3;

fn exit_code(e: CheckError, internal: u8) -> UserError {
    if e.is_user_error() {
        UserError(e.to_string(), 2)
    } else {
        UserError(e.to_string(), internal)
    }
}

/// Run `study baseline`.
pub fn baseline(args: &BaselineArgs) -> Result<(), UserError> {
    if let Some(out) = &args.out {
        autobal::output_file::prepare_folder("--out", out)?;
    }
    let plan = load(&args.study)?;
    let dir = args.out.clone().unwrap_or_else(|| default_dir(&plan));
    let run = RunOptions {
        threads: crate::limits::capped_threads(args.threads),
        overwrite: args.overwrite,
        ..RunOptions::default()
    };
    let manifest = record_baseline(&plan, &dir, &run, &NoProgress).map_err(|e| exit_code(e, 1))?;
    crate::output::say(&format!(
        "baseline of {} written to {}: {} designs × {} runs, seed {}, study sha256 {}",
        manifest.study_name,
        dir.display(),
        manifest.designs,
        manifest.samples,
        manifest.seed,
        &manifest.study_sha256[..12]
    ));
    Ok(())
}

/// Run `study check`.
pub fn check(args: &CheckArgs) -> Result<(), UserError> {
    if let Some(out) = &args.out {
        autobal::output_file::prepare_folder("--out", out)?;
    }
    let plan = load(&args.study)?;
    let dir = args.baseline.clone().unwrap_or_else(|| default_dir(&plan));
    let options = CheckOptions {
        seed: args.seed,
        alpha: args.alpha,
        runs: args.runs.clone(),
        output_root: args.out.clone(),
        run: RunOptions {
            threads: crate::limits::capped_threads(args.threads),
            ..RunOptions::default()
        },
    };
    let outcome = check_study(&plan, &dir, &options, &NoProgress).map_err(|e| {
        // A given baseline or runs file is named by the flag it came with.
        let flag = match &e {
            CheckError::Baseline(_) if args.baseline.is_some() => "--baseline ",
            CheckError::BadRuns { .. } if args.runs.is_some() => "--runs ",
            _ => "",
        };
        let UserError(message, code) = exit_code(e, CHECK_INTERNAL);
        UserError(format!("{flag}{message}"), code)
    })?;
    let report = &outcome.report;
    if args.json {
        println!("{}", serde_json::to_string_pretty(report)?);
    } else {
        print!("{}", verdict_table(report));
        let inputs = if outcome.seed == outcome.baseline.seed {
            "same seed as the baseline: same random inputs"
        } else {
            "another seed than the baseline: independent inputs"
        };
        crate::output::say(&format!(
            "{} hypotheses, Holm-corrected at family-wise α = {}; seed {} ({inputs}){}",
            report.tested,
            report.alpha,
            outcome.seed,
            if report.identical {
                "; the results reproduce the baseline exactly"
            } else {
                ""
            }
        ));
        crate::output::say(&format!(
            "baseline: {} (autobal {}, commit {}); compared: {}",
            dir.display(),
            outcome.baseline.autobal_version,
            short(&outcome.baseline.git_commit),
            outcome.runs_file.display()
        ));
    }
    if report.passed() {
        if !args.json {
            crate::output::say("verdict: pass");
        }
        Ok(())
    } else {
        Err(UserError(
            format!(
                "regression detected: {} of {} tests changed significantly (see the REGRESSION rows)",
                report.regressions(),
                report.tested
            ),
            1,
        ))
    }
}

fn short(commit: &str) -> &str {
    &commit[..commit.len().min(12)]
}

/// The verdict table: design, metric, baseline, now, effect, p, Holm p, verdict.
fn verdict_table(report: &CheckReport) -> String {
    let value = |metric: Metric, v: Option<f64>| match (metric, v) {
        (_, None) => "–".to_string(),
        (Metric::SettlingTime | Metric::PlaneSettlingTime(_), Some(x)) => format!("{x:.1}"),
        (Metric::SettledFraction | Metric::PlaneSettledFraction(_), Some(x)) => format!("{x:.3}"),
        (Metric::ResidualMedian, Some(x)) => format!("{x:.3e}"),
    };
    let p = |v: Option<f64>| match v {
        None => "–".to_string(),
        Some(x) if x >= 1e-3 => format!("{x:.3}"),
        Some(x) => format!("{x:.1e}"),
    };
    let rows: Vec<Vec<String>> = report
        .rows
        .iter()
        .map(|r| {
            let effect = match (r.metric, r.effect) {
                (_, None) => "–".to_string(),
                (Metric::SettledFraction | Metric::PlaneSettledFraction(_), Some(e)) => {
                    format!("{:+.1} pp", 100.0 * e)
                }
                (_, Some(e)) => format!("{:+.1} %", 100.0 * e),
            };
            let effect = match r.statistic {
                Some(d) => format!("{effect} (D={d:.2})"),
                None => effect,
            };
            vec![
                r.design_id.to_string(),
                r.design.clone(),
                r.metric.name().to_string(),
                r.metric.test().to_string(),
                format!("{}/{}", r.sizes.0, r.sizes.1),
                value(r.metric, r.baseline),
                value(r.metric, r.now),
                effect,
                p(r.p_value),
                p(r.p_holm),
                r.verdict.name().to_string(),
            ]
        })
        .collect();
    // The metric, its Holm-adjusted p and the verdict stay at any width.
    let (table, dropped) = fitted_table(
        &[
            "id",
            "design",
            "metric",
            "test",
            "n\nbase/now",
            "baseline",
            "now",
            "effect",
            "p",
            "p\n(Holm)",
            "verdict",
        ],
        &rows,
        &[0, 2, 0, 4, 5, 3, 3, 2, 6, 0, 0],
        text_width(),
    );
    let dropped_note = dropped_note(&dropped);
    table
        + &wrap(
            &format!(
                "{dropped_note}(settling_revs: median settling time in revolutions of settled runs; residual_rel: median RMS vibration / A_ref; effect: relative change of the median, or of the fraction in percentage points; D: KS statistic)\n"
            ),
            text_width(),
        )
}
