//! The study file: its schema and validation, the resolved plan, and what
//! is drawn from it per run. Uses nothing of the study's other rooms: a plan
//! is checked and resolved before anything runs.
//!
//! - [`config`]: the study file schema, validation and the resolved plan.
//! - [`criterion`]: what "best" means, as the study file states it.
//! - [`design`]: one resolved design of the grid, and the grid's one-or-many values.
//! - [`plane_designs`]: per-plane designs of a two-plane rotor.
//! - [`couple`]: the couple unbalance of a two-plane rotor, sampled per run.
//! - [`tolerance`]: manufacturing tolerances of the weights, sampled per run.
//! - [`optimize_spec`]: the `[optimize]` table.
//! - [`distribution`]: the `[sampling]` distributions (unbalance, direction, start).
//! - [`truncated`]: truncated normal draws.
//! - [`stream`]: the per-run random streams, one per (seed, design, sample, purpose).
//! - [`sample`]: the draws of one run (unbalance, direction, start angles).
//! - [`tie_break`]: how the part is chosen among designs the data cannot tell apart.

pub mod config;
pub mod couple;
pub mod criterion;
pub mod design;
pub mod distribution;
pub mod optimize_spec;
pub mod plane_designs;
pub mod sample;
pub mod stream;
pub mod tie_break;
pub mod tolerance;
pub mod truncated;
