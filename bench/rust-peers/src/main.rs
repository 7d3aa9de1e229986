//! autobal's DP5 against other Rust ODE crates on exactly the same right-hand
//! side (`RotorSystem`, reference scene, 3 cargoes), the same scalar
//! tolerances and the same horizon. Prints step/RHS counts, the final-state
//! error against a tight reference, and median wall time relative to autobal
//! measured in one run with the cases interleaved.
//!
//! Run: `cargo run --release` in this folder (see docs/benchmarks.md).

use autobal::bench::{BenchProblem, median};
use autobal::integrate::{Method, NoObserver, OdeSystem, SolverOptions, Status, solve};
use autobal::model::system::RotorSystem;
use nalgebra::{DVector, SVector};
use ode_solvers::dop_shared::{OutputType, System as OsSystem};
use ode_solvers::{Dop853, Dopri5};
use russell_lab::Vector;
use russell_ode::prelude::{Method as RMethod, NoArgs, OdeSolver, Params, System as RSystem};
use std::hint::black_box;
use std::time::Instant;

/// Cargoes in the comparison (the reference scene).
const N: usize = 3;
/// State dimension 2·(2 + N), fixed at compile time for nalgebra's SVector.
const DIM: usize = 2 * (2 + N);
/// Horizon in revolutions (as `autobal-bench`).
const REVOLUTIONS: f64 = 500.0;
/// Scalar absolute tolerance as a fraction of rtol (scalar: not every peer takes a vector).
const ATOL_PER_RTOL: f64 = 1e-2;

/// What one solve produced.
struct Outcome {
    y: Vec<f64>,
    steps: u64,
    rejected: u64,
    rhs_calls: u64,
    note: String,
}

type Solver = fn(&RotorSystem, &[f64], f64, f64) -> Outcome;

/// The ode_solvers view of the system (any nalgebra vector with a contiguous slice).
struct OsWrap<'a>(&'a RotorSystem);

impl OsSystem<f64, SVector<f64, DIM>> for OsWrap<'_> {
    fn system(&self, t: f64, y: &SVector<f64, DIM>, dy: &mut SVector<f64, DIM>) {
        self.0.rhs(t, y.as_slice(), dy.as_mut_slice());
    }
}

impl OsSystem<f64, DVector<f64>> for OsWrap<'_> {
    fn system(&self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        self.0.rhs(t, y.as_slice(), dy.as_mut_slice());
    }
}

fn autobal_dp5(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    let options = SolverOptions {
        rtol,
        atol: vec![rtol * ATOL_PER_RTOL],
        max_steps: u64::MAX,
        ..SolverOptions::default()
    };
    let r = solve(Method::Dp5, sys, 0.0, y0, t_end, &options, &mut NoObserver);
    Outcome {
        note: if r.status == Status::Finished {
            String::new()
        } else {
            format!("{:?}", r.status)
        },
        y: r.y,
        steps: r.stats.steps,
        rejected: r.stats.rejected,
        rhs_calls: r.stats.rhs_calls,
    }
}

fn os_outcome(
    result: Result<ode_solvers::dop_shared::Stats, ode_solvers::dop_shared::IntegrationError>,
    y: Option<Vec<f64>>,
) -> Outcome {
    match result {
        Ok(s) => Outcome {
            y: y.unwrap_or_default(),
            steps: u64::from(s.accepted_steps),
            rejected: u64::from(s.rejected_steps),
            rhs_calls: u64::from(s.num_eval),
            note: String::new(),
        },
        Err(e) => Outcome {
            y: Vec::new(),
            steps: 0,
            rejected: 0,
            rhs_calls: 0,
            note: e.to_string(),
        },
    }
}

/// ode_solvers' DOPRI5 on a stack vector, every accepted step stored (Sparse):
/// its cheapest configuration whose last stored state is the true final state.
fn os_dopri5_svector(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    let y = SVector::<f64, DIM>::from_column_slice(y0);
    let mut s = Dopri5::new(
        OsWrap(sys),
        0.0,
        t_end,
        t_end,
        y,
        rtol,
        rtol * ATOL_PER_RTOL,
    );
    s.set_output(OutputType::Sparse);
    let r = s.integrate();
    let last = s.y_out().last().map(|v| v.as_slice().to_vec());
    os_outcome(r, last)
}

