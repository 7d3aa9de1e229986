//! Reference problems with exact or published solutions, shared by the
//! stepper tests (`integrate.rs`) and the work-precision table of
//! docs/integrators.md (`cargo run --example work_precision_table`, which
//! includes this file by path).

#![allow(dead_code)]

use autobal::integrate::OdeSystem;

/// y'' = −y as a first-order system; exact solution (cos t, −sin t).
pub struct Oscillator;

impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = y[1];
        dydt[1] = -y[0];
    }
}

pub fn oscillator_exact(t: f64, y: &mut [f64]) {
    y[0] = t.cos();
    y[1] = -t.sin();
}

/// y' = cos(t)·y, y(0) = 1: time-dependent, exact solution exp(sin t). A stage
/// evaluated at the wrong time shows up here and not on autonomous problems.
pub struct Forced;

impl OdeSystem for Forced {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = t.cos() * y[0];
    }
}

pub fn forced_exact(t: f64, y: &mut [f64]) {
    y[0] = t.sin().exp();
}

/// x'' + c·x' + x = 0: a heavily over-damped mode, eigenvalues ≈ −1/c (slow)
/// and ≈ −c (fast), like a balancer in a very viscous fluid.
pub struct OverDamped(pub f64);

impl OdeSystem for OverDamped {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = y[1];
        dydt[1] = -y[0] - self.0 * y[1];
    }
}

impl OverDamped {
    /// Exact solution from x(0) = 1, x'(0) = 0.
    pub fn exact(&self, t: f64, y: &mut [f64]) {
        let c = self.0;
        let root = (c * c - 4.0).sqrt();
        let (slow, fast) = (-2.0 / (c + root), -(c + root) / 2.0);
        let (a, b) = (fast / (fast - slow), -slow / (fast - slow));
        y[0] = a * (slow * t).exp() + b * (fast * t).exp();
        y[1] = a * slow * (slow * t).exp() + b * fast * (fast * t).exp();
    }
}

/// The over-damped mode with c = 1000 used in the tables.
pub const OVER_DAMPED: OverDamped = OverDamped(1000.0);

pub fn over_damped_exact(t: f64, y: &mut [f64]) {
    OVER_DAMPED.exact(t, y);
}

/// Robertson's chemical kinetics: the classic stiff test problem.
pub struct Robertson;

impl OdeSystem for Robertson {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = -0.04 * y[0] + 1e4 * y[1] * y[2];
        dydt[2] = 3e7 * y[1] * y[1];
        dydt[1] = -dydt[0] - dydt[2];
    }
}

/// The same to 13 digits: Radau5 and DOP853 at rtol = 1e-13 agree on these
/// (and with the published digits); used where 10 digits are too few.
pub const ROBERTSON_40_TIGHT: [f64; 3] = [
    0.715_827_068_719_4,
    9.185_534_764_56e-6,
    0.284_163_745_745_8,
];

/// A reference problem for the work-precision table.
pub struct Problem {
    pub name: &'static str,
    pub system: &'static dyn OdeSystem,
    pub y0: &'static [f64],
    pub t_end: f64,
    /// Absolute tolerance per component as a multiple of rtol.
    pub atol_scale: &'static [f64],
    /// The solution at t_end.
    pub reference: fn() -> Vec<f64>,
    /// Errors are relative to max(|y_ref|, this).
    pub error_floor: f64,
}

pub fn exact(f: fn(f64, &mut [f64]), n: usize, t: f64) -> Vec<f64> {
    let mut y = vec![0.0; n];
    f(t, &mut y);
    y
}

pub fn problems() -> [Problem; 4] {
    [
        Problem {
            name: "oscillator, t ≤ 20",
            system: &Oscillator,
            y0: &[1.0, 0.0],
            t_end: 20.0,
            atol_scale: &[1.0],
            reference: || exact(oscillator_exact, 2, 20.0),
            error_floor: 1.0,
        },
        Problem {
            name: "y' = cos(t)·y, t ≤ 10",
            system: &Forced,
            y0: &[1.0],
            t_end: 10.0,
            atol_scale: &[1.0],
            reference: || exact(forced_exact, 1, 10.0),
            error_floor: 1.0,
        },
        Problem {
            name: "over-damped c = 1000, t ≤ 1000",
            system: &OVER_DAMPED,
            y0: &[1.0, 0.0],
            t_end: 1000.0,
            atol_scale: &[1e-2],
            reference: || exact(over_damped_exact, 2, 1000.0),
            error_floor: 1.0,
        },
        Problem {
            name: "Robertson, t ≤ 40",
            system: &Robertson,
            y0: &[1.0, 0.0, 0.0],
            t_end: 40.0,
            atol_scale: &[1e-2, 1e-6, 1e-2],
            reference: || ROBERTSON_40_TIGHT.to_vec(),
            error_floor: 0.0,
        },
    ]
}

/// Largest |y_i − ref_i| / max(|ref_i|, floor) over the components.
pub fn max_rel_error(y: &[f64], reference: &[f64], floor: f64) -> f64 {
    y.iter()
        .zip(reference)
        .map(|(a, b)| (a - b).abs() / b.abs().max(floor))
        .fold(0.0, f64::max)
}
