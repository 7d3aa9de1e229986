//! Command-line numbers with a range of their own, checked by clap while
//! the options are parsed: before any file is read or written, the same
//! rule on every verb, and the message names the flag, the value and the
//! limit (exit code 2).

/// Most runs held in memory before a chunk is written (each run is a few
/// hundred bytes to a few kilobytes, and twice this many may wait).
pub const MAX_CHUNK_RUNS: usize = 1_000_000;
/// Longest time between two progress lines (a year, in seconds).
pub const MAX_PROGRESS_SECONDS: f64 = 365.0 * 86_400.0;
/// Most points of a sweep or one axis of a map (each point is a whole run).
pub const MAX_POINTS: usize = 100_000;
/// Most points of a map (the product of its axes).
pub const MAX_MAP_POINTS: usize = 1_000_000;

/// A number in `lo..=hi` of a flag, or the reason it is not.
pub fn whole_in(text: &str, what: &str, lo: usize, hi: usize) -> Result<usize, String> {
    let n: usize = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a whole number ({what})"))?;
    if n < lo || n > hi {
        return Err(format!("{n} is outside {lo}..={hi} ({what})"));
    }
    Ok(n)
}

/// `--threads`: at least 1 (more than the cores are capped by
/// [`capped_threads`], with a warning).
pub fn threads(text: &str) -> Result<usize, String> {
    whole_in(text, "worker threads; at least one", 1, usize::MAX)
        .map_err(|why| format!("--threads {}: {why}", text.trim()))
}

/// The worker threads to use for `--threads asked`: at most the logical
/// cores here (a warning says so), `None` for rayon's default.
pub fn capped_threads(asked: Option<usize>) -> Option<usize> {
    let asked = asked?;
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    if asked > cores {
        eprintln!(
            "warning: --threads {asked} is more than the {cores} logical cores here; using {cores}"
        );
    }
    Some(asked.min(cores))
}

/// `--chunk-runs`: 1 ..= [`MAX_CHUNK_RUNS`].
pub fn chunk_runs(text: &str) -> Result<usize, String> {
    whole_in(
        text,
        "runs held before a chunk is written",
        1,
        MAX_CHUNK_RUNS,
    )
}

/// `--points` of a sweep: 2 ..= [`MAX_POINTS`].
pub fn sweep_points(text: &str) -> Result<usize, String> {
    whole_in(text, "speeds of the sweep, ends included", 2, MAX_POINTS)
}

/// A range flag `lo..hi` (finite hi > lo; lo > 0, or lo ≥ 0 when
/// `zero_allowed`), or the message naming `--flag`, with `example` if given.
pub fn range(
    flag: &str,
    text: &str,
    zero_allowed: bool,
    example: Option<&str>,
) -> Result<(f64, f64), String> {
    let bad = || {
        let bound = if zero_allowed {
            "0 ≤ lo < hi"
        } else {
            "0 < lo < hi"
        };
        let example = example.map(|e| format!(", e.g. {e}")).unwrap_or_default();
        format!("--{flag} {text}: expected lo..hi with {bound}{example}")
    };
    let (a, b) = text.split_once("..").ok_or_else(bad)?;
    let lo: f64 = a.trim().parse().map_err(|_| bad())?;
    let hi: f64 = b.trim().parse().map_err(|_| bad())?;
    let lo_ok = if zero_allowed { lo >= 0.0 } else { lo > 0.0 };
    if lo_ok && hi > lo && hi.is_finite() {
        Ok((lo, hi))
    } else {
        Err(bad())
    }
}

/// A speed range flag (`--omega` in rad/s, `--rpm`: `per_rad` units per
/// rad/s) whose ends are also spin rates a scene may name: refused here
/// naming the flag, not the scene key `speed.omega` each point becomes.
pub fn speed_range(
    flag: &str,
    text: &str,
    zero_allowed: bool,
    example: Option<&str>,
    per_rad: f64,
) -> Result<(f64, f64), String> {
    use autobal::model::validate::{MAX_SPIN_RATE, MIN_SPIN_RATE};
    let (lo, hi) = range(flag, text, zero_allowed, example)?;
    let inside = |v: f64| {
        (zero_allowed && v == 0.0) || (MIN_SPIN_RATE..=MAX_SPIN_RATE).contains(&(v / per_rad))
    };
    if inside(lo) && inside(hi) {
        Ok((lo, hi))
    } else {
        let unit = if per_rad == 1.0 { "rad/s" } else { "rpm" };
        Err(format!(
            "--{flag} {text}: each end must be a spin rate in [{}, {}] {unit}{} (outside it every run fails: no revolution completes, or the steps underflow)",
            crate::limits::short(MIN_SPIN_RATE * per_rad),
            crate::limits::short(MAX_SPIN_RATE * per_rad),
            if zero_allowed { ", or 0" } else { "" }
        ))
    }
}

