//! # autobal: design passive auto-balancers by virtual experiment
//!
//! autobal answers the question engineers ask when they put an auto-balancer
//! (balls, rollers or pendulums running in a race on a rotor) into a washing
//! machine, centrifuge, optical drive or grinder: how many weights, of what
//! radius, balance the rotor fastest and best over every unbalance it meets?
//!
//! ## Data flow
//! - [`design`]: the analytic theory (capacity, optimal radius, transient
//!   measures, seed 003's criterion) — pure functions, microseconds.
//! - [`model`]: what is simulated — a [`model::scene::Scene`] of rotor,
//!   balancers, speed law and effects, assembled into an ODE system.
//! - [`integrate`]: how — DP5, DOP853, Radau5 behind one `solve`, with dense
//!   output and step observers.
//! - [`metrics`]: what a run means — settling time, residual vibration,
//!   outcome — defined once.
//! - [`simulation`]: one run at a chosen fidelity; [`uncertain`]: scene keys
//!   nobody measured exactly, as distributions written into a run's scene.
//! - [`study`]: many runs on all cores, statistics with polars, Parquet, in
//!   three rooms: the study file ([`study::plan`]), what runs leave
//!   ([`study::results`]) and the runner ([`study::run`]).
//! - [`decide`]: summaries into a decision — criteria measured, verdicts,
//!   diagnosis, the typed decision — used by the runner, the CLI and the report.
//! - Analyses on top: [`optimize`], [`claims`], [`tradeoff`], [`check`], [`plot`],
//!   sharing one set of statistics ([`stats`]).
//!
//! Start reading at [`simulation::Simulation::run`] and [`study::run::run_study`].
//!
//! The library never prints: the `study` binary is a thin layer that parses
//! arguments, calls the library and formats the results.

// Index loops mirror the equations' subscripts (A[r][c], w_i); iterator
// chains over several parallel arrays would hide them.
#![allow(clippy::needless_range_loop)]

pub mod build_info;
pub mod calibrate;
pub mod check;
pub mod claims;
pub mod decide;
pub mod design;
pub mod input_file;
pub mod integrate;
pub mod invalid_key;
pub mod metrics;
pub mod model;
pub mod number_text;
pub mod optimize;
pub mod output_file;
pub mod pair;
pub mod plot;
pub mod report;
pub mod scene_file;
pub mod schema;
pub mod simulation;
pub mod stats;
pub mod study;
pub mod text;
pub mod tradeoff;
pub mod uncertain;
