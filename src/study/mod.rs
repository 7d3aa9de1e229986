//! The study runner: TOML studies → Monte Carlo on all cores → polars
//! statistics → Parquet.
//!
//! - [`config`]: the study file schema, validation and the resolved plan.
//! - [`distribution`]: the `[sampling]` distributions (unbalance, direction, start).
//! - [`design`]: one resolved design of the grid, and the grid's one-or-many values.
//! - [`stream`]: the per-run random streams, one per (seed, design, sample, purpose).
//! - [`sample`]: the draws of one run (unbalance, direction, start angles).
//! - [`tolerance`]: manufacturing tolerances of the weights, sampled per run.
//! - [`adaptive`]: sampling in batches until a requested precision.
//! - [`run`]: the executor (rayon, chunked writes, resume, shards).
//! - [`record`]: one row of `runs.parquet`.
//! - [`runs_file`]: `runs.parquet` assembled in run order with bounded memory.
//! - [`aggregate`]: per-design statistics (`summary.parquet`) with polars.
//! - [`measured_runs`]: a design's runs and their scale (τ, revolution), as criteria see them.
//! - [`criterion`]: what "best" means: the declared ranking criterion and its test.
//! - [`design_runs`]: each design's runs as the statistics count them (clock, τ).
//! - [`diagnosis`]: why no design balances, when none does.
//! - [`failures`]: runs that did not finish, and the setting to change.
//! - [`verdict`]: which design settles sooner: paired, censoring-aware, Holm-corrected.
//! - [`compare_designs`]: two designs of one or two results folders (`study compare`).
//! - [`summary_columns`]: typed access to `summary.parquet`'s columns.
//! - [`robustness`]: whether #1 stays #1 in every third of each uncertain key's range.
//! - [`decision`]: which design to build, or why none, typed, as `summary.parquet` records it.
//! - [`merge`]: combining shard outputs.
//! - [`sensitivity`]: Sobol indices of the measures over every sampled input (`study sensitivity`).
//! - [`study_folder`]: the study's folder as another verb's destination (tradeoff, optimize).
//! - [`io`]: Parquet with provenance, atomic writes.
//! - [`sweep`]: one scene over a grid of speeds, with criterion and linear stability.
//! - [`stability_map`]: linear stability over (speed, unbalance).
//! - [`stepped_bands`]: a stepped sweep over draws of a scene's uncertain keys: bands and onsets.

pub mod adaptive;
pub mod aggregate;
pub mod compare_designs;
pub mod config;
pub mod couple;
pub mod criterion;
pub mod decision;
pub mod design;
pub mod design_runs;
pub mod diagnosis;
pub mod distribution;
pub mod failures;
pub mod io;
pub mod lock;
pub mod measured_runs;
pub mod merge;
pub mod optimize_spec;
pub mod plane_designs;
pub mod plane_summary;
pub mod racing;
pub mod record;
pub mod results_table;
pub mod robustness;
pub mod run;
pub mod runs_file;
pub mod sample;
pub mod sensitivity;
pub mod stability_map;
pub mod stepped_bands;
pub mod stream;
pub mod study_folder;
pub mod summary_columns;
pub mod sweep;
pub mod tolerance;
pub mod truncated;
pub mod verdict;
