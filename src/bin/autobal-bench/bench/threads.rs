//! How `run_study` scales with its thread count on a fixed small study,
//! with the CPU time the study actually got (a shared machine lends cores).

use super::median;
use autobal::study::plan::config::{StudyFile, StudyPlan};
use autobal::study::results::record::RunRecord;
use autobal::study::run::{NoProgress, RunError, RunOptions, run_study};
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// The study behind the thread-scaling measurement (`studies/three_balls.toml`,
/// with its samples cut down by [`ThreadConfig::samples`]).
pub const THREAD_STUDY: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/studies/three_balls.toml"
));

/// How the thread-scaling measurement runs [`THREAD_STUDY`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThreadConfig {
    /// Samples per design (the file's 20 designs each get this many runs).
    pub samples: u32,
    /// Thread counts to compare; the first is the baseline of the speed-ups.
    pub thread_counts: Vec<usize>,
    /// Timed studies per thread count, interleaved (ABBA order).
    pub repeats: usize,
}

impl ThreadConfig {
    /// The measurement recorded in `docs/benchmarks.md`: 1 against 2 threads.
    pub fn full() -> Self {
        ThreadConfig {
            samples: 25,
            thread_counts: vec![1, 2],
            repeats: 7,
        }
    }

    /// One sample per design and one repeat (tests, smoke runs).
    pub fn quick() -> Self {
        ThreadConfig {
            samples: 1,
            repeats: 1,
            ..ThreadConfig::full()
        }
    }
}

/// Wall times of the study at one thread count.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThreadTiming {
    /// Worker threads of the study's pool.
    pub threads: usize,
    /// Every timed study (s), in the order measured.
    pub times_s: Vec<f64>,
    /// Median wall time (s).
    pub median_s: f64,
    /// Fastest study (s).
    pub min_s: f64,
    /// Speed-up over the baseline: ratio of medians.
    pub speedup: f64,
    /// Speed-up over the baseline: median of the per-round ratios (robust to drifting load).
    pub paired_speedup: f64,
    /// Speed-up over the baseline: ratio of the fastest studies.
    pub speedup_min: f64,
    /// CPU time (user + system, all threads) of every timed study (s); empty where unknown.
    pub cpu_s: Vec<f64>,
    /// Median over the studies of CPU time / wall time: the cores the study
    /// actually got (at most `threads`; less when other processes hold cores).
    pub cores_used: Option<f64>,
}

/// How `run_study` scales with its thread count on a fixed small study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThreadScaling {
    /// What was asked.
    pub config: ThreadConfig,
    /// True for a build with debug assertions (timings then mean little).
    pub debug_build: bool,
    /// Name of the study.
    pub study: String,
    /// Designs in the study.
    pub designs: usize,
    /// Runs per study (designs × samples).
    pub runs: u64,
    /// RHS calls summed over the runs (the work, identical for every thread count).
    pub rhs_calls: u64,
    /// Threads the operating system offers this process.
    pub available_parallelism: usize,
    /// Load averages (1, 5, 15 min) before measuring (Linux only).
    pub load_before: Option<[f64; 3]>,
    /// Load averages after measuring.
    pub load_after: Option<[f64; 3]>,
    /// True when every thread count produced the same records (wall time aside).
    pub identical_results: bool,
    /// One entry per thread count, in the order asked.
    pub timings: Vec<ThreadTiming>,
}

/// The cut-down [`THREAD_STUDY`] writing under `output`.
pub fn thread_study(samples: u32, output: &Path) -> StudyPlan {
    edited_main_job(samples, output, "--thread-scaling", |_| {})
}

/// The main job with `samples` per design, its output under `output`, and
/// `edit` applied; the provenance text names the `verb` and the changes,
/// so the files are not mistaken for the real study's.
pub fn edited_main_job(
    samples: u32,
    output: &Path,
    verb: &str,
    edit: impl FnOnce(&mut StudyFile),
) -> StudyPlan {
    let path = "studies/three_balls.toml";
    let mut file = StudyFile::parse(THREAD_STUDY, path).expect("the bundled study parses");
    file.sampling.samples = samples.max(1);
    file.output = output.display().to_string();
    let bundled = file.clone();
    edit(&mut file);
    let mut note = format!("sampling.samples = {}", file.sampling.samples);
    if file.metrics != bundled.metrics {
        note += &format!(", metrics = {:?}", file.metrics);
    }
    let text = format!("{THREAD_STUDY}\n# autobal-bench {verb}: {note}\n");
    file.plan(&text, path).expect("the bundled study is valid")
}

