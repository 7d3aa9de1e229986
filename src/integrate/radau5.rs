//! Radau IIA of order 5 (Hairer's RADAU5): implicit, L-stable, stiffly
//! accurate, for stiff extremes such as a heavily over-damped balancer.
//!
//! Why Radau IIA rather than a Rosenbrock method (Rodas4/Rodas5P):
//! - Robustness: L-stable and stiffly accurate with stage order 3, so it keeps
//!   its accuracy as damping → ∞ (the problem tends to an index-1 DAE) where
//!   Rosenbrock methods may lose order; it is the reference solver of the
//!   stiff test sets.
//! - Jacobian quality: a simplified Newton iteration only needs an
//!   approximate Jacobian, which is reused over many steps while Newton
//!   converges fast. Rosenbrock methods build the Jacobian into their order
//!   conditions, so they need a fresh, accurate one (n extra RHS calls by
//!   finite differences, plus ∂f/∂t) on every step.
//! - Cost: per step one real and one complex LU only when h or J changed
//!   (often not), and 3 RHS calls per Newton iteration (usually 1–3). Rodas
//!   pays 6 RHS calls, a Jacobian and an LU on every step.
//! - Simplicity of the numbers: the coefficients are closed forms in √6 and
//!   ∛9; only the eigenvector matrices T, T⁻¹ are tabulated, and a unit test
//!   checks them against the method's matrix. Dense output is the collocation
//!   polynomial itself (order 3, exact at both step ends).
//!
//! The step follows Hairer's `radcor`: Newton on the T⁻¹-transformed stage
//! system (one real n×n and one complex n×n matrix), the embedded
//! 3rd-order error estimate filtered through (γ/h·I − J)⁻¹, Gustafsson's
//! predictive step control, and Hairer's tolerance mapping
//! rtol' = 0.1·rtol^(2/3) so that the achieved error roughly matches the
//! requested tolerance as for the explicit methods.
//!
//! Counts in [`Stats`]: every attempt that is not accepted (error test,
//! Newton divergence, singular matrix) is a rejected step; a factorisation is
//! one real plus one complex LU (Hairer's `ndec`); RHS calls include the
//! finite-difference Jacobians.

#![allow(
    clippy::excessive_precision,
    reason = "coefficients keep the published digits so that they can be compared with the source"
)]

use super::newton_matrices::NewtonMatrices;
use super::norm::{atol_of, initial_step};
use super::stepper::{Stepper, Trial};
use super::{DenseOutput, Failure, Method, OdeSystem, SolverOptions, Stats};

/// T: eigenvectors of the inverse Radau IIA matrix (Hairer's digits); T32 = 1, T33 = 0.
const T11: f64 = 9.123_239_487_089_294_279_2e-2;
const T12: f64 = -0.141_255_295_020_954_208_43;
const T13: f64 = -3.002_919_410_514_742_449_2e-2;
const T21: f64 = 0.241_717_932_707_107_018_96;
const T22: f64 = 0.204_129_352_293_799_931_99;
const T23: f64 = 0.382_942_112_757_261_937_79;
const T31: f64 = 0.966_048_182_615_092_936_19;
/// T⁻¹.
const TI11: f64 = 4.325_579_890_063_155_351_0;
const TI12: f64 = 0.339_199_251_815_809_869_54;
const TI13: f64 = 0.541_770_539_935_874_871_19;
const TI21: f64 = -4.178_718_591_551_904_727_3;
const TI22: f64 = -0.327_682_820_761_062_387_08;
const TI23: f64 = 0.476_623_554_500_550_451_96;
const TI31: f64 = -0.502_872_634_945_786_875_95;
const TI32: f64 = 2.571_926_949_855_605_429_2;
const TI33: f64 = -0.596_039_204_828_224_924_97;

/// Newton iterations allowed per step (Hairer's `nit`).
const NIT: i32 = 7;
/// Keep the Jacobian while Newton contracts faster than this (Hairer's `thet`).
const THET: f64 = 0.001;
/// Keep the LU when the proposed h/h_old lies in [QUOT1, QUOT2].
const QUOT1: f64 = 1.0;
const QUOT2: f64 = 1.2;
/// Safety factor and step-change limits: h/5 ≤ h_new ≤ 8h.
const SAFE: f64 = 0.9;
const FACL: f64 = 5.0;
const FACR: f64 = 1.0 / 8.0;
/// Hairer's unit roundoff for the Newton tolerance and difference increments.
const UROUND: f64 = 1e-16;
/// Consecutive failed Newton iterations (each halving h) before giving up:
/// h may shrink by 2⁻⁴⁰ ≈ 1e-12. Rolling resistance's regularised stick
/// (slip rate 1e-7 ω) needs more than 10 halvings to step through its knee:
/// at 10, 3 of 360 runs of `studies/friction.toml` failed; at 40, none.
const MAX_NEWTON_FAILURES: u32 = 40;

