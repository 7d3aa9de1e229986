//! The benchmark's own command-line numbers, checked as the study
//! binary's are (`limits`): the message names the flag, the value and the
//! limit (exit code 2).

use crate::limits::{MAX_BENCH_REVOLUTIONS, number_in, whole_in};

/// Most repeats of a timed bench case.
pub const MAX_REPEATS: usize = 10_000;

/// `--revolutions`: a horizon in (0, [`MAX_BENCH_REVOLUTIONS`]].
pub fn bench_revolutions(text: &str) -> Result<f64, String> {
    number_in(
        text,
        "horizon of each solve in revolutions",
        MAX_BENCH_REVOLUTIONS,
    )
}

/// `--repeats`: 1 ..= [`MAX_REPEATS`].
pub fn repeats(text: &str) -> Result<usize, String> {
    whole_in(text, "timed repeats per case", 1, MAX_REPEATS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_horizon_and_repeats_refuse_their_extremes() {
        for bad in ["-1", "nan", "inf", "0", "1e300"] {
            assert!(bench_revolutions(bad).is_err(), "{bad}");
        }
        assert!(repeats("0").is_err());
        assert!(repeats("10001").unwrap_err().contains("1..=10000"));
        assert_eq!(repeats("21"), Ok(21));
    }
}