fn os_dopri5_dvector(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    let y = DVector::from_column_slice(y0);
    let mut s = Dopri5::new(
        OsWrap(sys),
        0.0,
        t_end,
        t_end,
        y,
        rtol,
        rtol * ATOL_PER_RTOL,
    );
    s.set_output(OutputType::Sparse);
    let r = s.integrate();
    let last = s.y_out().last().map(|v| v.as_slice().to_vec());
    os_outcome(r, last)
}

fn os_dop853_svector(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    let y = SVector::<f64, DIM>::from_column_slice(y0);
    let mut s = Dop853::new(
        OsWrap(sys),
        0.0,
        t_end,
        t_end,
        y,
        rtol,
        rtol * ATOL_PER_RTOL,
    );
    s.set_output(OutputType::Sparse);
    let r = s.integrate();
    let last = s.y_out().last().map(|v| v.as_slice().to_vec());
    os_outcome(r, last)
}

/// ode_solvers' DOP853 without its stiffness test (`n_stiff` = never), other
/// parameters at their defaults: shows the accuracy the method reaches here.
fn os_dop853_no_stiff_test(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    let y = SVector::<f64, DIM>::from_column_slice(y0);
    let mut s = Dop853::from_param(
        OsWrap(sys),
        0.0,
        t_end,
        t_end,
        y,
        rtol,
        rtol * ATOL_PER_RTOL,
        0.9,
        0.0,
        0.333,
        6.0,
        t_end,
        0.0,
        u32::MAX,
        u32::MAX,
        OutputType::Sparse,
    );
    let r = s.integrate();
    let last = s.y_out().last().map(|v| v.as_slice().to_vec());
    os_outcome(r, last)
}

/// The same system made autonomous: time is state component DIM (t' = 1) and
/// the RHS reads it from there, so a stage evaluated at the wrong `t` argument
/// no longer matters.
struct Autonomous<'a>(&'a RotorSystem);

impl OsSystem<f64, SVector<f64, { DIM + 1 }>> for Autonomous<'_> {
    fn system(&self, _t: f64, y: &SVector<f64, { DIM + 1 }>, dy: &mut SVector<f64, { DIM + 1 }>) {
        let (y, time) = y.as_slice().split_at(DIM);
        let dy = dy.as_mut_slice();
        self.0.rhs(time[0], y, &mut dy[..DIM]);
        dy[DIM] = 1.0;
    }
}

fn os_dop853_autonomous(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    let mut y = SVector::<f64, { DIM + 1 }>::zeros();
    y.as_mut_slice()[..DIM].copy_from_slice(y0);
    let mut s = Dop853::new(
        Autonomous(sys),
        0.0,
        t_end,
        t_end,
        y,
        rtol,
        rtol * ATOL_PER_RTOL,
    );
    s.set_output(OutputType::Sparse);
    let r = s.integrate();
    let last = s.y_out().last().map(|v| v.as_slice()[..DIM].to_vec());
    os_outcome(r, last)
}

/// ode_solvers' DOPRI5 with its default dense output on a grid of `per_rev`
/// points per revolution: the last stored point is labelled t_end.
fn os_dopri5_dense_grid(
    sys: &RotorSystem,
    y0: &[f64],
    t_end: f64,
    rtol: f64,
    per_rev: f64,
) -> Outcome {
    let y = SVector::<f64, DIM>::from_column_slice(y0);
    let dx = t_end / (REVOLUTIONS * per_rev);
    let mut s = Dopri5::new(OsWrap(sys), 0.0, t_end, dx, y, rtol, rtol * ATOL_PER_RTOL);
    let r = s.integrate();
    let (x, ys) = (s.x_out(), s.y_out());
    let mut o = os_outcome(r, ys.last().map(|v| v.as_slice().to_vec()));
    o.note = format!(
        "{} points, last labelled t = {:.6} (t_end {:.6})",
        x.len(),
        x.last().copied().unwrap_or(f64::NAN),
        t_end
    );
    o
}

