//! Dormand–Prince 5(4) (Hairer's DOPRI5): explicit, adaptive, FSAL, with the
//! 4th-order continuous extension for dense output and PI step-size control.

use super::controller::PiController;
use super::norm::{error_norm, explicit_start};
use super::stepper::{Stepper, Trial};
use super::stiffness::{PowerProbe, indicator};
use super::{DenseOutput, Failure, Method, OdeSystem, SolverOptions, Stats};

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Safety factor, step-change limits and PI gain of Hairer's DOPRI5.
const SAFE: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 10.0;
const BETA: f64 = 0.04;

/// The continuous extension over one step: Hairer's five `rcont` vectors.
struct Dense {
    t_old: f64,
    h: f64,
    r: [Vec<f64>; 5],
}

impl DenseOutput for Dense {
    fn eval(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.t_old) / self.h;
        let s1 = 1.0 - s;
        let [r1, r2, r3, r4, r5] = &self.r;
        for i in 0..out.len() {
            out[i] = r1[i] + s * (r2[i] + s1 * (r3[i] + s * (r4[i] + s1 * r5[i])));
        }
    }
}

/// DOPRI5's work vectors: the seven stages, the trial solution, the last
/// stage's argument (for the stiffness test) and the dense output.
pub struct Dp5 {
    options: SolverOptions,
    controller: PiController,
    k: [Vec<f64>; 7],
    y1: Vec<f64>,
    ystage: Vec<f64>,
    err: Vec<f64>,
    dense: Dense,
    probe: PowerProbe,
}

impl Stepper for Dp5 {
    const METHOD: Method = Method::Dp5;
    /// Hairer's bound on h·|λ| for the stability region of DOPRI5.
    const STIFF_BOUND: f64 = 3.25;

    fn new(dim: usize, options: &SolverOptions) -> Self {
        let zeros = || vec![0.0; dim];
        Dp5 {
            options: options.clone(),
            controller: PiController::new(0.2, BETA, SAFE, FAC_MIN, FAC_MAX),
            k: std::array::from_fn(|_| zeros()),
            y1: zeros(),
            ystage: zeros(),
            err: zeros(),
            dense: Dense {
                t_old: 0.0,
                h: 1.0,
                r: std::array::from_fn(|_| zeros()),
            },
            probe: PowerProbe::new(dim),
        }
    }

    fn start<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t0: f64,
        y0: &[f64],
        h_max: f64,
        stats: &mut Stats,
    ) -> Result<f64, Failure> {
        let [k1, k2, k3, ..] = &mut self.k;
        Ok(explicit_start(
            system,
            t0,
            y0,
            5,
            h_max,
            &self.options,
            k1,
            (k2, k3),
            stats,
        ))
    }

    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> Trial {
        let n = y.len();
        // Slices, not `&mut Vec`: their length and pointer stay in registers
        // across the right-hand-side calls.
        let [k1, k2, k3, k4, k5, k6, k7] = self.k.each_mut().map(|v| v.as_mut_slice());
        let (ystage, y1) = (self.ystage.as_mut_slice(), self.y1.as_mut_slice());
        for i in 0..n {
            ystage[i] = y[i] + h * A21 * k1[i];
        }
        system.rhs(t + C2 * h, ystage, k2);
        for i in 0..n {
            ystage[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        system.rhs(t + C3 * h, ystage, k3);
        for i in 0..n {
            ystage[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        system.rhs(t + C4 * h, ystage, k4);
        for i in 0..n {
            ystage[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        system.rhs(t + C5 * h, ystage, k5);
        for i in 0..n {
            ystage[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        let t_new = t + h;
        system.rhs(t_new, ystage, k6);
        for i in 0..n {
            y1[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        system.rhs(t_new, y1, k7);
        stats.rhs_calls += 6;
        let err = self.err.as_mut_slice();
        for i in 0..n {
            err[i] =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        }
        let e = error_norm(err, y, y1, self.options.rtol, &self.options.atol);
        if !e.is_finite() {
            if y.iter().any(|v| !v.is_finite()) {
                return Trial::Failed(Failure::NonFinite { t });
            }
            return Trial::Rejected {
                h_new: self.controller.after_non_finite(h),
            };
        }
        match self.controller.propose(e, h) {
            (true, h_new) => Trial::Accepted { h_new },
            (false, h_new) => Trial::Rejected { h_new },
        }
    }

    fn stiffness_indicator(&self, h: f64) -> f64 {
        // h·|λ| from the last two stages, which both sit at t + h.
        let [.., k6, k7] = &self.k;
        indicator(h, k7, k6, &self.y1, &self.ystage)
    }

    fn power_check<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t_new: f64,
        h: f64,
        enough: f64,
        stats: &mut Stats,
    ) -> f64 {
        let (y1, fy, y_other) = (&self.y1, &self.k[6], &self.ystage);
        let options = &self.options;
        self.probe
            .h_rho(system, t_new, y1, fy, y_other, h, options, enough, stats)
    }

    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        _system: &S,
        t: f64,
        h: f64,
        y: &mut Vec<f64>,
        _stats: &mut Stats,
    ) -> Result<(), Failure> {
        let [k1, _, k3, k4, k5, k6, k7] = &self.k;
        let y1 = &self.y1;
        let [r1, r2, r3, r4, r5] = &mut self.dense.r;
        for i in 0..y.len() {
            let ydiff = y1[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            r1[i] = y[i];
            r2[i] = ydiff;
            r3[i] = bspl;
            r4[i] = ydiff - h * k7[i] - bspl;
            r5[i] =
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        }
        self.dense.t_old = t;
        self.dense.h = h;
        // FSAL: the derivative at the new point starts the next step.
        self.k.swap(0, 6);
        std::mem::swap(y, &mut self.y1);
        Ok(())
    }

    fn dense(&self) -> &dyn DenseOutput {
        &self.dense
    }
}