/// The method's closed-form constants.
struct Coeffs {
    c1: f64,
    c2: f64,
    c1m1: f64,
    c2m1: f64,
    c1mc2: f64,
    dd: [f64; 3],
    /// Real eigenvalue of A⁻¹ (γ).
    u1: f64,
    /// Complex eigenvalue pair α ± iβ of A⁻¹.
    alph: f64,
    beta: f64,
}

impl Coeffs {
    fn new() -> Self {
        let sq6 = 6f64.sqrt();
        let (c1, c2) = ((4.0 - sq6) / 10.0, (4.0 + sq6) / 10.0);
        let (r81, r9) = (81f64.cbrt(), 9f64.cbrt());
        let u1 = (6.0 + r81 - r9) / 30.0;
        let alph = (12.0 - r81 + r9) / 60.0;
        let beta = (r81 + r9) * 3f64.sqrt() / 60.0;
        let cno = alph * alph + beta * beta;
        Coeffs {
            c1,
            c2,
            c1m1: c1 - 1.0,
            c2m1: c2 - 1.0,
            c1mc2: c1 - c2,
            dd: [
                -(13.0 + 7.0 * sq6) / 3.0,
                (-13.0 + 7.0 * sq6) / 3.0,
                -1.0 / 3.0,
            ],
            u1: 1.0 / u1,
            alph: alph / cno,
            beta: beta / cno,
        }
    }
}

/// The collocation polynomial of the last step, in Newton form around its end.
struct Dense {
    t: f64,
    h: f64,
    c1m1: f64,
    c2m1: f64,
    cont: [Vec<f64>; 4],
}

impl DenseOutput for Dense {
    fn eval(&self, t: f64, out: &mut [f64]) {
        let s = (t - self.t) / self.h;
        let [c0, c1, c2, c3] = &self.cont;
        for i in 0..out.len() {
            out[i] = c0[i] + s * (c1[i] + (s - self.c2m1) * (c2[i] + (s - self.c1m1) * c3[i]));
        }
    }
}

/// How one simplified Newton iteration ended.
enum Newton {
    /// Converged after this many iterations.
    Converged(i32),
    /// Converging too slowly for this h: retry with h scaled by the factor.
    TooSlow(f64),
    /// Diverged, hit the iteration limit, or met a non-finite value.
    Failed,
}

/// RMS of v_i / scal_i.
fn rms(v: &[f64], scal: &[f64]) -> f64 {
    let sum: f64 = v.iter().zip(scal).map(|(a, s)| (a / s) * (a / s)).sum();
    (sum / v.len() as f64).sqrt()
}

/// RADAU5's state between steps: the transformed tolerances, the Newton
/// iterates, the Jacobian and its two shifted factorisations (reused while
/// they stay good), and the step-size controller's memory.
pub struct Radau5 {
    k: Coeffs,
    options: SolverOptions,
    rtol: f64,
    atol: Vec<f64>,
    fnewt: f64,
    fy: Vec<f64>,
    scal: Vec<f64>,
    tmp: Vec<f64>,
    y_perturbed: Vec<f64>,
    z: [Vec<f64>; 3],
    f: [Vec<f64>; 3],
    jac: Vec<f64>,
    matrices: NewtonMatrices,
    dense: Dense,
    h_old: f64,
    first: bool,
    reject: bool,
    faccon: f64,
    theta: f64,
    cfac: f64,
    h_acc: f64,
    err_acc: f64,
    need_jac: bool,
    need_lu: bool,
    fresh_jac: bool,
    analytic: bool,
    newton_failures: u32,
    accepted: u64,
    fac1: f64,
    alphn: f64,
    betan: f64,
}

impl Radau5 {
    fn set_scal(&mut self, y: &[f64]) {
        for i in 0..y.len() {
            self.scal[i] = atol_of(&self.atol, i) + self.rtol * y[i].abs();
        }
    }

