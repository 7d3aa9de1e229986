//! `study run` and `study merge`: the Monte Carlo study runner.

use crate::UserError;
use crate::output::text_table;
use autobal::metrics::Outcome;
use autobal::study::config::load;
use autobal::study::merge::merge;
use autobal::study::record::RunRecord;
use autobal::study::run::{Progress, RunError, RunOptions, Shard, run_study};
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use polars::prelude::DataFrame;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::sync::atomic::{AtomicU64, Ordering};

/// Examples shown under `study run --help`.
pub const RUN_EXAMPLES: &str = "Examples:
  study run studies/three_balls.toml
  study run studies/three_balls.toml --resume        continue an interrupted run
  study run studies/three_balls.toml --overwrite     replace the previous results
  study run studies/balls_vs_rollers.toml --shard 2/8 one of eight disjoint slices
  RAYON_NUM_THREADS=1 study run studies/three_balls.toml --quiet";

/// Examples shown under `study merge --help`.
pub const MERGE_EXAMPLES: &str = "Examples:
  study merge results/balls_vs_rollers/shard-*-of-8";

/// Arguments of `study run`.
#[derive(Args)]
pub struct RunArgs {
    /// Study file (TOML).
    study: PathBuf,
    /// Continue an interrupted run; fails if the study file (or the autobal build) changed since.
    #[arg(long)]
    resume: bool,
    /// Replace results already in the output folder (a run over existing results is refused otherwise).
    #[arg(long, conflicts_with = "resume")]
    overwrite: bool,
    /// Run only the k-th of N disjoint slices, e.g. 2/8 (merge them with `study merge`).
    #[arg(long, value_parser = Shard::parse)]
    shard: Option<Shard>,
    /// Worker threads (default: all cores, or RAYON_NUM_THREADS).
    #[arg(long)]
    threads: Option<usize>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// Write finished runs to disk after this many, or every 2 s, whichever comes first.
    #[arg(long, default_value_t = 4096)]
    chunk_runs: usize,
}

/// Arguments of `study merge`.
#[derive(Args)]
pub struct MergeArgs {
    /// Shard folders written by `study run --shard k/N`.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Output folder (default: the shards' parent folder).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace merged results already in the output folder.
    #[arg(long)]
    overwrite: bool,
}

/// indicatif progress bar on stderr: runs done, rate, ETA, failures so far.
struct Bar {
    bar: ProgressBar,
    failures: AtomicU64,
}

impl Bar {
    fn new(quiet: bool) -> Self {
        let bar = ProgressBar::with_draw_target(
            None,
            if quiet {
                ProgressDrawTarget::hidden()
            } else {
                ProgressDrawTarget::stderr()
            },
        );
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {per_sec}  ETA {eta}  {msg}")
                .expect("valid template"),
        );
        Bar {
            bar,
            failures: AtomicU64::new(0),
        }
    }
}

impl Progress for Bar {
    fn begin(&self, total: u64, done: u64) {
        self.bar.set_length(total);
        self.bar.set_position(done);
        self.bar.set_message("failures 0");
    }
    fn advance(&self, record: &RunRecord) {
        if matches!(
            record.metrics.outcome,
            Outcome::Diverged | Outcome::SolverFailed | Outcome::BudgetExceeded
        ) {
            let f = self.failures.fetch_add(1, Ordering::Relaxed) + 1;
            self.bar.set_message(format!("failures {f}"));
        }
        self.bar.inc(1);
    }
    fn end(&self) {
        self.bar.finish_and_clear();
    }
}

/// Run `study run`.
pub fn run(args: &RunArgs) -> Result<(), UserError> {
    let threads = match args.threads {
        Some(0) => {
            return Err(UserError(
                "--threads 0: a study needs at least one worker thread".into(),
                2,
            ));
        }
        Some(asked) => {
            let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
            if asked > cores {
                eprintln!(
                    "warning: --threads {asked} is more than the {cores} logical cores here; using {cores}"
                );
            }
            Some(asked.min(cores))
        }
        None => None,
    };
    if args.chunk_runs == 0 {
        return Err(UserError(
            "--chunk-runs 0: a chunk holds at least one run".into(),
            2,
        ));
    }
    let plan = load(&args.study)?;
    // Ctrl-C (or a batch system's SIGTERM) asks the run to stop and save
    // what it has; a second one ends the process at once.
    let cancel = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(signal, 130, Arc::clone(&cancel))
            .and_then(|_| signal_hook::flag::register(signal, Arc::clone(&cancel)))
            .map_err(|e| UserError::internal(format!("cannot watch for Ctrl-C: {e}")))?;
    }
    let options = RunOptions {
        cancel: Some(cancel),
        resume: args.resume,
        overwrite: args.overwrite,
        chunk_runs: args.chunk_runs,
        shard: args.shard,
        threads,
        ..RunOptions::default()
    };
    let bar = Bar::new(args.quiet);
    let output = run_study(&plan, &options, &bar).map_err(|e| {
        if matches!(e, RunError::Interrupted { .. }) {
            UserError(e.to_string(), 130)
        } else if e.is_user_error() {
            UserError(e.to_string(), 2)
        } else {
            UserError::internal(e.to_string())
        }
    })?;
    match &output.summary {
        Some(summary) => print!("{}", ranked_table(summary)?),
        None => println!(
            "shard {} done: {} runs in {} (merge the shards with `study merge`)",
            args.shard.map(|s| s.label()).unwrap_or_default(),
            output.runs,
            output.dir.display()
        ),
    }
    eprintln!("wrote {}", output.dir.display());
    Ok(())
}

