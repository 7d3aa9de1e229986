//! How an ODE is solved: a plain problem description, interchangeable
//! steppers behind one entry point, dense output and per-step observers.
//!
//! The shape follows SciPy's `solve_ivp` and diffsol: a [`OdeSystem`] says
//! what is computed (right-hand side, dimension); [`SolverOptions`] say how
//! accurately; a [`StepObserver`] watches every accepted step through its
//! dense output and may stop the run (early settling detection). [`solve`]
//! runs any [`Method`] and always returns a [`SolveReport`], also on failure,
//! so that a failed sample can be recorded with its reason and statistics.
//!
//! The steppers are written by hand: measured on the plane-rotor model, a lean
//! runtime-sized Dormand–Prince was faster than every Rust ODE crate tried, and
//! two of them had correctness bugs for time-dependent right-hand sides (see
//! `docs/integrators.md` for the numbers).

pub mod controller;
mod cost;
#[cfg(test)]
pub(crate) use cost::DEARER_BY;
pub mod dop853;
pub mod dp5;
mod driver;
pub mod events;
pub(crate) mod lu;
mod newton_matrices;
pub mod norm;
pub mod radau5;
pub mod stepper;
mod stiffness;
mod structured_newton;

pub use events::{EventFlow, Events};
pub use stepper::{Stepper, Trial};

use serde::{Deserialize, Serialize};

/// A first-order system y' = f(t, y) of fixed dimension.
pub trait OdeSystem {
    /// Number of state components.
    fn dim(&self) -> usize;
    /// Evaluate f(t, y) into `dydt` (same length as `y`); must not allocate.
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]);
    /// Write ∂f_i/∂y_j at (t, y) row-major into `jac[i·dim + j]` and return
    /// true, or return false (the default) to let implicit methods use
    /// finite differences.
    fn jacobian(&self, _t: f64, _y: &[f64], _jac: &mut [f64]) -> bool {
        false
    }
    /// Some(m) when dim = 2m and f_i(t, y) = y_{m+i} exactly for i < m (a
    /// second-order system in first-order form): implicit methods then solve
    /// m×m instead of 2m×2m Newton systems. None (the default) is always safe.
    fn second_order_split(&self) -> Option<usize> {
        None
    }
    /// For a second-order system: write how its accelerations couple at
    /// (t, y) into `out` and return true, or return false (the default) to
    /// let implicit methods use dense Newton matrices. A system that returns
    /// true once must do so for every state.
    fn coupling_structure(&self, _t: f64, _y: &[f64], _out: &mut CouplingStructure) -> bool {
        false
    }
    /// For a system with a [`CouplingStructure`]: write its head equation
    /// at (t, y), f(t, y) = `f`, into `out` and return true, or return false
    /// (the default) to let implicit methods take ∂z/∂(q, q̇) by directional
    /// differences of the right-hand side, which cost a call per use.
    fn head_equation(&self, _t: f64, _y: &[f64], _f: &[f64], _out: &mut HeadEquation) -> bool {
        false
    }
    /// The system's events ([`events`]): functions whose zero crossings
    /// the driver locates and lets the system act on. None (the default):
    /// a smooth system.
    fn events(&self) -> Option<&dyn Events> {
        None
    }
}

/// The head rows of a second-order system with a [`CouplingStructure`],
///
///   M_h·z + Σ_i e_i·a_i = F_h(q, q̇),
///
/// linearised in the ring coordinates: with it, implicit methods form
/// ∂z/∂(q, q̇) from the local Jacobian (whose differences they take anyway)
/// instead of taking it by extra right-hand-side calls. M_h, e_i and F_h may
/// depend on the state, but each ring coordinate's terms in
/// F_h − M_h·z − Σ e_i·a_i only on that coordinate and the head: forces
/// between weights reach the head through their accelerations alone.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HeadEquation {
    /// M_h at (t, y), row-major, head × head.
    pub mass: Vec<f64>,
    /// e_i, `head` entries per coordinate head..m, in coordinate order.
    pub reaction: Vec<f64>,
    /// ∂(F_h − M_h·z − Σ e_j·a_j)/∂q_i, then ∂/∂q̇_i, at fixed accelerations
    /// (z and a): 2·`head` entries per coordinate head..m, in coordinate order.
    pub own: Vec<f64>,
}

