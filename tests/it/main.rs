//! autobal's integration tests, linked into one binary to keep builds fast.

mod bench;
mod check;
mod cli_design;
mod cli_simulate;
mod design_capacity;
mod design_transient;
mod integrate;
mod model_conservation;
mod model_physics;
mod study_input;
mod study_runner;
mod study_summary;
