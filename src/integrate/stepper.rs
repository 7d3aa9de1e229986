//! What a single-step method must provide so that the one driver
//! ([`super::driver`]) can run it: a trial step with its error estimate and
//! step-size proposal, the commit of an accepted step with its dense output,
//! and (for explicit methods) the stiffness indicator and check.
//!
//! A stepper owns no loop, no budget, no observer and no end-of-interval
//! logic: those are the driver's, written once for every method.

use super::{DenseOutput, Failure, Method, OdeSystem, SolverOptions, Stats};

/// The verdict on one trial step.
#[derive(Debug, Clone, PartialEq)]
pub enum Trial {
    /// The error is within tolerance; `h_new` is the controller's proposal
    /// for the next step (before the driver's limits).
    Accepted {
        /// Proposed next step size.
        h_new: f64,
    },
    /// The step must be retried with `h_new`.
    Rejected {
        /// Step size to retry with.
        h_new: f64,
    },
    /// The method cannot continue (e.g. a non-finite state, Newton failures).
    Failed(Failure),
}

/// One step of a Runge–Kutta-type method with error control.
///
/// The driver calls, per run: [`Stepper::start`] once, then per step
/// [`Stepper::attempt`] until a trial is accepted, then [`Stepper::accept`];
/// if the run goes on, [`Stepper::advance`] and [`Stepper::next_step`].
pub trait Stepper: Sized {
    /// The method this stepper implements.
    const METHOD: Method;
    /// Implicit methods need no stiffness watch and are what explicit ones hand over to.
    const IMPLICIT: bool = false;

    /// A stepper for a system of `dim` components with these options; every
    /// work vector is allocated here, once for the whole run.
    fn new(dim: usize, options: &SolverOptions) -> Self;

    /// Set up at (t0, y0) and return the first step size (`options.h0` or an
    /// automatic guess no larger than `h_max`).
    fn start<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t0: f64,
        y0: &[f64],
        h_max: f64,
        stats: &mut Stats,
    ) -> Result<f64, Failure>;

    /// Factor f in the driver's end test t + f·h ≥ t_end: a step that would
    /// stop just short of t_end is stretched to reach it (Hairer's explicit
    /// codes use 1.01).
    fn end_stretch(&self) -> f64 {
        1.01
    }

    /// Try a step of size `h` from (t, y).
    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> Trial;

    /// Hairer's bound on [`Stepper::stiffness_indicator`]: where the
    /// method's stability region ends on the negative real axis.
    const STIFF_BOUND: f64 = f64::INFINITY;

    /// After an accepted trial of size `h`: Hairer's indicator h·|λ|, which
    /// says whether the step size was held by stability rather than
    /// accuracy. Implicit methods, which have no such limit, say 0.
    fn stiffness_indicator(&self, _h: f64) -> f64 {
        0.0
    }

    /// After an accepted trial of size `h` ending at `t_new`: an estimate
    /// of h·ρ(J) there by power iteration ([`super::stiffness::PowerProbe`]),
    /// which may stop once it exceeds `enough`. Implicit methods say 0.
    fn power_check<S: OdeSystem + ?Sized>(
        &mut self,
        _system: &S,
        _t_new: f64,
        _h: f64,
        _enough: f64,
        _stats: &mut Stats,
    ) -> f64 {
        0.0
    }

    /// Commit the accepted trial from (t, y) of size `h`: overwrite `y` with
    /// the new state and prepare the dense output over [t, t + h].
    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        h: f64,
        y: &mut Vec<f64>,
        stats: &mut Stats,
    ) -> Result<(), Failure>;

    /// The interpolant over the last accepted step.
    fn dense(&self) -> &dyn DenseOutput;

    /// Work needed at the new point before the next step, once the run goes
    /// on (e.g. the implicit method's f(t, y)); explicit FSAL methods have it.
    fn advance<S: OdeSystem + ?Sized>(
        &mut self,
        _system: &S,
        _t: f64,
        _y: &[f64],
        _stats: &mut Stats,
    ) -> Result<(), Failure> {
        Ok(())
    }

    /// The next step size, given the one just taken (`h`) and the driver's
    /// limited proposal (`h_next`); `reaches_end` says that `h_next` would
    /// reach t_end. A method that reuses factorisations may keep `h`.
    fn next_step(&mut self, _h: f64, h_next: f64, _reaches_end: bool) -> f64 {
        h_next
    }
}