/// How the m accelerations a = q̈ of a second-order system couple: the first
/// `head` of them are coupling variables z (e.g. the rotor's), and every other
/// one reads a_i = l_i + Σ_r U_ir·z_r, where l_i depends only on the position
/// and velocity of coordinate i, of its two neighbours in its ring and of the
/// head coordinates. Weights on a race that touch only their neighbours and
/// feel each other only through the rotor have this form, and implicit
/// methods then form, factor and solve their Newton systems in O(m).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CouplingStructure {
    /// Number of head coordinates (the first ones of q).
    pub head: usize,
    /// U row-major, one row of `head` entries per coordinate head..m, in
    /// coordinate order.
    pub coupling: Vec<f64>,
    /// The coordinates head..m, ring after ring, each ring in its cyclic
    /// order (consecutive entries and its last and first are neighbours).
    pub order: Vec<usize>,
    /// One past the last position in `order` of each ring, increasing.
    pub ring_ends: Vec<usize>,
}

/// Continuous solution over the last accepted step, valid on [t_prev, t].
pub trait DenseOutput {
    /// Write the interpolated state at time `t` into `out`: its first
    /// `out.len()` components, so that a caller who needs only the leading
    /// ones (e.g. positions) pays only for them.
    fn eval(&self, t: f64, out: &mut [f64]);
}

/// What an observer sees after each accepted step.
pub struct Step<'a> {
    /// Start of the step.
    pub t_prev: f64,
    /// End of the step.
    pub t: f64,
    /// State at `t`.
    pub y: &'a [f64],
    /// Interpolant over [t_prev, t].
    pub dense: &'a dyn DenseOutput,
}

/// An observer's verdict after a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flow {
    /// Keep integrating.
    Continue,
    /// Stop now; the run ends with [`Status::Stopped`].
    Stop,
}

/// Watches the accepted steps of a run (metrics, recording, early stopping).
pub trait StepObserver {
    /// Called once with the initial state before the first step.
    fn start(&mut self, _t0: f64, _y0: &[f64]) {}
    /// Called after every accepted step.
    fn step(&mut self, step: &Step<'_>) -> Flow;
}

/// An observer that watches nothing.
pub struct NoObserver;

impl StepObserver for NoObserver {
    fn step(&mut self, _step: &Step<'_>) -> Flow {
        Flow::Continue
    }
}

/// Declares the methods once: each line names the [`Method`] variant, its
/// name in files and output, and the [`Stepper`] that implements it. The
/// enum, its names, [`Method::ALL`], [`Method::is_implicit`] and the dispatch
/// in [`solve`] all come from this list, so a new stepper is one file plus
/// one line here.
macro_rules! method_registry {
    ($( $(#[$doc:meta])* $variant:ident = $name:literal => $stepper:ty ),* $(,)?) => {
        /// Which stepper integrates the problem.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
        pub enum Method {
            $( $(#[$doc])* #[serde(rename = $name)] $variant, )*
        }

        impl Method {
            /// Every method, in the order they are documented.
            pub const ALL: &'static [Method] = &[$(Method::$variant),*];

            /// Name used in files and output.
            pub fn name(self) -> &'static str {
                match self {
                    $( Method::$variant => $name, )*
                }
            }

            /// True for implicit methods, which need no stiffness watch.
            pub fn is_implicit(self) -> bool {
                match self {
                    $( Method::$variant => <$stepper as Stepper>::IMPLICIT, )*
                }
            }
        }

        /// Run `method` in the driver from (t0, y0).
        #[allow(clippy::too_many_arguments)]
        fn drive_method<S: OdeSystem + ?Sized, O: StepObserver + ?Sized>(
            method: Method,
            system: &S,
            t0: f64,
            y0: &[f64],
            t_end: f64,
            options: &SolverOptions,
            deadline: Option<std::time::Instant>,
            observer: &mut O,
            trial: Option<cost::CostTrial>,
        ) -> SolveReport {
            match method {
                $( Method::$variant => driver::drive::<$stepper, _, _>(
                    system, t0, y0, t_end, options, deadline, observer, trial,
                ), )*
            }
        }
    };
}

method_registry! {
    /// Dormand–Prince 5(4) with 4th-order dense output: the default.
    Dp5 = "dp5" => dp5::Dp5,
    /// Dormand–Prince 8(5,3) with 7th-order dense output: tight tolerances.
    Dop853 = "dop853" => dop853::Dop853,
    /// Radau IIA order 5, implicit and L-stable: stiff problems.
    Radau5 = "radau5" => radau5::Radau5,
}

#[allow(
    clippy::derivable_impls,
    reason = "the enum is generated by method_registry!, which has no default marker"
)]
impl Default for Method {
    fn default() -> Self {
        Method::Dp5
    }
}

/// The implicit method an explicit one hands over to ([`Stiffness::SwitchToImplicit`]).
pub const IMPLICIT_FALLBACK: Method = Method::Radau5;

/// A method name that [`Method::from_str`](std::str::FromStr) does not know.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "unknown integration method `{name}` (expected one of: {known})",
    name = .0,
    known = Method::ALL.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
)]
pub struct UnknownMethod(pub String);

