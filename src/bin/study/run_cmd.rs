//! `study run` and `study merge`: the Monte Carlo study runner.

use crate::UserError;
use crate::output::{p_value_text, text_table};
use crate::progress::RunProgress;
use autobal::study::config::load;
use autobal::study::merge::merge;
use autobal::study::run::{AdaptiveOutcome, RunError, RunOptions, Shard, run_study};
use clap::Args;
use polars::prelude::DataFrame;
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
    #[arg(long)]
    threads: Option<usize>,
    /// No progress output (a bar on a terminal, else a line every --progress-every seconds).
    #[arg(long)]
    quiet: bool,
    /// Seconds between two progress lines when stderr is not a terminal (a batch log).
    #[arg(long, default_value_t = 30.0)]
    progress_every: f64,
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
    if !(args.progress_every.is_finite() && args.progress_every > 0.0) {
        return Err(UserError(
            format!(
                "--progress-every {}: seconds between progress lines, a positive number",
                args.progress_every
            ),
            2,
        ));
    }
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
            print!("{}", ranked_table(summary)?);
            if let Some(adaptive) = &output.adaptive {
                println!("{}", adaptive_line(adaptive));
            }
        }
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

/// Designs ranked by their Kaplan–Meier median settling time (every run
/// counts; a run that did not settle is censored), ties and medians beyond
/// the run ordered by the restricted mean; then the best design against
/// every other on paired runs, Holm-corrected.
pub fn ranked_table(summary: &DataFrame) -> Result<String, UserError> {
    let col_f = |name: &str| -> Result<Vec<Option<f64>>, UserError> {
        Ok(summary.column(name)?.f64()?.iter().collect())
    };
    let col_s = |name: &str| -> Result<Vec<Option<String>>, UserError> {
        Ok(summary
            .column(name)?
            .str()?
            .iter()
            .map(|s| s.map(str::to_string))
            .collect())
    };
    let kind: Vec<String> = col_s("kind")?
        .into_iter()
        .map(Option::unwrap_or_default)
        .collect();
    let n: Vec<Option<u32>> = summary.column("n")?.u32()?.iter().collect();
    let runs: Vec<Option<u64>> = summary.column("runs")?.u64()?.iter().collect();
    let (rho, drag, frac, lo, hi) = (
        col_f("rho")?,
        col_f("drag")?,
        col_f("settled_fraction")?,
        col_f("settled_fraction_lo")?,
        col_f("settled_fraction_hi")?,
    );
    let (median, median_lo, median_hi, rmst, rmst_lo, rmst_hi) = (
        col_f("settling_revs_median_km")?,
        col_f("settling_revs_median_km_lo")?,
        col_f("settling_revs_median_km_hi")?,
        col_f("settling_revs_rmst")?,
        col_f("settling_revs_rmst_lo")?,
        col_f("settling_revs_rmst_hi")?,
    );
    let (p90, res) = (
        col_f("settling_revs_p90_all_runs")?,
        col_f("residual_rel_median")?,
    );
    let (verdict, share, share_lo, share_hi, p_holm) = (
        col_s("vs_best_verdict")?,
        col_f("vs_best_sooner_share")?,
        col_f("vs_best_sooner_share_lo")?,
        col_f("vs_best_sooner_share_hi")?,
        col_f("vs_best_p_holm")?,
    );
    let key = |i: usize| {
        (
            median[i].unwrap_or(f64::INFINITY),
            rmst[i].unwrap_or(f64::INFINITY),
        )
    };
    let mut order: Vec<usize> = (0..summary.height()).collect();
    order.sort_by(|&a, &b| {
        let (ka, kb) = (key(a), key(b));
        ka.0.total_cmp(&kb.0)
            .then(ka.1.total_cmp(&kb.1))
            .then(a.cmp(&b))
    });
    // The summary picks the best design by the same key; show that one first.
    if let Some(pos) = order
        .iter()
        .position(|&i| verdict[i].as_deref() == Some("best"))
    {
        let best = order.remove(pos);
        order.insert(0, best);
    }
    let f =
        |v: Option<f64>, digits: usize| v.map_or("–".to_string(), |x| format!("{x:.digits$}"));
    let bound = |v: Option<f64>| v.map_or("∞".to_string(), |x| format!("{x:.1}"));
    let pct = |v: Option<f64>| v.map_or("–".to_string(), |x| format!("{:.0}", 100.0 * x));
    let rows: Vec<Vec<String>> = order
        .iter()
        .enumerate()
        .map(|(rank, &i)| {
            let versus = match verdict[i].as_deref() {
                Some("best") => "best".to_string(),
                Some("only_design") | None => "–".to_string(),
                Some(_) if share[i].is_some() => format!(
                    "{} % [{}, {}], p {}",
                    pct(share[i]),
                    pct(share_lo[i]),
                    pct(share_hi[i]),
                    p_text(p_holm[i])
                ),
                Some(_) => format!("log-rank p {}", p_text(p_holm[i])),
            };
            vec![
                (rank + 1).to_string(),
                kind[i].clone(),
                n[i].map_or("–".into(), |v| v.to_string()),
                f(rho[i], 4),
                f(drag[i], 3),
                format!("{} [{}, {}]", f(frac[i], 3), f(lo[i], 2), f(hi[i], 2)),
                match median[i] {
                    Some(m) => format!("{m:.1} [{}, {}]", bound(median_lo[i]), bound(median_hi[i])),
                    None => "beyond the run".to_string(),
                },
                format!(
                    "{} [{}, {}]",
                    f(rmst[i], 1),
                    f(rmst_lo[i], 1),
                    f(rmst_hi[i], 1)
                ),
                f(p90[i], 1),
                f(res[i], 4),
                versus,
            ]
        })
        .collect();
    // A stall-torque sweep gets its own column after β (designs differ by
    // it alone); other studies print exactly as before.
    let torque: Vec<Option<f64>> = match summary.column("stall_torque") {
        Ok(c) => c.f64()?.iter().collect(),
        Err(_) => vec![None; summary.height()],
    };
    let swept = torque.iter().any(Option::is_some);
    let rows: Vec<Vec<String>> = if swept {
        rows.into_iter()
            .zip(&order)
            .map(|(mut row, &i)| {
                row.insert(5, f(torque[i], 3));
                row
            })
            .collect()
    } else {
        rows
    };
    let mut header = vec!["rank", "kind", "n", "ρ", "β"];
    if swept {
        header.push("M_s (N·m)");
    }
    header.extend([
        "settled [95% CI]",
        "t_s median [95% CI]",
        "t_s restricted mean [95% CI]",
        "t_s p90",
        "residual/A_ref",
        "best sooner in (paired runs) [95% CI], Holm p",
    ]);
    let per_design = runs.iter().flatten().max().copied().unwrap_or(0);
    let alpha = col_f("vs_best_alpha")?
        .first()
        .copied()
        .flatten()
        .unwrap_or(f64::NAN);
    Ok(text_table(&header, &rows)
        + "(settling times in revolutions over every run, a run that did not settle counting as censored: Kaplan–Meier median with its Brookmeyer–Crowley interval (∞: not bounded within the run), restricted mean up to the horizon, p90; residual: median RMS vibration over the last hold window relative to A_ref)\n"
        + &verdict_line(summary, &order, alpha, per_design)?
        + &contact_line(summary)?
        + &passage_table(summary)?)
}

