//! General-purpose statistics, each defined once: quantiles and the median
//! ([`quantile`]).
//!
//! Nothing here knows about rotors or studies; the analyses (`study`,
//! `check`, `optimize`, `plot`, `tradeoff`) bring the data.

pub mod quantile;
