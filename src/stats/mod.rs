//! General-purpose statistics, each defined once: quantiles and the median
//! ([`quantile`]), intervals of a proportion ([`interval`]), the bootstrap
//! ([`bootstrap`]), and the two-sample tests and multiple-testing correction
//! that regression checks are built from ([`ks`], [`proportion`], [`mood`],
//! [`holm`]), censoring-aware settling statistics ([`survival`]: Kaplan–Meier,
//! its median and restricted mean) and paired comparisons of designs that
//! share their samples ([`paired`]: win shares, sign and signed-rank tests),
//! the rank correlation of two rankings ([`kendall`]), the spending of
//! a level over repeated looks at growing data ([`spending`]), and
//! variance-based sensitivity indices by pick-freeze ([`sobol_indices`]).
//!
//! Nothing here knows about rotors or studies; the analyses (`study`,
//! `check`, `optimize`, `plot`, `tradeoff`) bring the data.

pub mod bootstrap;
pub mod holm;
pub mod interval;
pub mod kendall;
pub mod ks;
pub mod mood;
pub mod paired;
pub mod paired_measures;
pub mod proportion;
pub mod quantile;
pub mod sobol_indices;
pub mod spending;
pub mod survival;
#[cfg(test)]
pub(crate) mod test_stream;
