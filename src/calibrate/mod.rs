//! Rigs as evidence: fit a scene's unknowns (a rolling resistance, a drag,
//! the direction of a race's eccentricity, a stiffness) to points measured
//! on a physical rig, give their intervals, and predict the points held out
//! of the fit with bands. The layer above the one-run simulator: it builds
//! scenes and runs them (a run or a stepped sweep per case) and knows
//! nothing of studies, designs or printing.
//!
//! - [`rig_file`]: the measured points, the cases, the protocol, the unknowns;
//! - [`problem`]: what the model predicts for each point (what is computed);
//! - [`misfit`]: the robust loss and the standardised residuals;
//! - [`fit`]: Nelder–Mead with restarts (how the loss is minimised);
//! - [`posterior`]: importance sampling with a defensive mixture (intervals);
//! - [`calibration`]: the steps in order, and the synthetic-rig coverage check;
//! - [`tables`]: the results as tables.

pub mod calibration;
pub mod fit;
pub mod misfit;
pub mod posterior;
pub mod problem;
pub mod rig_file;
pub mod tables;
