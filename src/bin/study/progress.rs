//! How `study run` shows that it is alive: a progress bar on a terminal, a
//! line every few seconds in a batch log (stderr not a terminal: a Slurm or
//! Kubernetes log would otherwise show nothing until the end), nothing with
//! `--quiet`.

use autobal::study::results::record::RunRecord;
use autobal::study::run::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Where progress goes.
pub enum Reporter {
    /// indicatif bar on a terminal.
    Bar(ProgressBar),
    /// One line on stderr every `every`.
    Log {
        /// Time between two lines.
        every: Duration,
        /// When the run began, and when the last line was printed.
        clock: Mutex<(Instant, Instant)>,
    },
    /// Nothing.
    Quiet,
}

/// Counters shared by the worker threads, and the reporter.
pub struct RunProgress {
    reporter: Reporter,
    total: AtomicU64,
    /// Runs finished before this invocation (a resumed run).
    earlier: AtomicU64,
    done: AtomicU64,
    settled: AtomicU64,
    /// Runs a certified hold ended early (`metrics.certified_hold`).
    certified: AtomicU64,
    failures: AtomicU64,
}

impl RunProgress {
    /// A bar when stderr is a terminal, else log lines every `every`;
    /// nothing when `quiet`.
    pub fn new(quiet: bool, every: Duration) -> Self {
        let reporter = if quiet {
            Reporter::Quiet
        } else if std::io::stderr().is_terminal() {
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template(
                    "{elapsed_precise} {wide_bar} {pos}/{len} runs  {rate}  ETA {eta}  {msg}",
                )
                .expect("valid template")
                // indicatif's {per_sec} prints "581.5896/s".
                .with_key(
                    "rate",
                    |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                        let _ = write!(w, "{}", rate_text(state.per_sec()));
                    },
                ),
            );
            Reporter::Bar(bar)
        } else {
            let now = Instant::now();
            Reporter::Log {
                every,
                clock: Mutex::new((now, now)),
            }
        };
        RunProgress {
            reporter,
            total: AtomicU64::new(0),
            earlier: AtomicU64::new(0),
            done: AtomicU64::new(0),
            settled: AtomicU64::new(0),
            certified: AtomicU64::new(0),
            failures: AtomicU64::new(0),
        }
    }

    /// "done/total runs (p %), r runs/s, ETA …, settled s % so far, failures f".
    fn line(&self, elapsed: Duration) -> String {
        let total = self.total.load(Ordering::Relaxed);
        let earlier = self.earlier.load(Ordering::Relaxed);
        let done = self.done.load(Ordering::Relaxed);
        let settled = self.settled.load(Ordering::Relaxed);
        let finished = earlier + done;
        let rate = done as f64 / elapsed.as_secs_f64().max(1e-9);
        let eta = if rate > 0.0 {
            hms((total.saturating_sub(finished)) as f64 / rate)
        } else {
            "–".into()
        };
        let settled_share = if done > 0 {
            format!("{:.1} %", 100.0 * settled as f64 / done as f64)
        } else {
            "–".into()
        };
        format!(
            "progress: {finished}/{total} runs ({:.1} %), {}, elapsed {}, ETA {eta}, settled {settled_share} so far, failures {}",
            100.0 * finished as f64 / total.max(1) as f64,
            rate_text(rate),
            hms(elapsed.as_secs_f64()),
            self.failures.load(Ordering::Relaxed)
        )
    }
}

/// A rate of runs as people read it: "581 runs/s", "1.3 runs/s" (a tenth
/// below ten, so that 1.29 is not read as 1), or below one run a second
/// "12.3 s/run" (a slow study would otherwise show "0 runs/s").
pub fn rate_text(runs_per_second: f64) -> String {
    if runs_per_second >= 9.95 {
        format!("{runs_per_second:.0} runs/s")
    } else if runs_per_second >= 0.95 {
        format!("{runs_per_second:.1} runs/s")
    } else if runs_per_second > 0.0 && runs_per_second.is_finite() {
        format!("{:.1} s/run", 1.0 / runs_per_second)
    } else {
        "– s/run".into()
    }
}