    /// Jacobian (analytic when the system has one, else forward differences)
    /// and the two shifted factorisations, as far as they are due; false
    /// when a matrix is singular.
    fn prepare<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> bool {
        let n = y.len();
        if self.need_jac {
            stats.jacobians += 1;
            let structured = match &mut self.matrices {
                NewtonMatrices::Structured(s) => {
                    let ok = s.evaluate(system, t, y, &self.fy, stats);
                    if !ok {
                        // No usable structure here: dense matrices from now on.
                        self.matrices = NewtonMatrices::new(n, Some(n / 2));
                    }
                    ok
                }
                _ => false,
            };
            // A structured Jacobian lives in the matrices; a dense one here.
            if !structured {
                self.jac.resize(n * n, 0.0);
                if !(self.analytic && system.jacobian(t, y, &mut self.jac)) {
                    self.analytic = false;
                    self.y_perturbed.copy_from_slice(y);
                    for j in 0..n {
                        let ysafe = y[j];
                        let delt = (UROUND * ysafe.abs().max(1e-5)).sqrt();
                        self.y_perturbed[j] = ysafe + delt;
                        system.rhs(t, &self.y_perturbed, &mut self.tmp);
                        for i in 0..n {
                            self.jac[i * n + j] = (self.tmp[i] - self.fy[i]) / delt;
                        }
                        self.y_perturbed[j] = ysafe;
                    }
                    stats.rhs_calls += n as u64;
                }
            }
            self.fresh_jac = true;
            self.need_jac = false;
            self.need_lu = true;
        }
        if self.need_lu {
            self.fac1 = self.k.u1 / h;
            self.alphn = self.k.alph / h;
            self.betan = self.k.beta / h;
            stats.factorizations += 1;
            let singular = !self
                .matrices
                .factor(system, self.fac1, self.alphn, self.betan, &self.jac, stats);
            self.need_lu = singular;
            return !singular;
        }
        true
    }

