//! False-alarm rate and power of `study check`, measured by simulation: the
//! study is run with `--seeds` different seeds, and every run is checked
//! against every other (independent inputs) and against itself (the default,
//! same-seed mode), with changes planted into the second: settling times
//! 0.5 to 10 % longer, and 1 to 10 percentage points fewer settled runs
//! (`autobal::check::plant`).
//!
//! cargo run --example check_error_rate -- studies/regression.toml --seeds 40
//!
//! Each study run is written to a temporary folder; nothing under results/ changes.

use autobal::check::compare::DEFAULT_ALPHA;
use autobal::check::plant::{AlarmCount, Planted, alarms_independent, alarms_paired};
use autobal::check::samples::{DesignSample, design_samples};
use autobal::decide::verdict::settling_horizon;
use autobal::stats::interval::wilson_interval;
use autobal::study::plan::config::load;
use autobal::study::results::io::read_parquet;
use autobal::study::run::{NoProgress, RunOptions, run_study};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut study = PathBuf::from("studies/regression.toml");
    let mut seeds = 20_u64;
    let mut alpha = DEFAULT_ALPHA;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seeds" => seeds = args.next().ok_or("--seeds N")?.parse()?,
            "--alpha" => alpha = args.next().ok_or("--alpha A")?.parse()?,
            other => study = PathBuf::from(other),
        }
    }
    let plan = load(&study)?;
    let horizon = settling_horizon(&plan);
    let scratch = tempfile::tempdir()?;
    let clock = std::time::Instant::now();
    let runs: Vec<Vec<DesignSample>> = (0..seeds)
        .map(|k| -> Result<_, Box<dyn std::error::Error>> {
            let mut file = plan.file.clone();
            file.seed = plan.file.seed + k;
            file.output = scratch.path().display().to_string();
            let p = file.plan(&plan.text, &study.display().to_string())?;
            let replace = RunOptions {
                overwrite: true,
                ..RunOptions::default()
            };
            let out = run_study(&p, &replace, &NoProgress)?;
            Ok(design_samples(&read_parquet(
                &out.dir.join("runs.parquet"),
            )?)?)
        })
        .collect::<Result<_, _>>()?;
    println!(
        "{}: {} designs × {} runs, {seeds} seeds from {} ({:.0} s), Holm at α = {alpha}",
        study.display(),
        plan.designs.len(),
        plan.file.sampling.samples,
        plan.file.seed,
        clock.elapsed().as_secs_f64()
    );
    println!(
        "| planted change | alarms, same seed | alarms, another seed | rate, another seed [95 % CI, {} replicates] |",
        seeds / 2
    );
    println!("| --- | ---: | ---: | ---: |");
    let changes = [
        Planted::Nothing,
        Planted::SettlingTime(0.005),
        Planted::SettlingTime(0.01),
        Planted::SettlingTime(0.02),
        Planted::SettlingTime(0.05),
        Planted::SettlingTime(0.10),
        Planted::SettledFraction(0.01),
        Planted::SettledFraction(0.02),
        Planted::SettledFraction(0.05),
        Planted::SettledFraction(0.10),
    ];
    for change in changes {
        let paired = alarms_paired(&runs, change, horizon, alpha)?;
        let other = alarms_independent(&runs, change, horizon, alpha)?;
        // The pairs share studies: count only as many replicates as
        // disjoint pairs there are, scaling the alarms to match.
        let replicates = seeds / 2;
        let (lo, hi) = wilson_interval(
            (other.rate() * replicates as f64).round() as u64,
            replicates,
        );
        println!(
            "| {} | {} | {} | {:.3} [{:.2}, {:.2}] |",
            change.label(),
            fraction(paired),
            fraction(other),
            other.rate(),
            lo,
            hi
        );
    }
    Ok(())
}

/// "a/b".
fn fraction(c: AlarmCount) -> String {
    format!("{}/{}", c.alarms, c.checks)
}