/// Seconds as h:mm:ss.
fn hms(seconds: f64) -> String {
    let s = seconds.round() as u64;
    format!("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
}

impl Progress for RunProgress {
    fn begin(&self, total: u64, done: u64) {
        self.total.store(total, Ordering::Relaxed);
        self.earlier.store(done, Ordering::Relaxed);
        if let Reporter::Bar(bar) = &self.reporter {
            bar.set_length(total);
            bar.set_position(done);
            bar.set_message("failures 0");
        }
    }

    fn advance(&self, record: &RunRecord) {
        self.done.fetch_add(1, Ordering::Relaxed);
        if record.metrics.settled {
            self.settled.fetch_add(1, Ordering::Relaxed);
        }
        if record.metrics.hold_certified {
            self.certified.fetch_add(1, Ordering::Relaxed);
        }
        // The same failures as the ranking's "failed" column and the advice.
        let failed = record.metrics.outcome.is_failure();
        if failed {
            self.failures.fetch_add(1, Ordering::Relaxed);
        }
        match &self.reporter {
            Reporter::Bar(bar) => {
                if failed {
                    let f = self.failures.load(Ordering::Relaxed);
                    bar.set_message(format!("failures {f}"));
                }
                bar.inc(1);
            }
            Reporter::Log { every, clock } => {
                // try_lock: a worker never waits for another one's printing.
                if let Ok(mut clock) = clock.try_lock() {
                    let now = Instant::now();
                    if now - clock.1 >= *every {
                        clock.1 = now;
                        eprintln!("{}", self.line(now - clock.0));
                    }
                }
            }
            Reporter::Quiet => {}
        }
    }

    fn skip(&self, runs: u64) {
        // Designs that left the race: their later runs will not come, so
        // the bar, the rate line and the ETA count to what is left.
        let total = self.total.load(Ordering::Relaxed).saturating_sub(runs);
        self.total.store(total, Ordering::Relaxed);
        if let Reporter::Bar(bar) = &self.reporter {
            bar.set_length(total);
        }
    }

    fn interrupted(&self, _finished: u64, _total: u64) {
        // The error that follows is the one line that says so: no
        // "finished" line may come before it.
        if let Reporter::Bar(bar) = &self.reporter {
            bar.finish_and_clear();
        }
    }

    fn end(&self) {
        let start = match &self.reporter {
            Reporter::Quiet => return,
            Reporter::Bar(bar) => {
                bar.finish_and_clear();
                Instant::now() - bar.elapsed()
            }
            Reporter::Log { clock, .. } => clock.lock().map_or_else(|e| e.into_inner().0, |c| c.0),
        };
        // The same closing line on a terminal as in a batch log.
        let elapsed = start.elapsed();
        let done = self.done.load(Ordering::Relaxed);
        let settled = self.settled.load(Ordering::Relaxed);
        let certified = self.certified.load(Ordering::Relaxed);
        let early = if certified > 0 {
            format!(
                " ({:.1} % ended early: their hold window proved settled before it ran out, docs/metrics.md)",
                100.0 * certified as f64 / done.max(1) as f64
            )
        } else {
            String::new()
        };
        let earlier = self.earlier.load(Ordering::Relaxed);
        let line = if done == 0 {
            // A resumed study that was already complete: no rate to give.
            format!(
                "already complete: all {earlier} runs were finished earlier; nothing left to run"
            )
        } else {
            format!(
                "finished: {} runs in {} ({}), settled {:.1} %{early}, failures {}",
                done,
                hms(elapsed.as_secs_f64()),
                rate_text(done as f64 / elapsed.as_secs_f64().max(1e-9)),
                100.0 * settled as f64 / done.max(1) as f64,
                self.failures.load(Ordering::Relaxed)
            )
        };
        eprint!(
            "{}",
            crate::output::wrap(&line, crate::output::text_width())
        );
    }
}

#[cfg(test)]
mod tests {
    use super::rate_text;

    #[test]
    fn a_rate_below_one_run_a_second_is_given_in_seconds_per_run() {
        assert_eq!(rate_text(581.6), "582 runs/s");
        assert_eq!(rate_text(1.0), "1.0 runs/s");
        assert_eq!(rate_text(1.29), "1.3 runs/s");
        assert_eq!(rate_text(9.96), "10 runs/s");
        assert_eq!(rate_text(1.0 / 12.3), "12.3 s/run");
        assert_eq!(rate_text(0.0), "– s/run");
    }
}