/// Run `study merge`.
pub fn merge_shards(args: &MergeArgs) -> Result<(), UserError> {
    let output = merge(&args.dirs, args.out.as_deref(), args.overwrite)?;
    if let Some(summary) = &output.summary {
        print!("{}", ranked_table(summary)?);
    }
    eprintln!("merged {} runs into {}", output.runs, output.dir.display());
    Ok(())
}

/// Designs ranked by the median settling time over all their runs, a run
/// that did not settle counting as later than every settled one (designs
/// whose median lies beyond the run last): a design that often fails to
/// settle cannot rank first on its few fast runs.
pub fn ranked_table(summary: &DataFrame) -> Result<String, UserError> {
    let col_f = |name: &str| -> Result<Vec<Option<f64>>, UserError> {
        Ok(summary.column(name)?.f64()?.iter().collect())
    };
    let kind: Vec<String> = summary
        .column("kind")?
        .str()?
        .iter()
        .map(|s| s.unwrap_or_default().to_string())
        .collect();
    let n: Vec<Option<u32>> = summary.column("n")?.u32()?.iter().collect();
    let (rho, drag, frac, lo, hi) = (
        col_f("rho")?,
        col_f("drag")?,
        col_f("settled_fraction")?,
        col_f("settled_fraction_lo")?,
        col_f("settled_fraction_hi")?,
    );
    let (median, p90, res) = (
        col_f("settling_revs_median_all_runs")?,
        col_f("settling_revs_p90_all_runs")?,
        col_f("residual_rel_median")?,
    );
    let mut order: Vec<usize> = (0..summary.height()).collect();
    order.sort_by(|&a, &b| match (median[a], median[b]) {
        (Some(x), Some(y)) => x.total_cmp(&y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => a.cmp(&b),
    });
    let f =
        |v: Option<f64>, digits: usize| v.map_or("–".to_string(), |x| format!("{x:.digits$}"));
    let rows: Vec<Vec<String>> = order
        .iter()
        .enumerate()
        .map(|(rank, &i)| {
            vec![
                (rank + 1).to_string(),
                kind[i].clone(),
                n[i].map_or("–".into(), |v| v.to_string()),
                f(rho[i], 4),
                f(drag[i], 3),
                format!("{} [{}, {}]", f(frac[i], 3), f(lo[i], 2), f(hi[i], 2)),
                f(median[i], 1),
                f(p90[i], 1),
                f(res[i], 4),
            ]
        })
        .collect();
    Ok(text_table(
        &[
            "rank",
            "kind",
            "n",
            "ρ",
            "β",
            "settled [95% CI]",
            "t_s median (all runs)",
            "t_s p90 (all runs)",
            "residual/A_ref",
        ],
        &rows,
    ) + "(settling times in revolutions; median and p90 over all runs, unsettled ones counting as later than any settled, – when that quantile lies beyond the run; residual: median RMS vibration over the last hold window)\n"
        + &contact_line(summary)?)
}

/// Whether the weights were solid, said under every ranking: a study that
/// switched contact off prints numbers for weights that pass through each other.
fn contact_line(summary: &DataFrame) -> Result<String, UserError> {
    let contact = summary.column("contact")?.bool()?;
    let deepest = summary
        .column("max_overlap_fraction")?
        .f64()?
        .iter()
        .flatten()
        .reduce(f64::max);
    let closest = deepest.map_or(String::new(), |f| {
        format!(
            "; deepest overlap {:.2} % of the touching angle 2α",
            100.0 * f
        )
    });
    let off = contact.iter().filter(|c| *c == Some(false)).count();
    Ok(if off == 0 {
        format!("contact between the weights: on{closest}\n")
    } else {
        format!(
            "contact between the weights: OFF in {} of {} designs (the study switched it off: weights may pass through each other){closest}\n",
            off,
            summary.height()
        )
    })
}