/// Same with a single output interval dx = t_end.
fn os_dopri5_dense_end(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    let y = SVector::<f64, DIM>::from_column_slice(y0);
    let mut s = Dopri5::new(
        OsWrap(sys),
        0.0,
        t_end,
        t_end,
        y,
        rtol,
        rtol * ATOL_PER_RTOL,
    );
    let r = s.integrate();
    let (x, ys) = (s.x_out(), s.y_out());
    let mut o = os_outcome(r, ys.last().map(|v| v.as_slice().to_vec()));
    o.note = format!("{} points at t = {:?}", x.len(), x);
    o
}

fn os_dop853_dense_end(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    let y = SVector::<f64, DIM>::from_column_slice(y0);
    let mut s = Dop853::new(
        OsWrap(sys),
        0.0,
        t_end,
        t_end,
        y,
        rtol,
        rtol * ATOL_PER_RTOL,
    );
    let r = s.integrate();
    let (x, ys) = (s.x_out(), s.y_out());
    let mut o = os_outcome(r, ys.last().map(|v| v.as_slice().to_vec()));
    o.note = format!("{} points at t = {:?}", x.len(), x);
    o
}

fn russell(
    method: RMethod,
    sys: &RotorSystem,
    y0: &[f64],
    t_end: f64,
    rtol: f64,
    tweak: impl FnOnce(&mut Params),
) -> Outcome {
    let system = RSystem::new(
        DIM,
        move |f: &mut Vector, t: f64, y: &Vector, _: &mut NoArgs| {
            sys.rhs(t, y.as_data(), f.as_mut_data());
            Ok(())
        },
    );
    let mut params = Params::new(method);
    let failed = |e: &str| Outcome {
        y: Vec::new(),
        steps: 0,
        rejected: 0,
        rhs_calls: 0,
        note: e.to_string(),
    };
    if let Err(e) = params.set_tolerances(rtol * ATOL_PER_RTOL, rtol, None) {
        return failed(e);
    }
    params.step.n_step_max = 100_000_000;
    tweak(&mut params);
    let mut solver = match OdeSolver::new(params, system) {
        Ok(s) => s,
        Err(e) => return failed(e),
    };
    let mut y = Vector::from(&y0.to_vec());
    let mut args: NoArgs = 0;
    let result = solver.solve(&mut y, 0.0, t_end, None, &mut args, None);
    let st = solver.stats();
    Outcome {
        y: y.as_data().clone(),
        steps: st.n_accepted as u64,
        rejected: st.n_rejected as u64,
        rhs_calls: st.n_function as u64,
        note: match result {
            Ok(()) if st.n_jacobian > 0 => {
                format!(
                    "{} Jacobians, {} factorisations",
                    st.n_jacobian, st.n_factor
                )
            }
            Ok(()) => String::new(),
            Err(e) => e.to_string(),
        },
    }
}

fn russell_dopri5(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    russell(RMethod::DoPri5, sys, y0, t_end, rtol, |_| {})
}

fn russell_dopri8(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    russell(RMethod::DoPri8, sys, y0, t_end, rtol, |_| {})
}

fn russell_radau5(sys: &RotorSystem, y0: &[f64], t_end: f64, rtol: f64) -> Outcome {
    russell(RMethod::Radau5, sys, y0, t_end, rtol, |p| {
        // One thread, as every other solver here; no analytic Jacobian exists.
        p.radau5.concurrent = false;
        p.newton.use_numerical_jacobian = true;
    })
}

/// The timed solvers; the first is the baseline of the ratios.
const TIMED: &[(&str, Solver)] = &[
    ("autobal dp5", autobal_dp5),
    ("ode_solvers Dopri5 (SVector)", os_dopri5_svector),
    ("ode_solvers Dopri5 (DVector)", os_dopri5_dvector),
    ("ode_solvers Dop853 (SVector)", os_dop853_svector),
    (
        "ode_solvers Dop853, autonomised (t as state)",
        os_dop853_autonomous,
    ),
    ("russell_ode DoPri5", russell_dopri5),
    ("russell_ode DoPri8", russell_dopri8),
    ("russell_ode Radau5 (1 thread)", russell_radau5),
];

