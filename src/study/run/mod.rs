//! The runner: every pending run of the plan on all cores (rayon),
//! finished runs written in chunks as they complete, resumable, shardable.
//! Uses the plan, the results and the decision (racing, the summary).
//!
//! - this file: the executor's entry points ([`run_study`], shards, options).
//! - [`racing`]: designs dropped early once they cannot be #1.
//! - [`adaptive`]: sampling in batches until a requested precision.
//! - [`aggregate`]: per-design statistics (`summary.parquet`) with polars.
//! - [`causes`]: the leading design's unsettled runs re-run without each effect (`causes.parquet`).
//! - [`merge`]: combining shard outputs.
//! - [`lock`]: one writer per results folder.
//! - [`study_folder`]: the study's folder as another verb's destination (tradeoff, optimize).
//!
//! Results never depend on the schedule: each run draws from its own stream
//! ([`crate::study::plan::sample`]) and the final files are sorted by run index, so they
//! are bit-identical (but for the wall-time column) for any thread count,
//! any interruption and resumption, and any sharding followed by a merge.

use crate::metrics::{Outcome, RunMetrics};
use crate::simulation::Simulation;
use crate::study::plan::config::StudyPlan;
use crate::study::plan::design::Design;
use crate::study::plan::sample::{Sample, draw_sample_in, draw_weights};
use crate::study::results::io::{Provenance, read_parquet, sha256_hex, write_chunk, write_parquet};
use crate::study::results::record::{RunRecord, from_dataframe, to_dataframe};
use crate::study::results::runs_file::{
    Piece, read_pieces_summary_columns, read_summary_columns, write_runs,
};
use crate::study::run::adaptive::{Precision, batch_ids, batches, precision};
use crate::study::run::aggregate::summarize_table;
use crate::study::run::lock::LockError;
use crate::study::run::racing::{Departure, Race, only_running, races};
use polars::prelude::{ChunkCompareIneq, DataFrame, PolarsError, PolarsResult};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, mpsc};
use std::time::{Duration, Instant};

pub mod adaptive;
pub mod aggregate;
mod assemble;
pub mod causes;
mod executor;
mod folder;
pub mod lock;
pub mod merge;
pub mod racing;
pub mod study_folder;

pub use assemble::{
    run_design_sample, run_design_sample_in, run_one, sample_simulation, sample_simulation_in,
};
use executor::{chunk_pieces, earlier_table_pieces, execute};

/// The k-th of N disjoint slices of a study (k counted from 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which slice, 1..=count.
    pub index: u32,
    /// How many slices.
    pub count: u32,
}

impl Shard {
    /// Parse "k/N" with 1 ≤ k ≤ N.
    pub fn parse(text: &str) -> Result<Self, String> {
        let (k, n) = text
            .split_once('/')
            .ok_or_else(|| format!("--shard {text}: expected k/N, e.g. 2/8"))?;
        let parse = |s: &str| {
            s.trim()
                .parse::<u32>()
                .map_err(|_| format!("--shard {text}: '{s}' is not a whole number"))
        };
        let (index, count) = (parse(k)?, parse(n)?);
        if count == 0 || index == 0 || index > count {
            return Err(format!("--shard {text}: need 1 ≤ k ≤ N"));
        }
        Ok(Shard { index, count })
    }

    /// True when run `run_id` belongs to this slice (runs are dealt round-robin,
    /// so that slow designs are spread over all shards).
    pub fn contains(&self, run_id: u64) -> bool {
        run_id % u64::from(self.count) == u64::from(self.index - 1)
    }

    /// "k/N".
    pub fn label(&self) -> String {
        format!("{}/{}", self.index, self.count)
    }
}

/// How to execute a plan.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Continue an interrupted run instead of starting afresh.
    pub resume: bool,
    /// Run only one slice.
    pub shard: Option<Shard>,
    /// Worker threads (default: rayon's global pool, RAYON_NUM_THREADS).
    pub threads: Option<usize>,
    /// Write a chunk after this many finished runs …
    pub chunk_runs: usize,
    /// … or after this much time, whichever comes first.
    pub chunk_interval: Duration,
    /// Replace the results already in the folder (otherwise a fresh run over
    /// existing results is refused: they are never deleted silently).
    pub overwrite: bool,
    /// Set it (e.g. from a SIGINT handler) to stop: runs not yet started are
    /// skipped, finished ones are saved as chunks for `--resume`, and
    /// [`run_study`] returns [`RunError::Interrupted`].
    pub cancel: Option<Arc<AtomicBool>>,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            resume: false,
            shard: None,
            threads: None,
            chunk_runs: 4096,
            chunk_interval: Duration::from_secs(2),
            overwrite: false,
            cancel: None,
        }
    }
}

