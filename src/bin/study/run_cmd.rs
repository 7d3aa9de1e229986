//! `study run` and `study merge`: the Monte Carlo study runner.

use crate::UserError;
use crate::output::{text_width, wrap};
use crate::progress::RunProgress;
use crate::robustness_notes::robustness_lines;
use autobal::decide::failures::failure_advice;
use autobal::study::plan::config::load;
use autobal::study::plan::criterion::Criterion;
use autobal::study::run::merge::merge;
use autobal::study::run::{AdaptiveOutcome, RunError, RunOptions, Shard, run_study};
use autobal::text::ranking::ranked_table;
use clap::Args;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

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
    #[arg(long, value_parser = crate::limits::threads)]
    threads: Option<usize>,
    /// No progress output (a bar on a terminal, else a line every --progress-every seconds).
    #[arg(long)]
    quiet: bool,
    /// Seconds between two progress lines when stderr is not a terminal (a batch log).
    #[arg(long, default_value_t = 30.0, value_parser = crate::limits::progress_seconds)]
    progress_every: f64,
    /// Write finished runs to disk after this many, or every 2 s, whichever comes first.
    #[arg(long, default_value_t = 4096, value_parser = crate::limits::chunk_runs)]
    chunk_runs: usize,
    /// Rank designs by this criterion instead of the study's `[summary] rank_by`:
    /// median, mean, p90, settled_fraction, settled_by:<X>rev|s, residual_p95, p_residual_below:<X>m.
    #[arg(long, value_parser = crate::completion_values::CriterionParser, hide_possible_values = true, value_name = "CRITERION")]
    rank_by: Option<Criterion>,
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

/// Run `study run`.
pub fn run(args: &RunArgs) -> Result<(), UserError> {
    let threads = crate::limits::capped_threads(args.threads);
    let mut plan = load(&args.study)?;
    if let Some(criterion) = args.rank_by {
        plan.file.summary.rank_by = criterion;
    }
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
    let bar = RunProgress::new(args.quiet, Duration::from_secs_f64(args.progress_every));
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
        Some(summary) => {
            print!("{}", ranked_table(summary, crate::output::layout())?);
            if let Some(adaptive) = &output.adaptive {
                println!("{}", adaptive_line(adaptive));
            }
            if let Some(line) = race_line(&output) {
                print!("{}", wrap(&(line + "\n"), text_width()));
            }
            print!("{}", robustness_lines(&plan, &output.dir, summary)?);
        }
        None => println!(
            "shard {} done: {} runs in {} (merge the shards with `study merge`)",
            args.shard.map(|s| s.label()).unwrap_or_default(),
            output.runs,
            output.dir.display()
        ),
    }
    eprintln!("wrote {}", output.dir.display());
    if args.shard.is_some() {
        // A shard's failed runs are reported here and fail the merge, the
        // step that completes the study: a batch system then still runs it.
        if let Some(advice) = failure_advice(&plan, &output.dir.join("runs.parquet"))? {
            eprintln!("warning: {advice} (`study merge` will exit 1)");
        }
        return Ok(());
    }
    fail_on_unfinished_runs(&plan, &output.dir)
}

/// Exit 1, after everything is written, when any run ended
/// `budget_exceeded` or `solver_failed`, with the setting to change.
fn fail_on_unfinished_runs(
    plan: &autobal::study::plan::config::StudyPlan,
    dir: &std::path::Path,
) -> Result<(), UserError> {
    match failure_advice(plan, &dir.join("runs.parquet"))? {
        Some(advice) => Err(UserError(advice, 1)),
        None => Ok(()),
    }
}

/// Run `study merge`.
pub fn merge_shards(args: &MergeArgs) -> Result<(), UserError> {
    if let Some(out) = &args.out {
        autobal::output_file::prepare_folder("--out", out)?;
    }
    let output = merge(&args.dirs, args.out.as_deref(), args.overwrite)?;
    if let Some(summary) = &output.summary {
        print!("{}", ranked_table(summary, crate::output::layout())?);
    }
    if let Some(line) = race_line(&output) {
        print!("{}", wrap(&(line + "\n"), text_width()));
    }
    // The shards' failed runs are never absorbed either: the study text
    // stored beside the merged files names the settings.
    let plan = load(&output.dir.join("study.toml"))?;
    if let Some(summary) = &output.summary {
        print!("{}", robustness_lines(&plan, &output.dir, summary)?);
    }
    eprintln!("merged {} runs into {}", output.runs, output.dir.display());
    fail_on_unfinished_runs(&plan, &output.dir)
}

/// Where adaptive sampling stopped: how many samples it took, and the
/// precision then against the target.
fn adaptive_line(adaptive: &AdaptiveOutcome) -> String {
    let state: Vec<String> = adaptive
        .precision
        .worst
        .iter()
        .map(|(key, value, target)| {
            let value = if value.is_finite() {
                format!("{value:.3}")
            } else {
                "unbounded".to_string()
            };
            format!("{key} {value} (target {target})")
        })
        .collect();
    let how = if adaptive.precision.reached {
        "precision reached"
    } else {
        "precision NOT reached: stopped at the cap `samples`"
    };
    format!(
        "adaptive sampling: {how} after {} batches, {} samples per design; {}",
        adaptive.batches,
        adaptive.samples_per_design,
        state.join(", ")
    )
}

/// What racing saved, in runs, and which designs left the race when.
fn race_line(output: &autobal::study::run::StudyOutput) -> Option<String> {
    let departures = output.race.as_ref()?;
    if departures.is_empty() {
        return Some(format!(
            "racing: no design left the race early; all {} runs were needed",
            group_thousands(output.runs)
        ));
    }
    // Designs that left at the same look, in one group.
    let mut groups: Vec<(u32, Vec<u32>)> = Vec::new();
    for d in departures {
        match groups.iter_mut().find(|(s, _)| *s == d.samples) {
            Some((_, ids)) => ids.push(d.design_id),
            None => groups.push((d.samples, vec![d.design_id])),
        }
    }
    groups.sort_by_key(|(s, _)| *s);
    let when: Vec<String> = groups
        .iter()
        .map(|(samples, ids)| {
            let ids: Vec<String> = ids.iter().map(u32::to_string).collect();
            format!("after {samples} samples: {}", ids.join(", "))
        })
        .collect();
    Some(format!(
        "racing: decided after {} of {} runs; {} left the race once #1 was significantly better and no other reported measure favoured {} ({}); `[sampling] racing = false` runs every sample",
        group_thousands(output.runs),
        group_thousands(output.runs_planned),
        if departures.len() == 1 {
            "1 design".to_string()
        } else {
            format!("{} designs", departures.len())
        },
        if departures.len() == 1 { "it" } else { "them" },
        when.join("; ")
    ))
}

/// 10000 as "10 000", as the tool prints counts.
fn group_thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(' ');
        }
        out.push(c);
    }
    out
}
