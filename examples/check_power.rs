//! Detection power of `study check` on a study: plant drag changes of a few
//! per cent and count how often the check flags them, with the baseline's
//! own seed (paired inputs, the default) and with another seed (independent
//! inputs); drift 0 with another seed measures the false-alarm rate.
//!
//! cargo run --example check_power -- studies/regression.toml --seeds 5 --drifts 0,1,2,5,10
//!
//! `--verbose` lists every flagged row on stderr.
//!
//! Each study run is written to a temporary folder; nothing under results/ changes.

use autobal::check::compare::{CheckReport, DEFAULT_ALPHA, Metric, Verdict, compare};
use autobal::check::samples::{DesignSample, design_samples};
use autobal::study::plan::config::{OneOrMany, StudyPlan, load};
use autobal::study::results::record::to_dataframe;
use autobal::study::run::{NoProgress, RunOptions, run_study};
use std::path::PathBuf;

/// Seeds of the independent runs are offset by this from the baseline's.
const INDEPENDENT_OFFSET: u64 = 1_000_003;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut study = PathBuf::from("studies/regression.toml");
    let mut seeds = 5_u64;
    let mut drifts = vec![0.0, 1.0, 2.0, 5.0, 10.0];
    let mut verbose = false;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seeds" => seeds = args.next().ok_or("--seeds N")?.parse()?,
            "--drifts" => {
                drifts = args
                    .next()
                    .ok_or("--drifts a,b,c (per cent)")?
                    .split(',')
                    .map(str::parse)
                    .collect::<Result<_, _>>()?
            }
            "--verbose" => verbose = true,
            other => study = PathBuf::from(other),
        }
    }
    let plan = load(&study)?;
    let scratch = tempfile::tempdir()?;
    let run = |drift: f64, seed: u64| -> Result<Vec<DesignSample>, Box<dyn std::error::Error>> {
        let mut file = plan.file.clone();
        file.seed = seed;
        file.output = scratch.path().display().to_string();
        let drags = file.designs.drag.values();
        file.designs.drag =
            OneOrMany::Many(drags.iter().map(|d| d * (1.0 + drift / 100.0)).collect());
        // The study text stays the original: a planted change is a change of the code, not of the file.
        let p: StudyPlan = file.plan(&plan.text, &study.display().to_string())?;
        // Every seed and drift reuses one scratch folder.
        let replace = RunOptions {
            overwrite: true,
            ..RunOptions::default()
        };
        let out = run_study(&p, &replace, &NoProgress)?;
        Ok(design_samples(&to_dataframe(&out.load_runs()?)?)?)
    };
    println!(
        "{}: {} designs × {} runs, Holm at α = {DEFAULT_ALPHA}, {seeds} baseline seeds from {}",
        study.display(),
        plan.designs.len(),
        plan.file.sampling.samples,
        plan.file.seed
    );
    println!(
        "{:>8}  {:>16}  {:>18}  {:>16}  {:>28}",
        "drift β",
        "paired detected",
        "independent det.",
        "designs flagged",
        "median t_s shift, range"
    );
    let baselines: Vec<Vec<DesignSample>> = (0..seeds)
        .map(|k| run(0.0, plan.file.seed + k))
        .collect::<Result<_, _>>()?;
    for &drift in &drifts {
        let (mut paired, mut independent, mut flagged, mut shifts) = (0, 0, 0, Vec::new());
        for (k, base) in baselines.iter().enumerate() {
            let seed = plan.file.seed + k as u64;
            let same = if drift == 0.0 {
                base.clone()
            } else {
                run(drift, seed)?
            };
            let report = compare(base, &same, DEFAULT_ALPHA)?;
            paired += usize::from(!report.passed());
            flagged += flagged_designs(&report);
            shifts.extend(settling_shifts(&report));
            let other = run(drift, seed + INDEPENDENT_OFFSET)?;
            let other = compare(base, &other, DEFAULT_ALPHA)?;
            independent += usize::from(!other.passed());
            if verbose {
                for (mode, r) in [("paired", &report), ("independent", &other)] {
                    for row in r.rows.iter().filter(|r| r.verdict == Verdict::Regression) {
                        eprintln!(
                            "  drift {drift}% seed {seed} {mode}: {} {} effect {:+.4} D {:.3} p_holm {:.1e}",
                            row.design,
                            row.metric.name(),
                            row.effect.unwrap_or(f64::NAN),
                            row.statistic.unwrap_or(f64::NAN),
                            row.p_holm.unwrap_or(f64::NAN)
                        );
                    }
                }
            }
        }
        shifts.sort_by(f64::total_cmp);
        let range = match (shifts.first(), shifts.last()) {
            (Some(lo), Some(hi)) => format!("{:+.1} … {:+.1} %", 100.0 * lo, 100.0 * hi),
            _ => "–".into(),
        };
        println!(
            "{:>7}%  {:>16}  {:>18}  {:>16}  {:>28}",
            drift,
            format!("{paired}/{seeds}"),
            format!("{independent}/{seeds}"),
            format!("{:.1}", flagged as f64 / seeds as f64),
            range
        );
    }
    Ok(())
}

/// Designs with at least one regression row.
fn flagged_designs(report: &CheckReport) -> usize {
    let mut ids: Vec<u32> = report
        .rows
        .iter()
        .filter(|r| r.verdict == Verdict::Regression)
        .map(|r| r.design_id)
        .collect();
    ids.dedup();
    ids.len()
}

/// Relative changes of the median settling time, one per design.
fn settling_shifts(report: &CheckReport) -> Vec<f64> {
    report
        .rows
        .iter()
        .filter(|r| r.metric == Metric::SettlingTime)
        .filter_map(|r| r.effect)
        .collect()
}
