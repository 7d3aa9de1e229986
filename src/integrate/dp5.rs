//! Dormand–Prince 5(4) (Hairer's DOPRI5): explicit, adaptive, FSAL, with the
//! 4th-order continuous extension for dense output and PI step-size control.

use super::norm::{check_step, error_norm, initial_step};
use super::{
    DenseOutput, Failure, Flow, OdeSystem, SolveReport, SolverOptions, Stats, Status, Step,
    StepObserver,
};

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

/// Integrate with DOPRI5; see [`super::solve`].
pub fn solve<S: OdeSystem + ?Sized, O: StepObserver + ?Sized>(
    system: &S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    options: &SolverOptions,
    observer: &mut O,
) -> SolveReport {
    let n = y0.len();
    let zeros = || vec![0.0; n];
    let (mut y, mut y1, mut ystage) = (y0.to_vec(), zeros(), zeros());
    let (mut k1, mut k2, mut k3, mut k4, mut k5, mut k6, mut k7) = (
        zeros(),
        zeros(),
        zeros(),
        zeros(),
        zeros(),
        zeros(),
        zeros(),
    );
    let mut err = zeros();
    let mut dense = Dense {
        t_old: t0,
        h: 1.0,
        r: [zeros(), zeros(), zeros(), zeros(), zeros()],
    };
    let mut stats = Stats::default();
    let (rtol, atol) = (options.rtol, &options.atol[..]);
    let h_max = options.h_max.min(t_end - t0);

    observer.start(t0, y0);
    system.rhs(t0, &y, &mut k1);
    stats.rhs_calls += 1;
    let mut h = match options.h0 {
        Some(h0) => h0.min(h_max),
        None => {
            stats.rhs_calls += 1;
            initial_step(system, t0, &y, &k1, 5, h_max, options, (&mut k2, &mut k3))
        }
    };
    let mut t = t0;
    let mut fac_old: f64 = 1e-4;
    // Hairer's stiffness test: h·|λ| estimated from the last two stages.
    let (mut stiff_count, mut non_stiff_count) = (0u32, 0u32);
    let mut last_rejected = false;
    let fail = |status, t, y: Vec<f64>, stats| SolveReport {
        status,
        t,
        y,
        stats,
    };

    loop {
        if let Err(f) = check_step(t, h, &stats, options) {
            return fail(Status::Failed(f), t, y, stats);
        }
        let last = t + 1.01 * h >= t_end;
        if last {
            h = t_end - t;
        }
        for i in 0..n {
            ystage[i] = y[i] + h * A21 * k1[i];
        }
        system.rhs(t + C2 * h, &ystage, &mut k2);
        for i in 0..n {
            ystage[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        system.rhs(t + C3 * h, &ystage, &mut k3);
        for i in 0..n {
            ystage[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        system.rhs(t + C4 * h, &ystage, &mut k4);
        for i in 0..n {
            ystage[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        system.rhs(t + C5 * h, &ystage, &mut k5);
        for i in 0..n {
            ystage[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        let t_new = t + h;
        system.rhs(t_new, &ystage, &mut k6);
        for i in 0..n {
            y1[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        system.rhs(t_new, &y1, &mut k7);
        stats.rhs_calls += 6;
        for i in 0..n {
            err[i] =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        }
        let e = error_norm(&err, &y, &y1, rtol, atol);
        if !e.is_finite() {
            // A non-finite trial usually means the step was far too large; shrink
            // hard, and give up only when the state itself is already bad.
            if y.iter().any(|v| !v.is_finite()) {
                return fail(Status::Failed(Failure::NonFinite { t }), t, y, stats);
            }
            stats.rejected += 1;
            h *= FAC_MIN;
            last_rejected = true;
            continue;
        }
        // PI controller (Hairer's DOPRI5 with β = 0.04).
        let fac11 = e.powf(0.2 - BETA * 0.75);
        if e <= 1.0 {
            let fac = (fac11 / fac_old.powf(BETA) / SAFE).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
            let mut h_new = h / fac;
            fac_old = e.max(1e-4);
            stats.steps += 1;
            if options.detect_stiffness {
                let (mut num, mut den) = (0.0, 0.0);
                for i in 0..n {
                    num += (k7[i] - k6[i]).powi(2);
                    den += (y1[i] - ystage[i]).powi(2);
                }
                if den > 0.0 && h * (num / den).sqrt() > 3.25 {
                    non_stiff_count = 0;
                    stiff_count += 1;
                    if stiff_count == 15 {
                        let f = Failure::StiffnessDetected { t };
                        return fail(Status::Failed(f), t, y, stats);
                    }
                } else {
                    non_stiff_count += 1;
                    if non_stiff_count == 6 {
                        stiff_count = 0;
                    }
                }
            }
            // Dense output coefficients for [t, t + h].
            {
                let [r1, r2, r3, r4, r5] = &mut dense.r;
                for i in 0..n {
                    let ydiff = y1[i] - y[i];
                    let bspl = h * k1[i] - ydiff;
                    r1[i] = y[i];
                    r2[i] = ydiff;
                    r3[i] = bspl;
                    r4[i] = ydiff - h * k7[i] - bspl;
                    r5[i] = h
                        * (D1 * k1[i]
                            + D3 * k3[i]
                            + D4 * k4[i]
                            + D5 * k5[i]
                            + D6 * k6[i]
                            + D7 * k7[i]);
                }
            }
            dense.t_old = t;
            dense.h = h;
            std::mem::swap(&mut k1, &mut k7);
            std::mem::swap(&mut y, &mut y1);
            t = t_new;
            if last_rejected {
                h_new = h_new.min(h);
            }
            last_rejected = false;
            let flow = observer.step(&Step {
                t_prev: dense.t_old,
                t,
                y: &y,
                dense: &dense,
            });
            if flow == Flow::Stop {
                return SolveReport {
                    status: Status::Stopped,
                    t,
                    y,
                    stats,
                };
            }
            if last || t >= t_end {
                return SolveReport {
                    status: Status::Finished,
                    t,
                    y,
                    stats,
                };
            }
            h = h_new.min(h_max);
        } else {
            stats.rejected += 1;
            h /= (fac11 / SAFE).min(1.0 / FAC_MIN);
            last_rejected = true;
        }
    }
}