    /// Simplified Newton iteration on the transformed stage equations.
    fn newton<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64],
        h: f64,
        stats: &mut Stats,
    ) -> Newton {
        let n = y.len();
        let k = &self.k;
        let t_new = t + h;
        // Slices, not `&mut Vec`: their length and pointer stay in registers
        // across the right-hand-side calls.
        let [z1, z2, z3] = self.z.each_mut().map(|v| v.as_mut_slice());
        let [f1, f2, f3] = self.f.each_mut().map(|v| v.as_mut_slice());
        let tmp = self.tmp.as_mut_slice();
        let scal = self.scal.as_slice();
        if self.first {
            for v in [&mut *z1, &mut *z2, &mut *z3, &mut *f1, &mut *f2, &mut *f3] {
                v.fill(0.0);
            }
        } else {
            // Start from the previous step's collocation polynomial.
            let c3q = h / self.h_old;
            let (c1q, c2q) = (k.c1 * c3q, k.c2 * c3q);
            let [_, a1, a2, a3] = &self.dense.cont;
            for i in 0..n {
                let ext = |q: f64| q * (a1[i] + (q - k.c2m1) * (a2[i] + (q - k.c1m1) * a3[i]));
                let (w1, w2, w3) = (ext(c1q), ext(c2q), ext(c3q));
                z1[i] = w1;
                z2[i] = w2;
                z3[i] = w3;
                f1[i] = TI11 * w1 + TI12 * w2 + TI13 * w3;
                f2[i] = TI21 * w1 + TI22 * w2 + TI23 * w3;
                f3[i] = TI31 * w1 + TI32 * w2 + TI33 * w3;
            }
        }
        self.faccon = self.faccon.max(UROUND).powf(0.8);
        self.theta = THET;
        let (fac1, alphn, betan) = (self.fac1, self.alphn, self.betan);
        let mut newt = 0;
        let (mut dyno_old, mut thq_old) = (1.0, 1.0);
        loop {
            if newt >= NIT {
                break Newton::Failed;
            }
            for (z, c) in [(&mut *z1, k.c1), (&mut *z2, k.c2)] {
                for i in 0..n {
                    tmp[i] = y[i] + z[i];
                }
                system.rhs(t + c * h, tmp, z);
            }
            for i in 0..n {
                tmp[i] = y[i] + z3[i];
            }
            system.rhs(t_new, tmp, z3);
            stats.rhs_calls += 3;
            for i in 0..n {
                let (a1, a2, a3) = (z1[i], z2[i], z3[i]);
                let w1 = TI11 * a1 + TI12 * a2 + TI13 * a3;
                let w2 = TI21 * a1 + TI22 * a2 + TI23 * a3;
                let w3 = TI31 * a1 + TI32 * a2 + TI33 * a3;
                z1[i] = w1 - f1[i] * fac1;
                z2[i] = w2 - f2[i] * alphn + f3[i] * betan;
                z3[i] = w3 - f3[i] * alphn - f2[i] * betan;
            }
            self.matrices.solve_real(system, z1, stats);
            self.matrices.solve_complex(system, z2, z3, stats);
            newt += 1;
            let dyno = {
                let s: f64 = (0..n)
                    .map(|i| {
                        let (a, b, c) = (z1[i] / scal[i], z2[i] / scal[i], z3[i] / scal[i]);
                        a * a + b * b + c * c
                    })
                    .sum();
                (s / (3 * n) as f64).sqrt()
            };
            if !dyno.is_finite() {
                break Newton::Failed;
            }
            if newt > 1 && newt < NIT {
                let thq = dyno / dyno_old;
                self.theta = if newt == 2 {
                    thq
                } else {
                    (thq * thq_old).sqrt()
                };
                thq_old = thq;
                if self.theta < 0.99 {
                    self.faccon = self.theta / (1.0 - self.theta);
                    let dyth = self.faccon * dyno * self.theta.powi(NIT - 1 - newt) / self.fnewt;
                    if dyth >= 1.0 {
                        let qnewt = dyth.clamp(1e-4, 20.0);
                        break Newton::TooSlow(
                            0.8 * qnewt.powf(-1.0 / f64::from(4 + NIT - 1 - newt)),
                        );
                    }
                } else {
                    break Newton::Failed;
                }
            }
            dyno_old = dyno.max(UROUND);
            for i in 0..n {
                let w1 = f1[i] + z1[i];
                let w2 = f2[i] + z2[i];
                let w3 = f3[i] + z3[i];
                f1[i] = w1;
                f2[i] = w2;
                f3[i] = w3;
                z1[i] = T11 * w1 + T12 * w2 + T13 * w3;
                z2[i] = T21 * w1 + T22 * w2 + T23 * w3;
                z3[i] = T31 * w1 + w2;
            }
            if self.faccon * dyno <= self.fnewt {
                break Newton::Converged(newt);
            }
        }
    }

    /// A trial that failed before its error could be judged: halve h, and
    /// give up after too many in a row.
    fn retreat(&mut self, h: f64, failure: Failure) -> Trial {
        self.newton_failures += 1;
        if self.newton_failures >= MAX_NEWTON_FAILURES {
            return Trial::Failed(failure);
        }
        self.mark_rejected();
        Trial::Rejected { h_new: h * 0.5 }
    }

    fn mark_rejected(&mut self) {
        self.reject = true;
        self.need_lu = true;
        self.need_jac = !self.fresh_jac;
    }
}

impl Stepper for Radau5 {
    const METHOD: Method = Method::Radau5;
    const IMPLICIT: bool = true;

