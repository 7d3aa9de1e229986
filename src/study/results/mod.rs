//! What runs leave: one row per run, the runs file in run order, Parquet
//! with provenance, and a design's runs as the statistics count them. Uses
//! the plan; knows nothing of decisions or of how runs are scheduled.
//!
//! - [`record`]: one row of `runs.parquet`.
//! - [`runs_file`]: `runs.parquet` assembled in run order with bounded memory.
//! - [`io`]: Parquet with provenance, atomic writes.
//! - [`results_table`]: a results table read back, its columns checked.
//! - [`summary_columns`]: typed access to `summary.parquet`'s columns.
//! - [`measured_runs`]: a design's runs and their scale (τ, revolution), as criteria see them.
//! - [`design_runs`]: each design's runs as the statistics count them (clock, τ).
//! - [`causes_file`]: `causes.parquet`, the counterfactual re-runs.

pub mod causes_file;
pub mod design_runs;
pub mod io;
pub mod measured_runs;
pub mod record;
pub mod results_table;
pub mod runs_file;
pub mod summary_columns;
