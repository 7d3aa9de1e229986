//! The study runner: TOML studies → Monte Carlo on all cores → polars
//! statistics → Parquet, in three rooms, each using only the ones before it
//! (and [`crate::decide`], which sits between the results and the runner):
//!
//! - [`plan`]: the study file — its schema, validation, the resolved plan
//!   and everything drawn from it (distributions, streams, per-run samples).
//! - [`results`]: what runs leave — the runs record, the runs file, Parquet
//!   with provenance, each design's runs as statistics count them.
//! - [`run`]: the runner — executor, racing, adaptive stop, aggregation into
//!   `summary.parquet`, shards and merge, the folder's lock.
//!
//! The verbs built on the runner for one scene or one question:
//! - [`sensitivity`]: Sobol indices of the measures over every sampled input (`study sensitivity`).
//! - [`sweep`]: one scene over a grid of speeds, with criterion and linear stability.
//! - [`stability_map`]: linear stability over (speed, unbalance).
//! - [`stepped_bands`]: a stepped sweep over draws of a scene's uncertain keys: bands and onsets.

pub mod plan;
pub mod results;
pub mod run;
pub mod sensitivity;
pub mod stability_map;
pub mod stepped_bands;
pub mod sweep;