/// Receives progress events (the CLI draws a progress bar; the library never prints).
pub trait Progress: Sync {
    /// The run is about to start: `total` runs in this slice, `done` already finished.
    fn begin(&self, _total: u64, _done: u64) {}
    /// One more run finished.
    fn advance(&self, _record: &RunRecord) {}
    /// `runs` runs of the total will not run: their designs left the race.
    fn skip(&self, _runs: u64) {}
    /// Everything is written.
    fn end(&self) {}
    /// The run stopped on request ([`RunOptions::cancel`]): `finished` of
    /// `total` runs are saved, and [`RunError::Interrupted`] follows; `end`
    /// is not called, since the study did not finish.
    fn interrupted(&self, _finished: u64, _total: u64) {}
}

/// A progress sink that ignores everything.
pub struct NoProgress;

impl Progress for NoProgress {}

/// What a finished study produced.
#[derive(Debug)]
pub struct StudyOutput {
    /// Folder holding the files.
    pub dir: PathBuf,
    /// How many runs `runs.parquet` holds (read them with [`StudyOutput::load_runs`]).
    pub runs: u64,
    /// Per-design statistics (unsharded runs only; shards are summarised by `merge`).
    pub summary: Option<DataFrame>,
    /// Runs executed in this invocation (the rest came from a resumed run).
    pub executed: u64,
    /// Where adaptive sampling stopped (studies with `stop_when`).
    pub adaptive: Option<AdaptiveOutcome>,
    /// The designs that left the race, in design order (`None`: the study
    /// did not race).
    pub race: Option<Vec<Departure>>,
    /// Runs the study would make without racing or a precision to stop at.
    pub runs_planned: u64,
}

/// Where adaptive sampling stopped, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct AdaptiveOutcome {
    /// Batches run.
    pub batches: usize,
    /// Samples per design when it stopped.
    pub samples_per_design: u32,
    /// The precision then (not reached: the cap `samples` was).
    pub precision: Precision,
}

impl StudyOutput {
    /// Every run of the folder, sorted by run index (the whole table in memory:
    /// for small studies and tests; large ones are read with polars).
    pub fn load_runs(&self) -> PolarsResult<Vec<RunRecord>> {
        from_dataframe(&read_parquet(&self.dir.join("runs.parquet"))?)
    }
}

