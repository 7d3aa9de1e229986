//! Statistical regression checks: does a study still produce what its
//! committed baseline recorded?
//!
//! Monte Carlo output is noisy, so the check is a set of hypothesis tests,
//! not a byte comparison: per design, a two-sample Kolmogorov–Smirnov test
//! on the settling times of settled runs ([`ks`]), Fisher's exact test on
//! the settled fraction ([`proportion`]) and Mood's median test on residual
//! vibration ([`median`]); all p-values of a study are corrected together
//! with Holm's method ([`holm`]) and judged in a verdict table ([`compare`]).
//!
//! - [`baseline`]: the baseline folder (runs, summary, manifest with provenance).
//! - [`samples`]: the per-design samples read from a runs table.
//! - [`study`]: record a baseline from a run; check a fresh run against one.
//!
//! `docs/regression-checks.md` explains the choices and the detectable drift.

pub mod baseline;
pub mod compare;
pub mod holm;
pub mod ks;
pub mod median;
pub mod proportion;
pub mod samples;
pub mod study;