impl std::str::FromStr for Method {
    type Err = UnknownMethod;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .iter()
            .copied()
            .find(|m| m.name() == s)
            .ok_or_else(|| UnknownMethod(s.to_string()))
    }
}

/// Accuracy and limits of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct SolverOptions {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance per component (length 1 applies to every component).
    pub atol: Vec<f64>,
    /// First step size; chosen automatically when `None`.
    pub h0: Option<f64>,
    /// Largest step size allowed (e.g. to keep observers' sampling meaningful).
    pub h_max: f64,
    /// Give up after this many steps (accepted plus rejected).
    pub max_steps: u64,
    /// Give up when a run has taken this long (wall clock, all segments):
    /// a budget against runs that crawl, checked every few hundred steps.
    pub max_wall: Option<std::time::Duration>,
    /// What an explicit method does when its step size is held at the
    /// stability boundary (Hairer's test) instead of by accuracy.
    pub stiffness: Stiffness,
    /// Let an implicit method solve m×m Newton systems on a second-order
    /// system ([`OdeSystem::second_order_split`]) instead of 2m×2m ones: the
    /// same answer up to rounding, at an eighth of the factorisation cost.
    pub reduce_second_order: bool,
    /// Let an implicit method use the system's coupling structure
    /// ([`OdeSystem::coupling_structure`]) for its reduced Newton systems
    /// when it has many ring coordinates: O(m) instead of O(m³) work, the
    /// same answer up to the finite differences' accuracy.
    pub structured_newton: bool,
    /// After a hand-over to Radau5 ([`Stiffness::SwitchToImplicit`]), return
    /// to the explicit method for the rest of the run when Radau5 proves
    /// dearer in RHS calls per unit time (see `cost.rs`).
    pub return_when_dearer: bool,
}

/// What the driver does about stiffness met by an explicit method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Stiffness {
    /// Do not watch: the explicit method crawls on with tiny steps.
    #[default]
    Ignore,
    /// Stop with [`Failure::StiffnessDetected`] and let the caller decide.
    Stop,
    /// Continue from the current state with Radau5 when the explicit method
    /// is held by stiffness, runs out of its step budget or its step size
    /// underflows; the report's [`SolveReport::switched`] says when and why.
    SwitchToImplicit,
}

impl Stiffness {
    /// Whether the driver runs Hairer's stiffness test at all.
    fn is_watched(self) -> bool {
        self != Stiffness::Ignore
    }
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            rtol: 1e-6,
            atol: vec![1e-9],
            h0: None,
            h_max: f64::INFINITY,
            max_steps: 10_000_000,
            max_wall: None,
            stiffness: Stiffness::Ignore,
            reduce_second_order: true,
            structured_newton: true,
            return_when_dearer: true,
        }
    }
}