/// A limit in a message: few digits, an exponent when large or small.
fn short(v: f64) -> String {
    if (1e-2..1e5).contains(&v) {
        format!("{}", (v * 1e4).round() / 1e4)
    } else {
        format!("{v:.3e}")
    }
}

/// `stepped --dwell`: seconds at each speed, in (0, one day].
pub fn dwell_seconds(text: &str) -> Result<f64, String> {
    number_in(text, "seconds held at each speed; a day at most", 86_400.0)
}

/// `stepped --step-rpm`: rpm between steps, in (0, 10⁶].
pub fn step_rpm(text: &str) -> Result<f64, String> {
    number_in(text, "rpm between two steps", 1e6)
}

/// `--progress-every`: seconds in (0, [`MAX_PROGRESS_SECONDS`]].
pub fn progress_seconds(text: &str) -> Result<f64, String> {
    number_in(
        text,
        "seconds between progress lines; a year at most",
        MAX_PROGRESS_SECONDS,
    )
}

/// Most samples per design a bench verb runs, or runs `study tradeoff` measures.
pub const MAX_BENCH_RUNS: usize = 1_000_000;
/// Longest horizon of a bench solve, in revolutions (as a study's `t_end_revs`).
pub const MAX_BENCH_REVOLUTIONS: f64 = 1e7;

/// A finite number in (0, `hi`], or the reason it is not.
pub fn number_in(text: &str, what: &str, hi: f64) -> Result<f64, String> {
    let v: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number ({what})"))?;
    if !(v > 0.0 && v <= hi) {
        return Err(format!(
            "{text}: must be above 0 and at most {hi:e} ({what})"
        ));
    }
    Ok(v)
}

/// `tradeoff --budget-revs`: a settling-time error in (0, 1e7] revolutions.
pub fn budget_revs(text: &str) -> Result<f64, String> {
    number_in(
        text,
        "settling-time error in revolutions",
        MAX_BENCH_REVOLUTIONS,
    )
}

/// `tradeoff --budget-residual`: a residual error in (0, 1e3] A_ref.
pub fn budget_residual(text: &str) -> Result<f64, String> {
    number_in(text, "residual error in units of A_ref", 1e3)
}

/// `bench --samples`, `tradeoff --runs`: 1 ..= [`MAX_BENCH_RUNS`].
pub fn bench_runs(text: &str) -> Result<usize, String> {
    whole_in(text, "runs", 1, MAX_BENCH_RUNS)
}

/// `--draws`: how many draws of a scene's uncertain keys (0: none).
pub fn draws(text: &str) -> Result<u32, String> {
    whole_in(text, "draws of the uncertain keys", 0, 100_000).map(|n| n as u32)
}

/// A significance level in (0, 0.5] (`study compare`).
pub fn significance(text: &str) -> Result<f64, String> {
    let v: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number"))?;
    if !(v > 0.0 && v <= 0.5) {
        return Err(format!(
            "{text}: a significance level in (0, 0.5], e.g. 0.05"
        ));
    }
    Ok(v)
}

/// A family-wise false-alarm level in (0, 1) (`study check`).
pub fn alpha(text: &str) -> Result<f64, String> {
    let v: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number"))?;
    if !(v > 0.0 && v < 1.0) {
        return Err(format!(
            "{text}: a false-alarm level strictly between 0 and 1, e.g. 0.01"
        ));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_range_refuses_its_extremes_and_names_the_limit() {
        assert!(threads("0").unwrap_err().contains("--threads 0"));
        assert_eq!(threads("2"), Ok(2));
        assert!(chunk_runs("18446744073709551615").is_err());
        assert!(
            sweep_points("18446744073709551615")
                .unwrap_err()
                .contains("2..=100000")
        );
        assert!(progress_seconds("1e300").unwrap_err().contains("a year"));
        assert!(progress_seconds("nan").is_err());
        assert_eq!(progress_seconds("30"), Ok(30.0));
        assert!(alpha("0").is_err() && alpha("nan").is_err() && alpha("1").is_err());
        assert_eq!(alpha("0.01"), Ok(0.01));
        for bad in ["-1", "nan", "inf", "0", "1e300"] {
            assert!(budget_residual(bad).is_err(), "{bad}");
            assert!(budget_revs(bad).is_err(), "{bad}");
        }
        assert!(bench_runs("0").is_err());
        assert!(
            bench_runs("4000000000")
                .unwrap_err()
                .contains("1..=1000000")
        );
        assert!(significance("0.6").is_err() && significance("nan").is_err());
        assert_eq!(significance("0.05"), Ok(0.05));
    }
}