    fn new(n: usize, options: &SolverOptions) -> Self {
        let k = Coeffs::new();
        let zeros = || vec![0.0; n];
        let rtol = 0.1 * options.rtol.powf(2.0 / 3.0);
        let atol: Vec<f64> = options
            .atol
            .iter()
            .map(|a| a * rtol / options.rtol)
            .collect();
        let fnewt = (10.0 * UROUND / rtol).max(0.03f64.min(rtol.sqrt()));
        let dense = Dense {
            t: 0.0,
            h: 1.0,
            c1m1: k.c1m1,
            c2m1: k.c2m1,
            cont: [zeros(), zeros(), zeros(), zeros()],
        };
        Radau5 {
            k,
            options: options.clone(),
            rtol,
            atol,
            fnewt,
            fy: zeros(),
            scal: zeros(),
            tmp: zeros(),
            y_perturbed: zeros(),
            z: [zeros(), zeros(), zeros()],
            f: [zeros(), zeros(), zeros()],
            // Sized when a dense Jacobian is first needed.
            jac: Vec::new(),
            // Sized in `start`, which sees the system.
            matrices: NewtonMatrices::new(0, None),
            dense,
            h_old: 0.0,
            first: true,
            reject: false,
            faccon: 1.0,
            theta: THET,
            cfac: SAFE * f64::from(1 + 2 * NIT),
            h_acc: 0.0,
            err_acc: 1.0,
            need_jac: true,
            need_lu: true,
            fresh_jac: false,
            analytic: true,
            newton_failures: 0,
            accepted: 0,
            fac1: 0.0,
            alphn: 0.0,
            betan: 0.0,
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
        self.matrices = NewtonMatrices::for_system(system, t0, y0, &self.options);
        self.set_scal(y0);
        system.rhs(t0, y0, &mut self.fy);
        stats.rhs_calls += 1;
        if self.fy.iter().any(|v| !v.is_finite()) {
            return Err(Failure::NonFinite { t: t0 });
        }
        let h = match self.options.h0 {
            Some(h0) => h0,
            None => {
                stats.rhs_calls += 1;
                let inner = SolverOptions {
                    rtol: self.rtol,
                    atol: self.atol.clone(),
                    ..self.options.clone()
                };
                let [z1, z2, _] = &mut self.z;
                initial_step(system, t0, y0, &self.fy, 3, h_max, &inner, (z1, z2))
            }
        }
        .min(h_max);
        // The first step's interpolant is not used (the Newton start is
        // zero), so h_old only has to be finite; the controller starts here.
        self.h_old = h;
        self.h_acc = h;
        Ok(h)
    }

    fn end_stretch(&self) -> f64 {
        // Hairer stretches only the first step; later ones are compared
        // with t_end as they are (his quot1 = 1).
        if self.first { 1.0001 } else { 1.0 }
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
        let outcome = if self.prepare(system, t, y, h, stats) {
            self.newton(system, t, y, h, stats)
        } else {
            Newton::Failed
        };
        let newt = match outcome {
            Newton::Converged(newt) => newt,
            Newton::TooSlow(factor) => {
                self.mark_rejected();
                return Trial::Rejected { h_new: h * factor };
            }
            Newton::Failed => return self.retreat(h, Failure::NewtonFailure { t }),
        };

        // The embedded error estimate, filtered through (γ/h·I − J)⁻¹.
        let k = &self.k;
        let [z1, z2, z3] = self.z.each_ref().map(|v| v.as_slice());
        let [f1, f2, _] = self.f.each_mut().map(|v| v.as_mut_slice());
        let tmp = self.tmp.as_mut_slice();
        let [d1, d2, d3] = [k.dd[0] / h, k.dd[1] / h, k.dd[2] / h];
        for i in 0..n {
            f2[i] = d1 * z1[i] + d2 * z2[i] + d3 * z3[i];
            tmp[i] = f2[i] + self.fy[i];
        }
        self.matrices.solve_real(system, tmp, stats);
        let mut err = rms(tmp, &self.scal);
        if err >= 1.0 && err.is_finite() && (self.first || self.reject) {
            for i in 0..n {
                tmp[i] += y[i];
            }
            system.rhs(t, tmp, f1);
            stats.rhs_calls += 1;
            for i in 0..n {
                tmp[i] = f1[i] + f2[i];
            }
            self.matrices.solve_real(system, tmp, stats);
            err = rms(tmp, &self.scal);
        }
        if !err.is_finite() {
            return self.retreat(h, Failure::NonFinite { t });
        }
        let err = err.max(1e-10);
        let fac = SAFE.min(self.cfac / f64::from(newt + 2 * NIT));
        let mut quot = (err.powf(0.25) / fac).clamp(FACR, FACL);
        let mut h_new = h / quot;

        if err < 1.0 {
            self.first = false;
            self.newton_failures = 0;
            self.accepted += 1;
            if self.accepted > 1 {
                // Gustafsson's predictive controller.
                let facgus = (self.h_acc / h) * (err * err / self.err_acc).powf(0.25) / SAFE;
                quot = quot.max(facgus.clamp(FACR, FACL));
                h_new = h / quot;
            }
            self.h_acc = h;
            self.err_acc = err.max(1e-2);
            self.h_old = h;
            Trial::Accepted { h_new }
        } else {
            let h_new = if self.first { h * 0.1 } else { h_new };
            self.mark_rejected();
            Trial::Rejected { h_new }
        }
    }

    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        _system: &S,
        t: f64,
        h: f64,
        y: &mut Vec<f64>,
        _stats: &mut Stats,
    ) -> Result<(), Failure> {
        let k = &self.k;
        let [z1, z2, z3] = &self.z;
        let [c0, c1, c2, c3] = &mut self.dense.cont;
        for i in 0..y.len() {
            y[i] += z3[i];
            c0[i] = y[i];
            c1[i] = (z2[i] - z3[i]) / k.c2m1;
            let ak = (z1[i] - z2[i]) / k.c1mc2;
            let acont3 = (ak - z1[i] / k.c1) / k.c2;
            c2[i] = (ak - c1[i]) / k.c1m1;
            c3[i] = c2[i] - acont3;
        }
        let t_new = t + h;
        self.dense.t = t_new;
        self.dense.h = h;
        if y.iter().any(|v| !v.is_finite()) {
            return Err(Failure::NonFinite { t: t_new });
        }
        self.set_scal(y);
        Ok(())
    }