/// For a study that sweeps the motor's stall torque: per design, how many
/// runs reached the operating speed and where the rest were held (the
/// Sommerfeld effect, docs/realism.md); empty otherwise.
fn passage_table(summary: &DataFrame) -> Result<String, UserError> {
    let Ok(torque) = summary.column("stall_torque") else {
        return Ok(String::new());
    };
    let torque: Vec<Option<f64>> = torque.f64()?.iter().collect();
    if torque.iter().all(Option::is_none) {
        return Ok(String::new());
    }
    let kind: Vec<Option<&str>> = summary.column("kind")?.str()?.iter().collect();
    let n: Vec<Option<u32>> = summary.column("n")?.u32()?.iter().collect();
    let runs: Vec<Option<u64>> = summary.column("runs")?.u64()?.iter().collect();
    let reached: Vec<Option<u64>> = summary
        .column("reached_operating_speed")?
        .u64()?
        .iter()
        .collect();
    let t_op: Vec<Option<f64>> = summary
        .column("operating_time_s_median")?
        .f64()?
        .iter()
        .collect();
    let spin: Vec<Option<f64>> = summary
        .column("final_spin_rate_median")?
        .f64()?
        .iter()
        .collect();
    let rows: Vec<Vec<String>> = (0..summary.height())
        .map(|i| {
            vec![
                i.to_string(),
                kind[i].unwrap_or("–").to_string(),
                n[i].map_or("–".into(), |v| v.to_string()),
                torque[i].map_or("–".into(), |v| format!("{v:.3}")),
                format!("{}/{}", reached[i].unwrap_or(0), runs[i].unwrap_or(0)),
                t_op[i].map_or("–".into(), |v| format!("{v:.2}")),
                spin[i].map_or("–".into(), |v| format!("{v:.1}")),
            ]
        })
        .collect();
    Ok(text_table(
        &[
            "design",
            "kind",
            "n",
            "M_s (N·m)",
            "reached operating speed",
            "after (s, median)",
            "final φ̇ median (rad/s)",
        ],
        &rows,
    ) + "(passage through resonance: a run that never reached |φ̇ − ω_sync| ≤ δ ω_sync was held below it for the whole run)\n")
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

/// An optional p-value as printed.
fn p_text(p: Option<f64>) -> String {
    p.map_or("–".to_string(), p_value_text)
}

/// The sentence under the ranking: which design is fastest, against how
/// many others that holds at α, and which it cannot be told apart from.
fn verdict_line(
    summary: &DataFrame,
    order: &[usize],
    alpha: f64,
    per_design: u64,
) -> Result<String, UserError> {
    let verdict: Vec<Option<String>> = summary
        .column("vs_best_verdict")?
        .str()?
        .iter()
        .map(|s| s.map(str::to_string))
        .collect();
    let test: Vec<Option<String>> = summary
        .column("vs_best_test")?
        .str()?
        .iter()
        .map(|s| s.map(str::to_string))
        .collect();
    let Some(&best) = order.first() else {
        return Ok(String::new());
    };
    if verdict[best].as_deref() != Some("best") {
        return Ok(String::new());
    }
    let count = |name: &str| {
        verdict
            .iter()
            .filter(|v| v.as_deref() == Some(name))
            .count()
    };
    let rank_of = |names: &[&str]| -> Vec<String> {
        order
            .iter()
            .enumerate()
            .filter(|(_, i)| names.contains(&verdict[**i].as_deref().unwrap_or("")))
            .map(|(r, _)| format!("#{}", r + 1))
            .collect()
    };
    let how = if test.iter().flatten().any(|t| t == "sign") {
        "sign test on runs paired by their shared samples"
    } else {
        "log-rank test: the designs did not share samples"
    };
    let mut line = format!(
        "verdict: #1 settles sooner than {} of the other {} designs ({how}, Holm-adjusted at α = {alpha}, {per_design} runs per design)",
        count("best_sooner"),
        order.len() - 1
    );
    let unclear = rank_of(&["not_distinguishable"]);
    if !unclear.is_empty() {
        line += &format!("; not distinguishable from {}", unclear.join(", "));
    }
    let reversed = rank_of(&["other_sooner"]);
    if !reversed.is_empty() {
        line += &format!(
            "; {} settle sooner in more paired runs although their median is higher",
            reversed.join(", ")
        );
    }
    Ok(line + "\n")
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
