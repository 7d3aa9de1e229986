//! What racing's looks cost: the main job run once on every sample
//! (`racing = false`), then the race it makes replayed on those runs with
//! each look timed. A look reads the runs so far, pairs the designs, tests
//! the leader against each and, for the designs that may leave, bounds
//! their lead on every other reported measure; the replay makes the same
//! departures as the raced study (`Race::replay`), so the timings are the
//! looks' own, without the runs between them.

use super::median;
use super::threads::edited_main_job;
use autobal::study::run::adaptive::batches;
use autobal::study::run::racing::Race;
use autobal::study::run::{NoProgress, RunError, RunOptions, run_study};
use polars::prelude::*;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// One look of the replayed race.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LookCost {
    /// The look, counted from 1 (after that many batches).
    pub look: usize,
    /// Samples per design read at the look.
    pub samples: u32,
    /// Designs still in the race before the look.
    pub running: usize,
    /// Designs that left at the look.
    pub left: usize,
    /// Median wall time of the look over the repeats (ms).
    pub ms: f64,
}

/// The looks of the main job's race and what the race made.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LooksReport {
    /// True for a build with debug assertions (timings then mean little).
    pub debug_build: bool,
    /// Samples per design of the study.
    pub samples: u32,
    /// Runs of the study on every sample.
    pub runs_every_sample: usize,
    /// Runs the race makes.
    pub runs_raced: usize,
    /// Each look until the race ends.
    pub looks: Vec<LookCost>,
    /// The most expensive look (ms).
    pub max_ms: f64,
    /// The median look (ms).
    pub median_ms: f64,
}

/// Run the main job (`samples` per design, files under `output`) on every
/// sample, then replay its race `repeats` times, timing each look.
pub fn measure_looks(samples: u32, repeats: usize, output: &Path) -> Result<LooksReport, RunError> {
    let every = edited_main_job(samples, output, "--racing-looks", |f| {
        f.sampling.racing = false;
    });
    let raced = edited_main_job(samples, output, "--racing-looks", |_| {});
    let options = RunOptions {
        overwrite: true,
        ..RunOptions::default()
    };
    let out = run_study(&every, &options, &NoProgress)?;
    let runs = read_runs(&out.dir.join("runs.parquet"))?;
    let batches = batches(&raced);
    let sample = runs.column("sample_id")?.u32()?.clone();
    let mut timings: Vec<Vec<f64>> = Vec::new();
    let mut shape: Vec<(u32, usize, usize)> = Vec::new();
    let mut made = 0;
    for _ in 0..repeats.max(1) {
        let mut race = Race::new(&raced, &batches);
        shape.clear();
        for (k, batch) in batches.iter().enumerate().take(batches.len() - 1) {
            // What the raced study holds at the look: the runs it made so far.
            let judged = race.made(&runs.filter(&sample.lt(batch.end))?)?;
            let running = race.running_count();
            let start = Instant::now();
            let left = race.look(&raced, k, batch.end, &judged)?.len();
            let ms = 1e3 * start.elapsed().as_secs_f64();
            if timings.len() <= k {
                timings.push(Vec::new());
            }
            timings[k].push(ms);
            shape.push((batch.end, running, left));
            if race.decided() {
                break;
            }
        }
        made = race.made(&runs)?.height();
    }
    let looks: Vec<LookCost> = shape
        .iter()
        .zip(&timings)
        .enumerate()
        .map(|(k, (&(samples, running, left), ms))| LookCost {
            look: k + 1,
            samples,
            running,
            left,
            ms: median(ms),
        })
        .collect();
    let ms: Vec<f64> = looks.iter().map(|l| l.ms).collect();
    Ok(LooksReport {
        debug_build: cfg!(debug_assertions),
        samples,
        runs_every_sample: runs.height(),
        runs_raced: made,
        max_ms: ms.iter().copied().fold(0.0, f64::max),
        median_ms: median(&ms),
        looks,
    })
}

/// The runs table the study wrote.
fn read_runs(path: &Path) -> Result<DataFrame, RunError> {
    autobal::study::results::io::read_parquet(path).map_err(RunError::from)
}