/// Why a study could not run or finish.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The output folder cannot be created or written.
    #[error("output folder {path} cannot be written: {source}")]
    NotWritable {
        /// The folder.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// `--resume` on a folder whose run began from a different study file.
    #[error(
        "cannot resume in {path}: the study file changed since the run began; run it with --overwrite instead of --resume to replace the earlier runs with runs of the changed file (or restore the file, or give the study another `name`)"
    )]
    StudyChanged {
        /// The folder.
        path: String,
    },
    /// A fresh run over a folder that already holds results.
    #[error(
        "{path} already holds results of a study run; continue it with --resume, replace it with --overwrite, or choose another output folder"
    )]
    ResultsExist {
        /// The folder.
        path: String,
    },
    /// `--resume` on a folder with results but no record of their plan.
    #[error(
        "cannot resume in {path}: it holds results but no study.toml saying which plan made them; nothing was changed (move them away, or run with --overwrite to replace them)"
    )]
    NoPlan {
        /// The folder.
        path: String,
    },
    /// `--resume` on a folder written by another autobal build.
    #[error(
        "cannot resume in {path}: its runs were made by another autobal build (plan {found}, this one {expected}); mixing them would mix results of different code"
    )]
    PlanChanged {
        /// The folder.
        path: String,
        /// The plan id stored in the folder.
        found: String,
        /// This run's plan id.
        expected: String,
    },
    /// A results table in the folder recorded another study, seed or
    /// shard than the one asked to continue.
    #[error(
        "cannot resume in {folder}: {path} does not hold this study's runs: {reason}; nothing was changed (move it away, or run with --overwrite to replace it)"
    )]
    ForeignTable {
        /// The folder.
        folder: String,
        /// The table.
        path: String,
        /// What its provenance says.
        reason: String,
    },
    /// `--resume` on a folder whose plan id is missing or unreadable.
    #[error(
        "cannot resume in {path}: its {PLAN_ID_FILE} is missing or unreadable, so which autobal build made its runs cannot be told; nothing was changed (run with --overwrite to replace them)"
    )]
    PlanUnknown {
        /// The folder.
        path: String,
    },
    /// Another process is writing the folder.
    #[error(transparent)]
    Locked(#[from] LockError),
    /// A verb that rewrites its own folders met one it did not write.
    #[error(
        "{path} holds results that {owner} did not write; nothing was replaced: give the study another `name` or `output`"
    )]
    NotOwned {
        /// The folder.
        path: String,
        /// The verb that owns its folders.
        owner: &'static str,
    },
    /// Adaptive sampling decides on all designs' runs, which a shard lacks.
    #[error(
        "sampling.stop_when cannot be used with --shard: the stopping decision needs every run of a batch; run the study unsharded (or set a fixed sample count)"
    )]
    AdaptiveSharded,
    /// Stopped on request; what finished is saved.
    #[error(
        "interrupted after {finished} of {total} runs ({saved} of them in this invocation), saved in {path}; continue with --resume"
    )]
    Interrupted {
        /// The folder.
        path: String,
        /// Runs finished and saved in this invocation.
        saved: u64,
        /// Runs finished in all, earlier invocations included.
        finished: u64,
        /// Runs of the study (of the shard, with `--shard`).
        total: u64,
    },
    /// An entry of the study folder is of the wrong kind (a file where its
    /// `chunks/` folder belongs, a folder named `study.toml`).
    #[error(
        "{path} is {found}, where the study folder keeps its {want}; nothing was changed: move it away, or choose another output folder"
    )]
    Misshapen {
        /// The entry.
        path: String,
        /// What it is ("a file", "a folder").
        found: &'static str,
        /// What belongs there.
        want: &'static str,
    },
    /// Reading or writing Parquet failed.
    #[error("{0}")]
    Polars(#[from] PolarsError),
    /// Other I/O.
    #[error("i/o: {0}")]
    Io(#[from] std::io::Error),
    /// I/O in the study's output folder.
    #[error("{path}: {source}")]
    FolderIo {
        /// The folder.
        path: String,
        /// The cause.
        source: std::io::Error,
    },
    /// The thread pool could not be built.
    #[error("thread pool: {0}")]
    Pool(String),
}

impl RunError {
    /// True when the error is the user's (bad folder, changed study): exit code 2.
    pub fn is_user_error(&self) -> bool {
        matches!(
            self,
            RunError::NotWritable { .. }
                | RunError::StudyChanged { .. }
                | RunError::ResultsExist { .. }
                | RunError::NoPlan { .. }
                | RunError::PlanChanged { .. }
                | RunError::ForeignTable { .. }
                | RunError::PlanUnknown { .. }
                | RunError::Locked(_)
                | RunError::NotOwned { .. }
                | RunError::AdaptiveSharded
                | RunError::Misshapen { .. }
        ) || matches!(self, RunError::Polars(e) if crate::study::results::io::is_not_parquet(e))
    }
}

/// Folder of a study's (or a shard's) files.
pub fn output_dir(plan: &StudyPlan, shard: Option<Shard>) -> PathBuf {
    let base = Path::new(&plan.file.output).join(&plan.name);
    match shard {
        Some(s) => base.join(format!("shard-{}-of-{}", s.index, s.count)),
        None => base,
    }
}

/// File holding the folder's plan id (see [`plan_id`]).
pub const PLAN_ID_FILE: &str = "plan.sha256";

/// What makes runs of one folder comparable: the study text (with its seed)
/// and the autobal build that ran them (version and git commit, as in the
/// run's `provenance`).
pub fn plan_id(plan: &StudyPlan, provenance: &Provenance) -> String {
    sha256_hex(&format!(
        "autobal {}\ncommit {}\n{}",
        provenance.version, provenance.git_commit, plan.text
    ))
}

/// Label stored in provenance: "all" or "k/N".
pub fn shard_label(shard: Option<Shard>) -> String {
    shard.map_or_else(|| "all".to_string(), |s| s.label())
}

/// Run (or resume) the plan and write `runs.parquet` (and `summary.parquet`
/// for an unsharded run) under [`output_dir`].
pub fn run_study(
    plan: &StudyPlan,
    options: &RunOptions,
    progress: &dyn Progress,
) -> Result<StudyOutput, RunError> {
    // Refused before the folder is made: nothing is written.
    if plan.file.sampling.stop_when.is_some() && options.shard.is_some() {
        return Err(RunError::AdaptiveSharded);
    }
    let dir = output_dir(plan, options.shard);
    run_in_folder(&dir, plan, options, progress).map_err(|e| match e {
        RunError::Io(source) => RunError::FolderIo {
            path: dir.display().to_string(),
            source,
        },
        other => other,
    })
}

/// [`run_study`] in its output folder `dir`: claim the folder, check what
/// it holds, run the batches not yet run, write the tables.
fn run_in_folder(
    dir: &Path,
    plan: &StudyPlan,
    options: &RunOptions,
    progress: &dyn Progress,
) -> Result<StudyOutput, RunError> {
    let dir = dir.to_path_buf();
    let _lock = folder::claim(&dir)?;
    let files = folder::FolderFiles::in_folder(&dir);
    // Provenance asks git for the commit: once per run, shared with the plan id.
    let provenance = Provenance::new(&plan.text, plan.file.seed, &shard_label(options.shard));
    let id = plan_id(plan, &provenance);
    if options.resume && files.manifest.exists() {
        folder::check_resume(&dir, &files, plan, &id, &provenance)?;
    } else {
        folder::start_afresh(&dir, &files, plan, options, &id)?;
    }
    // What earlier invocations finished: only their run ids are read, the
    // table before anything is made, so that a damaged one is refused with
    // the folder as it was.
    let earlier_table = earlier_table_pieces(&files.runs)?;
    std::fs::create_dir_all(&files.chunks)?;
    let total_ids = plan.total_runs();
    let mut done = vec![false; total_ids as usize];
    mark_done(&earlier_table, &mut done);
    mark_done(&chunk_pieces(&files.chunks)?, &mut done);
    let in_slice = |id: &u64| options.shard.is_none_or(|s| s.contains(*id));
    let total = (0..total_ids).filter(in_slice).count() as u64;
    let already = done.iter().filter(|d| **d).count() as u64;
    progress.begin(total, already);

    // One pool for the runs and the summary's comparisons, so that
    // `--threads` bounds both.
    let pool = match options.threads {
        Some(t) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .map_err(|e| RunError::Pool(e.to_string()))?,
        ),
        None => None,
    };
    let run = RunContext {
        dir: &dir,
        files: &files,
        plan,
        options,
        pool: pool.as_ref(),
        progress,
    };
    let batched = run.batches(&done, (total, already))?;

    // The earlier table first: on a duplicate (a crash between writing the
    // table and removing the chunks) its copy is kept.
    let mut pieces = earlier_table;
    pieces.extend(chunk_pieces(&files.chunks)?);
    let (written, summary) = run.write_tables(pieces, total, &provenance)?;
    std::fs::remove_dir_all(&files.chunks)?;
    progress.end();
    Ok(StudyOutput {
        dir,
        runs: written,
        summary,
        executed: batched.executed,
        adaptive: batched.adaptive,
        race: batched.race.map(|r| r.departures()),
        runs_planned: total_ids,
    })
}