/// Run [`thread_study`] at every thread count of `config`, interleaved, with
/// its files under `output` (overwritten by every repeat).
pub fn measure_threads(config: &ThreadConfig, output: &Path) -> Result<ThreadScaling, RunError> {
    let plan = thread_study(config.samples, output);
    let counts = &config.thread_counts;
    let repeats = config.repeats.max(1);
    let load_before = load_average();
    let mut times = vec![Vec::with_capacity(repeats); counts.len()];
    let mut cpu = vec![Vec::with_capacity(repeats); counts.len()];
    let mut records: Vec<Option<Vec<RunRecord>>> = vec![None; counts.len()];
    for round in 0..repeats {
        // ABBA: a drifting background load then favours no thread count.
        let order: Vec<usize> = if round % 2 == 0 {
            (0..counts.len()).collect()
        } else {
            (0..counts.len()).rev().collect()
        };
        for i in order {
            let options = RunOptions {
                threads: Some(counts[i].max(1)),
                overwrite: true,
                ..RunOptions::default()
            };
            let cpu_start = process_cpu_seconds();
            let start = Instant::now();
            let out = run_study(&plan, &options, &NoProgress)?;
            times[i].push(start.elapsed().as_secs_f64());
            if let (Some(a), Some(b)) = (cpu_start, process_cpu_seconds()) {
                cpu[i].push(b - a);
            }
            if records[i].is_none() {
                let mut runs = out.load_runs()?;
                for r in &mut runs {
                    r.wall_time_s = 0.0;
                }
                records[i] = Some(runs);
            }
        }
    }
    let load_after = load_average();
    let base = &times[0];
    let base_median = median(base);
    let base_min = base.iter().copied().fold(f64::INFINITY, f64::min);
    let timings = counts
        .iter()
        .zip(&times)
        .zip(cpu)
        .map(|((&threads, t), cpu_s)| {
            let min_s = t.iter().copied().fold(f64::INFINITY, f64::min);
            let paired: Vec<f64> = base.iter().zip(t).map(|(b, x)| b / x).collect();
            ThreadTiming {
                threads,
                times_s: t.clone(),
                median_s: median(t),
                min_s,
                speedup: base_median / median(t),
                paired_speedup: median(&paired),
                speedup_min: base_min / min_s,
                cores_used: (cpu_s.len() == t.len())
                    .then(|| median(&cpu_s.iter().zip(t).map(|(c, w)| c / w).collect::<Vec<_>>())),
                cpu_s,
            }
        })
        .collect();
    let first = records[0].as_deref().unwrap_or_default();
    Ok(ThreadScaling {
        config: config.clone(),
        debug_build: cfg!(debug_assertions),
        study: plan.name.clone(),
        designs: plan.designs.len(),
        runs: plan.total_runs(),
        rhs_calls: first.iter().map(|r| r.metrics.rhs_calls).sum(),
        available_parallelism: std::thread::available_parallelism().map_or(1, usize::from),
        load_before,
        load_after,
        identical_results: records.iter().all(|r| r.as_deref() == Some(first)),
        timings,
    })
}

/// CPU time (user + system) of this process and all its threads so far, in
/// seconds, from `/proc/self/stat` (`None` elsewhere). Resolution is one
/// clock tick, 10 ms at the usual 100 Hz, which is assumed: reading the real
/// rate would need libc.
pub fn process_cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The command name may contain spaces; fields after it start at field 3 (state).
    let rest = &text[text.rfind(')')? + 1..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<f64>().ok();
    Some((ticks(11)? + ticks(12)?) / 100.0)
}

/// The 1, 5 and 15 minute load averages from `/proc/loadavg` (`None` elsewhere).
pub fn load_average() -> Option<[f64; 3]> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    let mut it = text.split_whitespace().map(|s| s.parse::<f64>().ok());
    Some([it.next()??, it.next()??, it.next()??])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thread_scaling_reports_every_thread_count_with_identical_results() {
        let dir = tempfile::tempdir().unwrap();
        let config = ThreadConfig {
            samples: 1,
            thread_counts: vec![1, 2],
            repeats: 2,
        };
        let r = measure_threads(&config, dir.path()).unwrap();
        assert_eq!(r.runs, r.designs as u64);
        assert!(r.designs >= 2 && r.rhs_calls > 0);
        assert!(r.identical_results);
        let threads: Vec<usize> = r.timings.iter().map(|t| t.threads).collect();
        assert_eq!(threads, [1, 2]);
        for t in &r.timings {
            assert_eq!(t.times_s.len(), 2);
            assert!(t.median_s > 0.0 && t.speedup.is_finite() && t.paired_speedup.is_finite());
            if cfg!(target_os = "linux") {
                assert_eq!(t.cpu_s.len(), 2);
                assert!(t.cores_used.is_some_and(|c| c >= 0.0));
            }
        }
        assert_eq!(r.timings[0].speedup, 1.0);
    }
}