    fn dense(&self) -> &dyn DenseOutput {
        &self.dense
    }

    fn advance<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64],
        stats: &mut Stats,
    ) -> Result<(), Failure> {
        self.fresh_jac = false;
        system.rhs(t, y, &mut self.fy);
        stats.rhs_calls += 1;
        if self.fy.iter().any(|v| !v.is_finite()) {
            return Err(Failure::NonFinite { t });
        }
        Ok(())
    }

    fn next_step(&mut self, h: f64, h_next: f64, reaches_end: bool) -> f64 {
        self.reject = false;
        // Keep h, and with it the factorisations, while Newton converges
        // fast and the controller asks for a change within [QUOT1, QUOT2].
        if !reaches_end && self.theta <= THET && (QUOT1..=QUOT2).contains(&(h_next / h)) {
            return h;
        }
        if self.theta <= THET {
            self.need_lu = true;
        } else {
            self.need_jac = true;
        }
        h_next
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Radau IIA matrix A in closed form (Hairer & Wanner, Table IV.5.6).
    fn radau_a() -> [[f64; 3]; 3] {
        let s = 6f64.sqrt();
        [
            [
                (88.0 - 7.0 * s) / 360.0,
                (296.0 - 169.0 * s) / 1800.0,
                (-2.0 + 3.0 * s) / 225.0,
            ],
            [
                (296.0 + 169.0 * s) / 1800.0,
                (88.0 + 7.0 * s) / 360.0,
                (-2.0 - 3.0 * s) / 225.0,
            ],
            [(16.0 - s) / 36.0, (16.0 + s) / 36.0, 1.0 / 9.0],
        ]
    }

    fn mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
        let mut c = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                c[i][j] = (0..3).map(|l| a[i][l] * b[l][j]).sum();
            }
        }
        c
    }

    /// T⁻¹·A⁻¹·T must be diag(γ, [[α, −β], [β, α]]), i.e. A·T = T·Λ⁻¹ with the
    /// tabulated T and closed-form eigenvalues, and T⁻¹·T = I.
    #[test]
    fn tabulated_transformation_diagonalises_the_method() {
        let t = [[T11, T12, T13], [T21, T22, T23], [T31, 1.0, 0.0]];
        let ti = [[TI11, TI12, TI13], [TI21, TI22, TI23], [TI31, TI32, TI33]];
        let id = mul(&ti, &t);
        for i in 0..3 {
            for j in 0..3 {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((id[i][j] - want).abs() < 1e-14, "T⁻¹T = {id:?}");
            }
        }
        let k = Coeffs::new();
        // Λ = T⁻¹ A⁻¹ T, so T⁻¹ A T = Λ⁻¹.
        let lam_inv = mul(&ti, &mul(&radau_a(), &t));
        let g = 1.0 / k.u1;
        let den = k.alph * k.alph + k.beta * k.beta;
        let (ar, ai) = (k.alph / den, k.beta / den);
        let want = [[g, 0.0, 0.0], [0.0, ar, ai], [0.0, -ai, ar]];
        for i in 0..3 {
            for j in 0..3 {
                assert!(
                    (lam_inv[i][j] - want[i][j]).abs() < 1e-14,
                    "T⁻¹AT = {lam_inv:?}, want {want:?}"
                );
            }
        }
        // Row sums of A are the nodes; the last row is the weights (stiffly accurate).
        let a = radau_a();
        for (i, c) in [k.c1, k.c2, 1.0].into_iter().enumerate() {
            assert!((a[i].iter().sum::<f64>() - c).abs() < 1e-15);
        }
    }
}
