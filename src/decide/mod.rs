//! The decision: what turns a study's runs and summaries into which design to
//! build, or why none. Used by the runner (racing, the summary), the CLI, the
//! report and the claims; uses the study's plan and results, never the runner.
//!
//! - [`measure`]: a criterion measured on a design's runs, and two designs compared on it.
//! - [`verdict`]: which design settles sooner: paired, censoring-aware, Holm-corrected.
//! - [`decision`]: which design to build, or why none, typed, as `summary.parquet` records it.
//! - [`diagnosis`]: why no design balances, when none does.
//! - [`causes`]: why runs do not settle, as re-runs without each effect tell.
//! - [`plane_summary`]: per-plane parts and causes of a two-plane design.
//! - [`robustness`]: whether #1 stays #1 in every third of each uncertain key's range.
//! - [`failures`]: runs that did not finish, and the setting to change.
//! - [`compare_designs`]: two designs of one or two results folders (`study compare`).

pub mod causes;
pub mod compare_designs;
pub mod decision;
pub mod diagnosis;
pub mod failures;
pub mod measure;
pub mod plane_summary;
pub mod robustness;
pub mod verdict;