/// Work done by a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Stats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected: u64,
    /// Right-hand-side evaluations (including those for Jacobians).
    pub rhs_calls: u64,
    /// Jacobian evaluations (implicit methods).
    pub jacobians: u64,
    /// LU factorisations (implicit methods).
    pub factorizations: u64,
}

impl std::ops::AddAssign for Stats {
    fn add_assign(&mut self, other: Stats) {
        self.steps += other.steps;
        self.rejected += other.rejected;
        self.rhs_calls += other.rhs_calls;
        self.jacobians += other.jacobians;
        self.factorizations += other.factorizations;
    }
}

/// Why a run could not continue.
#[derive(Debug, Clone, PartialEq, thiserror::Error, Serialize)]
pub enum Failure {
    /// The step size fell below what floating point can resolve at t.
    #[error("step size underflow at t = {t} (h = {h:e})")]
    StepSizeUnderflow {
        /// Time reached.
        t: f64,
        /// Last attempted step.
        h: f64,
    },
    /// The step budget ran out.
    #[error("too many steps: {max} steps taken by t = {t}")]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// The budget.
        max: u64,
    },
    /// The wall-time budget ran out.
    #[error("wall-time budget of {limit_s} s exhausted at t = {t}")]
    WallTimeExceeded {
        /// Time reached.
        t: f64,
        /// The budget (s).
        limit_s: f64,
    },
    /// The right-hand side or the state became NaN or infinite.
    #[error("non-finite state at t = {t}")]
    NonFinite {
        /// Time reached.
        t: f64,
    },
    /// An explicit method's step size was held by stability, not accuracy.
    #[error("problem is stiff at t = {t}: explicit steps are limited by stability")]
    StiffnessDetected {
        /// Time reached.
        t: f64,
    },
    /// The implicit method's Newton iteration failed repeatedly.
    #[error("Newton iteration failed to converge at t = {t}")]
    NewtonFailure {
        /// Time reached.
        t: f64,
    },
    /// A method that took over from another made more RHS calls per unit
    /// time than the other had (by `ratio`): the run changes back
    /// ([`SolverOptions::return_when_dearer`]).
    #[error("{ratio:.1} times the other method's RHS calls per unit time at t = {t}")]
    Dearer {
        /// Time reached.
        t: f64,
        /// This method's RHS calls per unit time.
        rate: f64,
        /// Over the other method's.
        ratio: f64,
    },
    /// The problem itself is malformed (e.g. wrong atol length).
    #[error("invalid problem: {0}")]
    Invalid(String),
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// Reached t_end.
    Finished,
    /// An observer asked to stop.
    Stopped,
    /// The solver could not continue.
    Failed(Failure),
}

/// Everything a run produced: where it ended, why, and what it cost.
#[derive(Debug, Clone)]
pub struct SolveReport {
    /// How the run ended.
    pub status: Status,
    /// Time reached.
    pub t: f64,
    /// State at `t`.
    pub y: Vec<f64>,
    /// Work done (by every segment of the run).
    pub stats: Stats,
    /// When the explicit method handed over to Radau5 ([`Stiffness::SwitchToImplicit`]).
    pub switched: Option<Switch>,
    /// RHS calls per unit time over the last segment's latest accepted
    /// steps (`None` for a segment too short to say).
    pub cost_rate: Option<f64>,
}

/// A hand-over from an explicit method to the implicit one during a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Switch {
    /// The method that stalled.
    pub from: Method,
    /// Time of the hand-over.
    pub t: f64,
    /// Why the explicit method could not go on.
    pub why: Failure,
    /// Work done by the explicit method before the hand-over.
    pub before: Stats,
    /// When Radau5 proved dearer and the run returned to the explicit method
    /// ([`SolverOptions::return_when_dearer`]).
    pub back: Option<Return>,
}

