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

use super::lu::{ComplexLu, RealLu};
use super::norm::{atol_of, check_step, initial_step};
use super::{
    DenseOutput, Failure, Flow, OdeSystem, SolveReport, SolverOptions, Stats, Status, Step,
    StepObserver,
};

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
/// Consecutive failed Newton iterations (each halving h) before giving up.
const MAX_NEWTON_FAILURES: u32 = 10;

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

/// Integrate with RADAU5; see [`super::solve`].
pub fn solve<S: OdeSystem + ?Sized, O: StepObserver + ?Sized>(
    system: &S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    options: &SolverOptions,
    observer: &mut O,
) -> SolveReport {
    let n = y0.len();
    let k = Coeffs::new();
    let zeros = || vec![0.0; n];
    // Hairer's tolerance mapping (see the module docs).
    let rtol = 0.1 * options.rtol.powf(2.0 / 3.0);
    let atol: Vec<f64> = options
        .atol
        .iter()
        .map(|a| a * rtol / options.rtol)
        .collect();
    let fnewt = (10.0 * UROUND / rtol).max(0.03f64.min(rtol.sqrt()));
    let h_max = options.h_max.min(t_end - t0);

    let mut y = y0.to_vec();
    let (mut fy, mut scal, mut tmp) = (zeros(), zeros(), zeros());
    let (mut z1, mut z2, mut z3) = (zeros(), zeros(), zeros());
    let (mut f1, mut f2, mut f3) = (zeros(), zeros(), zeros());
    let mut jac = vec![0.0; n * n];
    let mut e1 = RealLu::new(n);
    let mut e2 = ComplexLu::new(n);
    let mut dense = Dense {
        t: t0,
        h: 1.0,
        c1m1: k.c1m1,
        c2m1: k.c2m1,
        cont: [zeros(), zeros(), zeros(), zeros()],
    };
    let mut stats = Stats::default();
    let report = |status, t, y, stats| SolveReport {
        status,
        t,
        y,
        stats,
    };
    let set_scal = |y: &[f64], scal: &mut [f64]| {
        for i in 0..n {
            scal[i] = atol_of(&atol, i) + rtol * y[i].abs();
        }
    };

    observer.start(t0, y0);
    let mut t = t0;
    set_scal(&y, &mut scal);
    system.rhs(t, &y, &mut fy);
    stats.rhs_calls += 1;
    if fy.iter().any(|v| !v.is_finite()) {
        return report(Status::Failed(Failure::NonFinite { t }), t, y, stats);
    }
    let mut h = match options.h0 {
        Some(h0) => h0,
        None => {
            stats.rhs_calls += 1;
            let inner = SolverOptions {
                rtol,
                atol: atol.clone(),
                ..options.clone()
            };
            initial_step(system, t0, &y, &fy, 3, h_max, &inner, (&mut z1, &mut z2))
        }
    }
    .min(h_max);
    let mut last = false;
    if t + h * 1.0001 >= t_end {
        h = t_end - t;
        last = true;
    }

    let mut h_old = h;
    let (mut first, mut reject) = (true, false);
    let mut faccon: f64 = 1.0;
    let mut theta = THET;
    let cfac = SAFE * f64::from(1 + 2 * NIT);
    let (mut h_acc, mut err_acc) = (h, 1.0);
    let (mut need_jac, mut need_lu, mut fresh_jac) = (true, true, false);
    let mut analytic = true;
    let mut newton_failures = 0;
    let (mut fac1, mut alphn, mut betan) = (0.0, 0.0, 0.0);

    loop {
        let mut singular = false;
        if need_jac {
            stats.jacobians += 1;
            if !(analytic && system.jacobian(t, &y, &mut jac)) {
                // Forward differences as in Hairer's code, against f(t, y) in `fy`.
                analytic = false;
                for j in 0..n {
                    let ysafe = y[j];
                    let delt = (UROUND * ysafe.abs().max(1e-5)).sqrt();
                    y[j] = ysafe + delt;
                    system.rhs(t, &y, &mut tmp);
                    for i in 0..n {
                        jac[i * n + j] = (tmp[i] - fy[i]) / delt;
                    }
                    y[j] = ysafe;
                }
                stats.rhs_calls += n as u64;
            }
            fresh_jac = true;
            need_jac = false;
            need_lu = true;
        }
        if need_lu {
            fac1 = k.u1 / h;
            alphn = k.alph / h;
            betan = k.beta / h;
            stats.factorizations += 1;
            singular = !(e1.factor_shifted(fac1, &jac) && e2.factor_shifted(alphn, betan, &jac));
            need_lu = singular;
        }

        if let Err(f) = check_step(t, h, &stats, options) {
            return report(Status::Failed(f), t, y, stats);
        }
        let t_new = t + h;

        let outcome = if singular {
            Newton::Failed
        } else {
            // Starting values: zero on the first step, else the last
            // collocation polynomial extrapolated over the new step.
            if first {
                for v in [&mut z1, &mut z2, &mut z3, &mut f1, &mut f2, &mut f3] {
                    v.fill(0.0);
                }
            } else {
                let c3q = h / h_old;
                let (c1q, c2q) = (k.c1 * c3q, k.c2 * c3q);
                let [_, a1, a2, a3] = &dense.cont;
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
            faccon = faccon.max(UROUND).powf(0.8);
            theta = THET;
            let mut newt = 0;
            let (mut dyno_old, mut thq_old) = (1.0, 1.0);
            loop {
                if newt >= NIT {
                    break Newton::Failed;
                }
                for (z, c) in [(&mut z1, k.c1), (&mut z2, k.c2)] {
                    for i in 0..n {
                        tmp[i] = y[i] + z[i];
                    }
                    system.rhs(t + c * h, &tmp, z);
                }
                for i in 0..n {
                    tmp[i] = y[i] + z3[i];
                }
                system.rhs(t_new, &tmp, &mut z3);
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
                e1.solve(&mut z1);
                e2.solve(&mut z2, &mut z3);
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
                    theta = if newt == 2 {
                        thq
                    } else {
                        (thq * thq_old).sqrt()
                    };
                    thq_old = thq;
                    if theta < 0.99 {
                        faccon = theta / (1.0 - theta);
                        let dyth = faccon * dyno * theta.powi(NIT - 1 - newt) / fnewt;
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
                if faccon * dyno <= fnewt {
                    break Newton::Converged(newt);
                }
            }
        };

        let newt = match outcome {
            Newton::Converged(newt) => newt,
            Newton::TooSlow(factor) => {
                stats.rejected += 1;
                h *= factor;
                reject = true;
                last = false;
                need_lu = true;
                need_jac = !fresh_jac;
                continue;
            }
            Newton::Failed => {
                stats.rejected += 1;
                newton_failures += 1;
                if newton_failures >= MAX_NEWTON_FAILURES {
                    return report(Status::Failed(Failure::NewtonFailure { t }), t, y, stats);
                }
                h *= 0.5;
                reject = true;
                last = false;
                need_lu = true;
                need_jac = !fresh_jac;
                continue;
            }
        };

        // Error estimate: the embedded 3rd-order difference, smoothed by
        // (γ/h·I − J)⁻¹ so that it stays bounded for stiff components.
        let [d1, d2, d3] = [k.dd[0] / h, k.dd[1] / h, k.dd[2] / h];
        for i in 0..n {
            f2[i] = d1 * z1[i] + d2 * z2[i] + d3 * z3[i];
            tmp[i] = f2[i] + fy[i];
        }
        e1.solve(&mut tmp);
        let mut err = rms(&tmp, &scal);
        if err >= 1.0 && err.is_finite() && (first || reject) {
            // After a rejection the plain estimate can be far too pessimistic
            // for stiff components: apply the filter once more (Hairer).
            for i in 0..n {
                tmp[i] += y[i];
            }
            system.rhs(t, &tmp, &mut f1);
            stats.rhs_calls += 1;
            for i in 0..n {
                tmp[i] = f1[i] + f2[i];
            }
            e1.solve(&mut tmp);
            err = rms(&tmp, &scal);
        }
        if !err.is_finite() {
            stats.rejected += 1;
            newton_failures += 1;
            if newton_failures >= MAX_NEWTON_FAILURES {
                return report(Status::Failed(Failure::NonFinite { t }), t, y, stats);
            }
            h *= 0.5;
            reject = true;
            last = false;
            need_lu = true;
            need_jac = !fresh_jac;
            continue;
        }
        let err = err.max(1e-10);
        let fac = SAFE.min(cfac / f64::from(newt + 2 * NIT));
        let mut quot = (err.powf(0.25) / fac).clamp(FACR, FACL);
        let mut h_new = h / quot;

        if err < 1.0 {
            first = false;
            newton_failures = 0;
            stats.steps += 1;
            if stats.steps > 1 {
                // Gustafsson's predictive controller.
                let facgus = (h_acc / h) * (err * err / err_acc).powf(0.25) / SAFE;
                quot = quot.max(facgus.clamp(FACR, FACL));
                h_new = h / quot;
            }
            h_acc = h;
            err_acc = err.max(1e-2);
            h_old = h;
            let t_prev = t;
            t = t_new;
            {
                let [c0, c1, c2, c3] = &mut dense.cont;
                for i in 0..n {
                    y[i] += z3[i];
                    c0[i] = y[i];
                    c1[i] = (z2[i] - z3[i]) / k.c2m1;
                    let ak = (z1[i] - z2[i]) / k.c1mc2;
                    let acont3 = (ak - z1[i] / k.c1) / k.c2;
                    c2[i] = (ak - c1[i]) / k.c1m1;
                    c3[i] = c2[i] - acont3;
                }
            }
            dense.t = t;
            dense.h = h;
            if y.iter().any(|v| !v.is_finite()) {
                return report(Status::Failed(Failure::NonFinite { t }), t, y, stats);
            }
            set_scal(&y, &mut scal);
            let flow = observer.step(&Step {
                t_prev,
                t,
                y: &y,
                dense: &dense,
            });
            if flow == Flow::Stop {
                return report(Status::Stopped, t, y, stats);
            }
            if last || t >= t_end {
                return report(Status::Finished, t, y, stats);
            }
            fresh_jac = false;
            system.rhs(t, &y, &mut fy);
            stats.rhs_calls += 1;
            if fy.iter().any(|v| !v.is_finite()) {
                return report(Status::Failed(Failure::NonFinite { t }), t, y, stats);
            }
            h_new = h_new.min(h_max);
            if reject {
                h_new = h_new.min(h);
            }
            reject = false;
            if t + h_new / QUOT1 >= t_end {
                h = t_end - t;
                last = true;
            } else {
                let qt = h_new / h;
                if theta <= THET && (QUOT1..=QUOT2).contains(&qt) {
                    // Same Jacobian and LU: h is kept as it is.
                    continue;
                }
                h = h_new;
            }
            if theta <= THET {
                need_lu = true;
            } else {
                need_jac = true;
            }
        } else {
            stats.rejected += 1;
            reject = true;
            last = false;
            h = if first { h * 0.1 } else { h_new };
            need_lu = true;
            need_jac = !fresh_jac;
        }
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
