//! Statistical regression checks: does a study still produce what its
//! committed baseline recorded?
//!
//! Monte Carlo output is noisy, so the check is a set of hypothesis tests,
//! not a byte comparison: per design, a two-sample Kolmogorov–Smirnov test
//! on the settling times of settled runs ([`crate::stats::ks`]), Fisher's
//! exact test on the settled fraction ([`crate::stats::proportion`]) and
//! Mood's median test on residual vibration ([`crate::stats::mood`]); all
//! p-values of a study are corrected together with Holm's method
//! ([`crate::stats::holm`]) and judged in a verdict table ([`compare`]).
//!
//! - [`baseline`]: the baseline folder (runs, summary, manifest with provenance).
//! - [`samples`]: the per-design samples read from a runs table.
//! - [`study`]: record a baseline from a run; check a fresh run against one.
//! - [`plant`]: planted changes, to measure the check's false-alarm rate and power.
//!
//! `docs/regression-checks.md` explains the choices and the detectable drift.

pub mod baseline;
pub mod compare;
pub mod plant;
pub mod samples;
pub mod study;
