//! autobal's integration tests, linked into one binary to keep builds fast.

mod bench;
mod check;
mod claims;
mod cli_design;
mod cli_simulate;
mod contact;
mod design_capacity;
mod design_criterion;
mod design_transient;
mod extremes;
mod fixtures;
mod golden;
mod integrate;
mod model_conservation;
mod model_flexible;
mod model_linear;
mod model_physics;
mod model_two_support;
mod optimize;
mod plot;
mod study_input;
mod study_runner;
mod study_summary;
mod study_sweep;
mod toy_effect;
mod tradeoff;
