//! Shared pieces of the steppers: the weighted error norm, input validation
//! and the initial step-size guess.

use super::{OdeSystem, SolverOptions};

/// Absolute tolerance of component i (a single value applies to all).
#[inline]
pub fn atol_of(atol: &[f64], i: usize) -> f64 {
    if atol.len() == 1 { atol[0] } else { atol[i] }
}

/// RMS of err_i / (atol_i + rtol·max(|y0_i|, |y1_i|)) (Hairer's norm).
pub fn error_norm(err: &[f64], y0: &[f64], y1: &[f64], rtol: f64, atol: &[f64]) -> f64 {
    let mut sum = 0.0;
    for i in 0..err.len() {
        let scale = atol_of(atol, i) + rtol * y0[i].abs().max(y1[i].abs());
        let r = err[i] / scale;
        sum += r * r;
    }
    (sum / err.len() as f64).sqrt()
}

/// Check that a problem is well formed before any stepper touches it.
pub fn validate(
    dim: usize,
    y0: &[f64],
    t0: f64,
    t_end: f64,
    options: &SolverOptions,
) -> Result<(), String> {
    if y0.len() != dim {
        return Err(format!("y0 has {} components, the system {dim}", y0.len()));
    }
    if !(options.atol.len() == 1 || options.atol.len() == dim) {
        return Err(format!(
            "atol has {} entries; expected 1 or {dim}",
            options.atol.len()
        ));
    }
    if options.atol.iter().any(|a| !(a.is_finite() && *a > 0.0)) {
        return Err("atol entries must be positive and finite".into());
    }
    if !(options.rtol.is_finite() && options.rtol > 0.0) {
        return Err(format!(
            "rtol = {} must be positive and finite",
            options.rtol
        ));
    }
    if !(t0.is_finite() && t_end.is_finite() && t_end > t0) {
        return Err(format!(
            "time span [{t0}, {t_end}] must be finite and increasing"
        ));
    }
    if y0.iter().any(|v| !v.is_finite()) {
        return Err("y0 contains NaN or infinity".into());
    }
    // A zero, negative or NaN step would make the steppers walk backwards or
    // spin; say so up front instead of failing somewhere later.
    if let Some(h0) = options.h0
        && !(h0.is_finite() && h0 > 0.0)
    {
        return Err(format!("h0 = {h0} must be positive and finite"));
    }
    if options.h_max.is_nan() || options.h_max <= 0.0 {
        return Err(format!("h_max = {} must be positive", options.h_max));
    }
    Ok(())
}

/// Initial step guess of Hairer, Nørsett & Wanner (II.4): one explicit Euler
/// step to estimate the second derivative. Uses two right-hand-side calls;
/// `f0` must hold f(t0, y0) and `work` two scratch vectors of the state size.
#[allow(clippy::too_many_arguments)]
pub fn initial_step<S: OdeSystem + ?Sized>(
    system: &S,
    t0: f64,
    y0: &[f64],
    f0: &[f64],
    order: i32,
    h_max: f64,
    options: &SolverOptions,
    work: (&mut [f64], &mut [f64]),
) -> f64 {
    let (y1, f1) = work;
    let n = y0.len() as f64;
    let (mut dnf, mut dny) = (0.0, 0.0);
    for i in 0..y0.len() {
        let sk = atol_of(&options.atol, i) + options.rtol * y0[i].abs();
        dnf += (f0[i] / sk).powi(2);
        dny += (y0[i] / sk).powi(2);
    }
    let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
        1e-6
    } else {
        (dny / dnf).sqrt() * 0.01
    };
    h = h.min(h_max);
    for i in 0..y0.len() {
        y1[i] = y0[i] + h * f0[i];
    }
    system.rhs(t0 + h, y1, f1);
    let mut der2 = 0.0;
    for i in 0..y0.len() {
        let sk = atol_of(&options.atol, i) + options.rtol * y0[i].abs();
        der2 += ((f1[i] - f0[i]) / sk).powi(2);
    }
    let der2 = (der2 / n).sqrt() / h;
    let der12 = der2.max((dnf / n).sqrt());
    let h1 = if der12 <= 1e-15 {
        (h * 1e-3).max(1e-6)
    } else {
        (0.01 / der12).powf(1.0 / f64::from(order + 1))
    };
    (100.0 * h).min(h1).min(h_max)
}

/// How an explicit FSAL method starts: f(t0, y0) into `f0`, then the first
/// step size, `options.h0` or Hairer's guess for a method of this `order`
/// (two scratch vectors in `work`); counts its right-hand-side calls.
#[allow(clippy::too_many_arguments)]
pub fn explicit_start<S: OdeSystem + ?Sized>(
    system: &S,
    t0: f64,
    y0: &[f64],
    order: i32,
    h_max: f64,
    options: &SolverOptions,
    f0: &mut [f64],
    work: (&mut [f64], &mut [f64]),
    stats: &mut super::Stats,
) -> f64 {
    system.rhs(t0, y0, f0);
    stats.rhs_calls += 1;
    match options.h0 {
        Some(h0) => h0.min(h_max),
        None => {
            stats.rhs_calls += 1;
            initial_step(system, t0, y0, f0, order, h_max, options, work)
        }
    }
}

/// The checks every stepper makes before a step: the step budget and a step
/// size that floating point can still resolve at t.
pub fn check_step(
    t: f64,
    h: f64,
    stats: &super::Stats,
    options: &SolverOptions,
) -> Result<(), super::Failure> {
    if stats.steps + stats.rejected >= options.max_steps {
        return Err(super::Failure::TooManySteps {
            t,
            max: options.max_steps,
        });
    }
    if 0.1 * h.abs() <= t.abs() * f64::EPSILON {
        return Err(super::Failure::StepSizeUnderflow { t, h });
    }
    Ok(())
}
