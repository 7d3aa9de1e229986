//! Lean reference for autobal's default path (issue 17, item 6).
//!
//! Reads the runs written by `autobal-bench --lean-inputs FILE` and redoes each
//! one in the rotating frame with the least code that gives the same answer:
//! a minimal Dormand–Prince 5(4) (Hairer's DOPRI5 coefficients, error norm,
//! PI step control, initial step rule and 4th-order dense output, as in
//! autobal's `src/integrate/{dp5,controller,norm}.rs` and driver), the
//! rotating-frame right-hand side with drag and contact (autobal's
//! `RotatingSystem::rhs`, same operations in the same order), and the
//! settling rule of autobal's observer on the whirl radius alone.
//!
//! What it leaves out, being a reference and not a tool: stiffness detection
//! and the hand-over to Radau5 (a run autobal switched just goes on with
//! DP5), the balancing-error, gap and residual metrics, recording, and every
//! check a user's input would need. Dense output is formed only for u and v,
//! the components the settling rule reads.
//!
//! Usage: autobal-lean RUNS.csv [--rounds R] [--quiet]
//! Times every run single-threaded (R rounds over all runs; the fastest
//! round and the median are reported) and compares settling times and RHS
//! calls with autobal's, which the CSV carries.

use std::collections::HashMap;
use std::f64::consts::{PI, TAU};
use std::time::Instant;

// Hairer's DOPRI5 tableau, error weights and dense-output weights.
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
// PI controller of DOPRI5: safety, step-change bounds, gain.
const SAFE: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 10.0;
const BETA: f64 = 0.04;

/// One exported run: the equations' constants, the solver's and the
/// observer's, and autobal's answer.
struct Run {
    run_id: u64,
    model: Model,
    y0: Vec<f64>,
    rtol: f64,
    atol: Vec<f64>,
    max_steps: u64,
    t_end: f64,
    dt: f64,
    samples_per_rev: u32,
    band: f64,
    window: f64,
    divergence_limit: f64,
    autobal_outcome: String,
    autobal_settling_revs: Option<f64>,
    autobal_rhs_calls: u64,
    autobal_method: String,
}

/// The rotating-frame equations of one run, constants precomputed.
struct Model {
    n: usize,
    omega: f64,
    m_total: f64,
    k: f64,
    b: f64,
    force: (f64, f64),
    /// m_j l_j.
    ml: Vec<f64>,
    inertia: Vec<f64>,
    /// β_j l_j², when any weight has drag.
    drag: Option<Vec<f64>>,
    /// (α_j, k_θ, c_θ) per weight, when the scene has contact.
    contact: Option<Vec<(f64, f64, f64)>>,
}