/// Diagnostics, run and timed once: too slow to repeat, or a correctness probe.
const DIAGNOSTICS: &[(&str, Solver)] = &[
    (
        "ode_solvers Dop853, no stiffness test",
        os_dop853_no_stiff_test,
    ),
    ("ode_solvers Dopri5 dense, dx = 1 rev", |s, y, t, r| {
        os_dopri5_dense_grid(s, y, t, r, 1.0)
    }),
    ("ode_solvers Dopri5 dense, dx = 0.1 rev", |s, y, t, r| {
        os_dopri5_dense_grid(s, y, t, r, 10.0)
    }),
    ("ode_solvers Dopri5 dense, dx = 0.01 rev", |s, y, t, r| {
        os_dopri5_dense_grid(s, y, t, r, 100.0)
    }),
    ("ode_solvers Dopri5 dense, dx = t_end", os_dopri5_dense_end),
    ("ode_solvers Dop853 dense, dx = t_end", os_dop853_dense_end),
];

fn main() {
    let repeats: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(21);
    let problem = BenchProblem::new(N, 1e-6, REVOLUTIONS);
    let (sys, y0, t_end) = (&problem.system, &problem.y0[..], problem.t_end);
    assert_eq!(y0.len(), DIM);

    // Two independent tight references; their difference bounds the reference error.
    let reference = autobal_dp5(sys, y0, t_end, 1e-12);
    let check = russell_dopri8(sys, y0, t_end, 1e-12);
    println!(
        "reference: autobal dp5 rtol 1e-12 ({} steps); russell DoPri8 rtol 1e-12 differs by {:.1e} ({})",
        reference.steps,
        problem.scaled_error(&check.y, &reference.y),
        if check.note.is_empty() {
            "ok"
        } else {
            &check.note
        }
    );
    println!(
        "scene: reference scene, {N} cargoes, {REVOLUTIONS} revolutions (t_end {t_end:.3}), atol = {ATOL_PER_RTOL}·rtol (scalar), {repeats} interleaved repeats\n"
    );

    for rtol in [1e-6, 1e-9] {
        let outcomes: Vec<Outcome> = TIMED.iter().map(|(_, f)| f(sys, y0, t_end, rtol)).collect();
        let mut times = vec![Vec::with_capacity(repeats); TIMED.len()];
        for _ in 0..repeats {
            for (i, (_, f)) in TIMED.iter().enumerate() {
                let start = Instant::now();
                black_box(f(black_box(sys), y0, t_end, rtol));
                times[i].push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        let best = |t: &[f64]| t.iter().copied().fold(f64::INFINITY, f64::min);
        let (base, base_min) = (median(&times[0]), best(&times[0]));
        let error = |o: &Outcome| {
            if o.y.len() == DIM {
                format!("{:.1e}", problem.scaled_error(&o.y, &reference.y))
            } else {
                "–".into()
            }
        };
        println!("rtol {rtol:e}");
        println!(
            "| solver | steps | rejected | RHS calls | median ms | ratio (median) | ratio (min) | error vs reference | note |"
        );
        println!("|---|---:|---:|---:|---:|---:|---:|---:|---|");
        for (i, ((name, _), o)) in TIMED.iter().zip(&outcomes).enumerate() {
            let ms = median(&times[i]);
            println!(
                "| {name} | {} | {} | {} | {ms:.2} | {:.2} | {:.2} | {} | {} |",
                o.steps,
                o.rejected,
                o.rhs_calls,
                ms / base,
                best(&times[i]) / base_min,
                error(o),
                o.note
            );
        }
        println!();
        println!("Diagnostics (one run each; ratio to the autobal median above):");
        for (name, f) in DIAGNOSTICS {
            let start = Instant::now();
            let o = f(sys, y0, t_end, rtol);
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let note: String = o.note.chars().take(120).collect();
            println!(
                "  {name}: {} steps, {} RHS calls, {ms:.1} ms (×{:.0}), error {}; {note}",
                o.steps,
                o.rhs_calls,
                ms / base,
                error(&o)
            );
        }
        println!();
    }
}