/// Mark every run id of `pieces` as done.
fn mark_done(pieces: &[Piece], done: &mut [bool]) {
    for piece in pieces {
        for &id in piece.ids() {
            if let Some(d) = done.get_mut(id as usize) {
                *d = true;
            }
        }
    }
}

/// What one invocation of a study run works with.
struct RunContext<'a> {
    dir: &'a Path,
    files: &'a folder::FolderFiles,
    plan: &'a StudyPlan,
    options: &'a RunOptions,
    pool: Option<&'a rayon::ThreadPool>,
    progress: &'a dyn Progress,
}

/// What the batches left: runs executed here, the adaptive stop, the race.
struct Batched {
    executed: u64,
    adaptive: Option<AdaptiveOutcome>,
    race: Option<Race>,
}

impl RunContext<'_> {
    /// `f` on the run's thread pool (the global one without `--threads`).
    fn install<T: Send>(&self, f: impl FnOnce() -> T + Send) -> T {
        match self.pool {
            Some(p) => p.install(f),
            None => f(),
        }
    }

    /// Run the batches' runs not yet `done` of this slice, judging the race
    /// and the adaptive stop after each batch; (`total`, `already`): the
    /// slice's runs and those finished before this invocation.
    fn batches(&self, done: &[bool], (total, already): (u64, u64)) -> Result<Batched, RunError> {
        let (plan, options) = (self.plan, self.options);
        let in_slice = |id: &u64| options.shard.is_none_or(|s| s.contains(*id));
        let stop_when = plan.file.sampling.stop_when.as_ref();
        let mut executed = 0;
        let mut adaptive = None;
        let batches = batches(plan);
        // A shard cannot judge a race (it lacks the other shards' runs): it
        // runs every sample, and `merge` replays the race on the merged runs.
        let mut race = (races(plan) && options.shard.is_none()).then(|| Race::new(plan, &batches));
        let samples = u64::from(plan.file.sampling.samples);
        for (k, range) in batches.iter().enumerate() {
            let pending: Vec<u64> = batch_ids(plan, range)
                .into_iter()
                .filter(in_slice)
                .filter(|&id| !done[id as usize])
                .filter(|&id| {
                    race.as_ref()
                        .is_none_or(|r| r.runs((id / samples) as usize, (id % samples) as u32))
                })
                .collect();
            let saved = execute(
                plan,
                &pending,
                options,
                self.pool,
                &self.files.chunks,
                self.progress,
            )?;
            if options
                .cancel
                .as_ref()
                .is_some_and(|c| c.load(Ordering::Relaxed))
            {
                let finished = already + executed + saved;
                self.progress.interrupted(finished, total);
                return Err(RunError::Interrupted {
                    path: self.dir.display().to_string(),
                    saved: executed + saved,
                    finished,
                    total,
                });
            }
            executed += pending.len() as u64;
            let last = k + 1 == batches.len();
            // Nothing to judge: a shard of a raced study runs every batch,
            // and a race with one design left only runs it to the end.
            let raced_out = race.as_ref().is_none_or(Race::decided);
            if stop_when.is_none() && (raced_out || last) {
                continue;
            }
            // Judge the batches so far on their own runs only.
            let mut pieces = earlier_table_pieces(&self.files.runs)?;
            pieces.extend(chunk_pieces(&self.files.chunks)?);
            let so_far = read_pieces_summary_columns(&pieces)?;
            let mask = so_far.column("sample_id")?.u32()?.lt(range.end);
            let judged = so_far.filter(&mask)?;
            if let Some(race) = race.as_mut().filter(|r| !last && !r.decided()) {
                let left = self.install(|| race.look(plan, k, range.end, &judged))?;
                // Runs that will not come: the later samples of the designs that left.
                if !left.is_empty() {
                    let remaining = u64::from(plan.file.sampling.samples - range.end);
                    self.progress.skip(remaining * left.len() as u64);
                }
            }
            if let Some(stop) = stop_when {
                let judged = match &race {
                    Some(race) => only_running(&judged, race)?,
                    None => judged,
                };
                let reached = self.install(|| precision(plan, stop, &judged))?;
                let stop_here = reached.reached || k + 1 == batches.len();
                adaptive = Some(AdaptiveOutcome {
                    batches: k + 1,
                    samples_per_design: range.end,
                    precision: reached,
                });
                if stop_here {
                    break;
                }
            }
        }
        Ok(Batched {
            executed,
            adaptive,
            race,
        })
    }

    /// Write runs.parquet from `pieces` (and, unsharded, summary.parquet);
    /// the rows written and the summary.
    fn write_tables(
        &self,
        pieces: Vec<Piece>,
        total: u64,
        provenance: &Provenance,
    ) -> Result<(u64, Option<DataFrame>), RunError> {
        let runs_path = &self.files.runs;
        let written = if total == 0 {
            // A shard whose slice of a small study holds no run is a shard all
            // the same: an empty table with the runs' columns, which `merge`
            // reads as such.
            let mut empty = crate::study::results::record::to_dataframe(&[])?;
            write_parquet(runs_path, &mut empty, provenance)?;
            0
        } else {
            write_runs(&pieces, self.plan.total_runs(), runs_path, provenance)?
        };
        drop(pieces);
        let summary = if self.options.shard.is_none() {
            let table = read_summary_columns(runs_path)?;
            let mut summary = self.install(|| summarize_table(self.plan, &table))?;
            let found =
                self.install(|| causes::test_and_append(self.plan, &table, &mut summary))?;
            write_parquet(&self.files.summary, &mut summary, provenance)?;
            causes::write_or_remove(&self.files.causes, found.as_ref(), provenance)?;
            Some(summary)
        } else {
            None
        };
        Ok((written, summary))
    }
}