/// Angle wrapped to (−π, π], as autobal's contact effect wraps it.
fn wrapped(d: f64) -> f64 {
    let w = d.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

impl Model {
    /// f(y) into `f`; `trig` is n scratch slots for (sin ψ, cos ψ), so that
    /// a call allocates nothing and evaluates the trig once per weight.
    #[inline]
    fn rhs(&self, y: &[f64], f: &mut [f64], trig: &mut [(f64, f64)]) {
        let n = self.n;
        let nq = 2 + n;
        let (q, qd) = y.split_at(nq);
        f[..nq].copy_from_slice(qd);
        let (u, v, ud, vd) = (q[0], q[1], qd[0], qd[1]);
        let w = self.omega;
        let (fr, fi) = (-2.0 * w * vd - w * w * u, 2.0 * w * ud - w * w * v);
        let mut gr = -self.m_total * fr - self.b * (ud - w * v) - self.k * u + self.force.0;
        let mut gi = -self.m_total * fi - self.b * (vd + w * u) - self.k * v + self.force.1;
        let (psi, rate) = (&q[2..], &qd[2..]);
        let cf = &mut f[nq + 2..];
        // −0.0 as autobal starts its force sums: the results stay bit-identical.
        match &self.drag {
            Some(drag) => {
                for j in 0..n {
                    cf[j] = -0.0 - drag[j] * rate[j];
                }
            }
            None => cf.fill(-0.0),
        }
        if let Some(contact) = &self.contact {
            for j in 0..n {
                let (aj, kj, cj) = contact[j];
                if aj == 0.0 {
                    continue;
                }
                for k in j + 1..n {
                    let (ak, kk, ck) = contact[k];
                    if ak == 0.0 {
                        continue;
                    }
                    let d = wrapped(psi[k] - psi[j]);
                    let overlap = (aj + ak) - d.abs();
                    if overlap <= 0.0 {
                        continue;
                    }
                    let dir = if d >= 0.0 { 1.0 } else { -1.0 };
                    let overlap_rate = -dir * (rate[k] - rate[j]);
                    let torque = (kj.min(kk) * overlap + cj.min(ck) * overlap_rate).max(0.0);
                    cf[k] += dir * torque;
                    cf[j] -= dir * torque;
                }
            }
        }
        // Eliminate the weights' rows into the 2×2 head (the arrowhead system).
        let (mut a11, mut a12, mut a22) = (self.m_total, 0.0, self.m_total);
        for j in 0..n {
            let (s, co) = libm::sincos(psi[j]);
            trig[j] = (s, co);
            let ml = self.ml[j];
            let rt = w + rate[j];
            gr += ml * rt * rt * co;
            gi += ml * rt * rt * s;
            let qj = cf[j] - ml * (fi * co - fr * s);
            cf[j] = qj;
            let (wr, wi) = (-ml * s, ml * co);
            let inv = 1.0 / self.inertia[j];
            a11 -= wr * wr * inv;
            a12 -= wr * wi * inv;
            a22 -= wi * wi * inv;
            gr -= wr * qj * inv;
            gi -= wi * qj * inv;
        }
        let det = a11 * a22 - a12 * a12;
        let ar = (gr * a22 - gi * a12) / det;
        let ai = (gi * a11 - gr * a12) / det;
        for j in 0..n {
            let (s, co) = trig[j];
            cf[j] = (cf[j] - self.ml[j] * (co * ai - s * ar)) / self.inertia[j];
        }
        f[nq] = ar;
        f[nq + 1] = ai;
    }
}

/// How a lean run ended.
#[derive(Debug, Clone, Copy, PartialEq)]
enum End {
    /// r stayed in the band for the hold window from this time.
    Settled(f64),
    /// Reached t_end without settling.
    Censored,
    /// r non-finite or beyond the divergence limit.
    Diverged,
    /// Step budget or step-size underflow.
    Failed,
}

/// What one lean run produced.
struct Answer {
    end: End,
    rhs_calls: u64,
}

/// autobal's settling rule on r = |(u, v)| sampled at t0 + k·dt: settled at
/// the start of the first stretch inside the band that lasts the window
/// (the speed is constant, so every sample counts as at operating speed).
struct Observer {
    dt: f64,
    band: f64,
    window: f64,
    divergence_limit: f64,
    next_index: u64,
    stretch_start: Option<f64>,
}

impl Observer {
    /// One sample; `Some(end)` stops the run.
    #[inline]
    fn sample(&mut self, t: f64, u: f64, v: f64) -> Option<End> {
        let r = u.hypot(v);
        if !r.is_finite() || r > self.divergence_limit {
            return Some(End::Diverged);
        }
        if r <= self.band {
            let start = *self.stretch_start.get_or_insert(t);
            if t - start >= self.window {
                return Some(End::Settled(start));
            }
        } else {
            self.stretch_start = None;
        }
        None
    }
}

/// Hairer's initial step guess (order 5): one Euler step for the second derivative.
fn initial_step(
    run: &Run,
    y0: &[f64],
    f0: &[f64],
    h_max: f64,
    y1: &mut [f64],
    f1: &mut [f64],
    trig: &mut [(f64, f64)],
) -> f64 {
    let n = y0.len() as f64;
    let (mut dnf, mut dny) = (0.0, 0.0);
    for i in 0..y0.len() {
        let sk = run.atol[i] + run.rtol * y0[i].abs();
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
    run.model.rhs(y1, f1, trig);
    let mut der2 = 0.0;
    for i in 0..y0.len() {
        let sk = run.atol[i] + run.rtol * y0[i].abs();
        der2 += ((f1[i] - f0[i]) / sk).powi(2);
    }
    let der2 = (der2 / n).sqrt() / h;
    let der12 = der2.max((dnf / n).sqrt());
    let h1 = if der12 <= 1e-15 {
        (h * 1e-3).max(1e-6)
    } else {
        (0.01 / der12).powf(1.0 / 6.0)
    };
    (100.0 * h).min(h1).min(h_max)
}

/// Integrate one run with DP5 from t = 0 until it settles (plus the hold
/// window, which the rule includes), diverges or reaches t_end.
fn solve(run: &Run) -> Answer {
    let model = &run.model;
    let dim = run.y0.len();
    // Every work vector once per run; the step loop allocates nothing.
    let mut k: [Vec<f64>; 7] = std::array::from_fn(|_| vec![0.0; dim]);
    let mut y = run.y0.clone();
    let mut y1 = vec![0.0; dim];
    let mut ys = vec![0.0; dim];
    let mut trig = vec![(0.0, 0.0); model.n];
    let mut obs = Observer {
        dt: run.dt,
        band: run.band,
        window: run.window,
        divergence_limit: run.divergence_limit,
        next_index: 1,
        stretch_start: None,
    };
    let (t0, t_end) = (0.0, run.t_end);
    let mut calls = 0u64;
    let answer = |end, calls| Answer {
        end,
        rhs_calls: calls,
    };
    // Sample zero; as in autobal, it cannot stop the run.
    let _ = obs.sample(t0, y[0], y[1]);
    model.rhs(&y, &mut k[0], &mut trig);
    let h_max = t_end - t0;
    let mut h = {
        let [k0, k1, k2, ..] = &mut k;
        initial_step(run, &y, k0, h_max, k1, k2, &mut trig)
    }
    .min(h_max);
    calls += 2;

    let expo = 0.2 - BETA * 0.75;
    let mut err_old: f64 = 1e-4;
    let (mut steps, mut rejected) = (0u64, 0u64);
    let mut last_rejected = false;
    let mut t = t0;
    // Dense output of u and v only: Hairer's five coefficients each.
    let mut rc = [[0.0f64; 5]; 2];
    let n = dim as f64;
    loop {
        if steps + rejected >= run.max_steps || 0.1 * h.abs() <= t.abs() * f64::EPSILON {
            return answer(End::Failed, calls);
        }
        let last = t + 1.01 * h >= t_end;
        if last {
            h = t_end - t;
        }
        let [k1, k2, k3, k4, k5, k6, k7] = k.each_mut().map(|v| v.as_mut_slice());
        for i in 0..dim {
            ys[i] = y[i] + h * A21 * k1[i];
        }
        model.rhs(&ys, k2, &mut trig);
        for i in 0..dim {
            ys[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        model.rhs(&ys, k3, &mut trig);
        for i in 0..dim {
            ys[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        model.rhs(&ys, k4, &mut trig);
        for i in 0..dim {
            ys[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        model.rhs(&ys, k5, &mut trig);
        for i in 0..dim {
            ys[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        model.rhs(&ys, k6, &mut trig);
        for i in 0..dim {
            y1[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        model.rhs(&y1, k7, &mut trig);
        calls += 6;
        // Hairer's RMS error norm, fused with the error estimate.
        let mut sum = 0.0;
        for i in 0..dim {
            let e =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
            let r = e / (run.atol[i] + run.rtol * y[i].abs().max(y1[i].abs()));
            sum += r * r;
        }
        let err = (sum / n).sqrt();
        if !err.is_finite() {
            if y.iter().any(|v| !v.is_finite()) {
                return answer(End::Diverged, calls);
            }
            rejected += 1;
            h *= FAC_MIN;
            last_rejected = true;
            continue;
        }
        let fac11 = err.powf(expo);
        if err > 1.0 {
            rejected += 1;
            h /= (fac11 / SAFE).min(1.0 / FAC_MIN);
            last_rejected = true;
            continue;
        }
        let fac = (fac11 / err_old.powf(BETA) / SAFE).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
        err_old = err.max(1e-4);
        let h_new = h / fac;
        steps += 1;
        for (i, r) in rc.iter_mut().enumerate() {
            let ydiff = y1[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            *r = [
                y[i],
                ydiff,
                bspl,
                ydiff - h * k7[i] - bspl,
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]),
            ];
        }
        let t_old = t;
        t = t_old + h;
        // FSAL: f at the new point starts the next step.
        k.swap(0, 6);
        std::mem::swap(&mut y, &mut y1);
        loop {
            let ts = t0 + obs.next_index as f64 * obs.dt;
            if ts > t {
                break;
            }
            let s = (ts - t_old) / h;
            let s1 = 1.0 - s;
            let [u, v] = rc.map(|r| r[0] + s * (r[1] + s1 * (r[2] + s * (r[3] + s1 * r[4]))));
            obs.next_index += 1;
            if let Some(end) = obs.sample(ts, u, v) {
                return answer(end, calls);
            }
        }
        if last || t >= t_end {
            return answer(End::Censored, calls);
        }
        let mut h_next = h_new.min(h_max);
        if last_rejected {
            h_next = h_next.min(h);
        }
        last_rejected = false;
        h = h_next;
    }
}

/// Parse the CSV of `autobal-bench --lean-inputs` (no quoting: no cell holds a comma).
fn read_runs(path: &str) -> Result<Vec<Run>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let mut lines = text.lines();
    let header: HashMap<&str, usize> = lines
        .next()
        .ok_or("empty file")?
        .split(',')
        .enumerate()
        .map(|(i, c)| (c, i))
        .collect();
    let mut runs = Vec::new();
    for (no, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        let cell = |name: &str| -> Result<&str, String> {
            let i = *header.get(name).ok_or(format!("no column {name}"))?;
            cells
                .get(i)
                .copied()
                .ok_or(format!("line {}: no cell {name}", no + 2))
        };
        let num = |name: &str| -> Result<f64, String> {
            cell(name)?
                .parse::<f64>()
                .map_err(|e| format!("line {}: {name}: {e}", no + 2))
        };
        let int = |name: &str| -> Result<u64, String> {
            cell(name)?
                .parse::<u64>()
                .map_err(|e| format!("line {}: {name}: {e}", no + 2))
        };
        let list = |name: &str| -> Result<Vec<f64>, String> {
            let c = cell(name)?;
            if c.is_empty() {
                return Ok(Vec::new());
            }
            c.split(';')
                .map(|v| {
                    v.parse::<f64>()
                        .map_err(|e| format!("line {}: {name}: {e}", no + 2))
                })
                .collect()
        };
        let n = int("n")? as usize;
        let (mass, l, drag) = (list("mass")?, list("track_radius")?, list("drag")?);
        let (alpha, kc, cc) = (
            list("contact_half_angle")?,
            list("contact_stiffness")?,
            list("contact_damping")?,
        );
        let model = Model {
            n,
            omega: num("omega")?,
            // As autobal sums them: rotor mass plus the weights' sum.
            m_total: num("rotor_mass")? + mass.iter().sum::<f64>(),
            k: num("k")?,
            b: num("b")?,
            force: (num("unbalance_force_u")?, num("unbalance_force_v")?),
            ml: mass.iter().zip(&l).map(|(m, l)| m * l).collect(),
            inertia: list("inertia")?,
            drag: drag
                .iter()
                .any(|&d| d != 0.0)
                .then(|| drag.iter().zip(&l).map(|(d, l)| d * l * l).collect()),
            contact: (!alpha.is_empty())
                .then(|| (0..n).map(|j| (alpha[j], kc[j], cc[j])).collect()),
        };
        let revs = cell("autobal_settling_revs")?;
        runs.push(Run {
            run_id: int("run_id")?,
            model,
            y0: list("y0")?,
            rtol: num("rtol")?,
            atol: list("atol")?,
            max_steps: int("max_steps")?,
            t_end: num("t_end")?,
            dt: num("dt")?,
            samples_per_rev: int("samples_per_rev")? as u32,
            band: num("band")?,
            window: num("window")?,
            divergence_limit: num("divergence_limit")?,
            autobal_outcome: cell("autobal_outcome")?.to_string(),
            autobal_settling_revs: if revs.is_empty() {
                None
            } else {
                Some(
                    revs.parse()
                        .map_err(|e| format!("autobal_settling_revs: {e}"))?,
                )
            },
            autobal_rhs_calls: int("autobal_rhs_calls")?,
            autobal_method: cell("autobal_method")?.to_string(),
        });
        let r = runs.last().expect("just pushed");
        if r.y0.len() != 2 * (2 + n) || r.atol.len() != r.y0.len() {
            return Err(format!(
                "line {}: state size does not match n = {n}",
                no + 2
            ));
        }
    }
    Ok(runs)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1).filter(|a| !a.starts_with("--")) else {
        eprintln!("usage: autobal-lean RUNS.csv [--rounds R] [--quiet]");
        std::process::exit(2);
    };
    let rounds: usize = args
        .iter()
        .position(|a| a == "--rounds")
        .and_then(|i| args.get(i + 1))
        .map_or(1, |r| r.parse().expect("--rounds takes a whole number"))
        .max(1);
    let quiet = args.iter().any(|a| a == "--quiet");
    let runs = match read_runs(path) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    };

    // Timed: every run, one after the other, on this thread; each run's
    // time too (two clock reads per run of about a millisecond), so that the
    // runs autobal kept on DP5 and those it handed to Radau5 can be told apart.
    let mut round_s = Vec::new();
    let mut answers = Vec::new();
    let mut run_s = vec![f64::INFINITY; runs.len()];
    for _ in 0..rounds {
        let clock = Instant::now();
        answers = runs
            .iter()
            .zip(run_s.iter_mut())
            .map(|(run, best)| {
                let c = Instant::now();
                let a = solve(run);
                *best = best.min(c.elapsed().as_secs_f64());
                a
            })
            .collect::<Vec<_>>();
        round_s.push(clock.elapsed().as_secs_f64());
    }
    let mut sorted = round_s.clone();
    sorted.sort_by(f64::total_cmp);
    let median_s = sorted[sorted.len() / 2];

    // Same answers as autobal?
    let mut same_time = 0usize;
    let mut same_calls = 0usize;
    let mut dp5_runs = 0usize;
    let mut mismatches = Vec::new();
    for (run, a) in runs.iter().zip(&answers) {
        let rev = run.dt * f64::from(run.samples_per_rev);
        let lean_revs = match a.end {
            End::Settled(t) => Some(t / rev),
            _ => None,
        };
        if lean_revs == run.autobal_settling_revs {
            same_time += 1;
        } else {
            mismatches.push(format!(
                "run {}: lean {:?} ({:?}), autobal {:?} ({}, {}); Δ = {} samples",
                run.run_id,
                lean_revs,
                a.end,
                run.autobal_settling_revs,
                run.autobal_outcome,
                run.autobal_method,
                match (lean_revs, run.autobal_settling_revs) {
                    (Some(l), Some(r)) =>
                        format!("{:.0}", (l - r) * f64::from(run.samples_per_rev)),
                    _ => "–".into(),
                }
            ));
        }
        if run.autobal_method == "dp5" {
            dp5_runs += 1;
            if a.rhs_calls == run.autobal_rhs_calls {
                same_calls += 1;
            }
        }
    }
    let total = runs.len();
    let calls: u64 = answers.iter().map(|a| a.rhs_calls).sum();
    let autobal_calls: u64 = runs.iter().map(|r| r.autobal_rhs_calls).sum();
    let switched = runs.iter().filter(|r| r.autobal_method != "dp5").count();
    let settled = answers
        .iter()
        .filter(|a| matches!(a.end, End::Settled(_)))
        .count();
    if !quiet {
        println!(
            "lean DP5 reference: {total} runs, {rounds} round(s), single thread, profile {}",
            if cfg!(debug_assertions) {
                "release (opt-level 2 + debug assertions, as autobal's dev profile)"
            } else {
                "full (opt-level 3)"
            }
        );
        println!(
            "  time: median round {:.3} s, fastest {:.3} s -> {:.0} runs/s per core",
            median_s,
            sorted[0],
            total as f64 / median_s
        );
        println!(
            "  RHS calls per run: lean {:.0}, autobal {:.0};  {:.1} ns per RHS call (whole run / RHS calls)",
            calls as f64 / total as f64,
            autobal_calls as f64 / total as f64,
            1e9 * median_s / calls as f64
        );
        println!(
            "  settled: {settled}/{total}; settling time identical to autobal's: {same_time}/{total}; \
             RHS calls identical on the {dp5_runs} runs autobal kept on dp5: {same_calls}/{dp5_runs}; \
             {switched} runs autobal switched to radau5 (lean stays on DP5)"
        );
        for (label, kept) in [
            ("kept on dp5 by autobal", true),
            ("switched to radau5 by autobal", false),
        ] {
            let pick: Vec<usize> = (0..total)
                .filter(|&i| (runs[i].autobal_method == "dp5") == kept)
                .collect();
            if pick.is_empty() {
                continue;
            }
            let secs: f64 = pick.iter().map(|&i| run_s[i]).sum();
            let lean: u64 = pick.iter().map(|&i| answers[i].rhs_calls).sum();
            let ours: u64 = pick.iter().map(|&i| runs[i].autobal_rhs_calls).sum();
            println!(
                "  {} runs {label}: {:.0} runs/s, RHS calls per run lean {:.0} / autobal {:.0}, {:.1} ns per RHS call (fastest round per run)",
                pick.len(),
                pick.len() as f64 / secs,
                lean as f64 / pick.len() as f64,
                ours as f64 / pick.len() as f64,
                1e9 * secs / lean as f64
            );
        }
        for m in &mismatches {
            println!("  mismatch: {m}");
        }
    }
    // For scripts (bench/lean/run.sh): one summary line, then each run's
    // best time and RHS calls.
    for (run, (a, secs)) in runs.iter().zip(answers.iter().zip(&run_s)) {
        println!("LEANRUN {} {secs} {}", run.run_id, a.rhs_calls);
    }
    println!(
        "LEAN runs={total} rounds={rounds} median_s={median_s} min_s={} rhs_calls={calls} same_settling={same_time} switched={switched} same_calls_dp5={same_calls}/{dp5_runs}",
        sorted[0]
    );
}