/// A return from Radau5 to the explicit method, when Radau5 proved dearer.
#[derive(Debug, Clone, PartialEq)]
pub struct Return {
    /// Time of the return.
    pub t: f64,
    /// Radau5's RHS calls per unit time over the explicit method's.
    pub ratio: f64,
    /// When the explicit method then ran out of steps or step size and
    /// Radau5 took the rest of the run.
    pub stalled_at: Option<f64>,
}

impl SolveReport {
    /// The method the run ended on, begun with `method`.
    pub fn ended_with(&self, method: Method) -> Method {
        match &self.switched {
            Some(Switch {
                back: Some(Return {
                    stalled_at: None, ..
                }),
                ..
            }) => method,
            Some(_) => IMPLICIT_FALLBACK,
            None => method,
        }
    }
}

/// Integrate `system` from (t0, y0) to t_end with `method`, reporting every
/// accepted step to `observer`.
pub fn solve<S: OdeSystem + ?Sized, O: StepObserver + ?Sized>(
    method: Method,
    system: &S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    options: &SolverOptions,
    observer: &mut O,
) -> SolveReport {
    let invalid = |reason, t, y: &[f64], stats| SolveReport {
        status: Status::Failed(Failure::Invalid(reason)),
        t,
        y: y.to_vec(),
        stats,
        switched: None,
        cost_rate: None,
    };
    if let Err(reason) = norm::validate(system.dim(), y0, t0, t_end, options) {
        return invalid(reason, t0, y0, Stats::default());
    }
    // A hybrid system chooses its starting mode, and may move the state
    // onto it (a projection of rounding size).
    let started;
    let y0 = match system.events() {
        Some(events) => {
            let mut y = y0.to_vec();
            events.start(t0, &mut y);
            started = y;
            &started[..]
        }
        None => y0,
    };
    observer.start(t0, y0);
    let deadline = options.max_wall.map(|d| std::time::Instant::now() + d);
    let first = drive_method(
        method, system, t0, y0, t_end, options, deadline, observer, None,
    );
    let switch = options.stiffness == Stiffness::SwitchToImplicit
        && !method.is_implicit()
        && driver::stalled(&first.status);
    if !switch {
        return first;
    }
    let Status::Failed(why) = first.status.clone() else {
        unreachable!("a stalled run has failed")
    };
    // The implicit method continues where the explicit one stalled, with a
    // step budget of its own; the observer sees one seamless run.
    if let Err(reason) = norm::validate(system.dim(), &first.y, first.t, t_end, options) {
        return invalid(reason, first.t, &first.y, first.stats);
    }
    let trial = first
        .cost_rate
        .filter(|_| options.return_when_dearer)
        .map(|rival_rate| cost::CostTrial {
            rival_rate,
            margin: cost::DEARER_BY,
        });
    // Every later segment continues where the one before it ended.
    let mut continue_from = |m, before: &SolveReport, o: &SolverOptions, trial| {
        drive_method(
            m, system, before.t, &before.y, t_end, o, deadline, observer, trial,
        )
    };
    let mut rest = continue_from(IMPLICIT_FALLBACK, &first, options, trial);
    let mut back = None;
    if let Status::Failed(Failure::Dearer { t, ratio, .. }) = rest.status {
        // Back for the rest of the run, deaf to stiffness: the measured cost
        // says the explicit method is the cheaper one here.
        let deaf = SolverOptions {
            stiffness: Stiffness::Ignore,
            ..options.clone()
        };
        let mut last = continue_from(method, &rest, &deaf, None);
        // Out of steps or below the step-size floor, the explicit method
        // hands over as it did the first time, now for good.
        let mut stalled_at = None;
        if driver::stalled(&last.status) {
            let explicit = last.stats;
            stalled_at = Some(last.t);
            last = continue_from(IMPLICIT_FALLBACK, &last, options, None);
            last.stats += explicit;
        }
        let implicit = rest.stats;
        rest = last;
        rest.stats += implicit;
        back = Some(Return {
            t,
            ratio,
            stalled_at,
        });
    }
    rest.stats += first.stats;
    rest.switched = Some(Switch {
        from: method,
        t: first.t,
        why,
        before: first.stats,
        back,
    });
    rest
}
