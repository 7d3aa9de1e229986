//! The end of a run: the observations and the solver's report turned into
//! the run's metrics, its outcome classified.

use super::*;
use crate::metrics::Budget;
use crate::metrics::reference::plane_whirls;

/// Where the run ended and what the holds measured there, borrowed from the
/// observer or the solver's report: the state that classifying the outcome
/// and filling the metrics share, so neither copies it.
struct Ending<'a> {
    /// One revolution of the sampling clock (s).
    rev: f64,
    /// The run's end: the certifying sample, the horizon, or the solver's.
    t_final: f64,
    /// The state at `t_final`.
    y_final: &'a [f64],
    /// The weights' angles at `t_final`.
    psi: &'a [f64],
    /// Settling time of r ≤ δ A_ref, and whether its hold completed.
    t_s: Option<f64>,
    hold_complete: bool,
    /// Settling time of the balancing error.
    t_eps: Option<f64>,
    /// RMS whirl over the last hold window.
    rms: f64,
}

impl SettlingObserver<'_> {
    /// Turn the observations and the solver's report into the run's metrics.
    pub fn finish(self, report: &SolveReport) -> (RunMetrics, Option<Series>) {
        let end = self.ending(report);
        let merged_apart = self.merged_apart(&end);
        let (outcome, reason) = self.classify(report, &end, merged_apart.as_deref());
        let metrics = self.run_metrics(report, &end, outcome, reason);
        (metrics, self.series)
    }

    /// The run's end state and the holds' readings there, the first step:
    /// everything after reads them.
    #[inline]
    fn ending<'a>(&'a self, report: &'a SolveReport) -> Ending<'a> {
        let lay = self.system.layout();
        let rev = self.dt * f64::from(self.options.samples_per_rev.max(32));
        // The run's end as the integration computes it, to the last bit.
        let horizon = self.t0 + self.options.t_end_revs * 2.0 * PI / self.omega;
        // A certified hold ends the run at the sample that certified it; a
        // certified "not settled" at a revolution boundary, whose state every
        // later boundary, the horizon's too, repeats within the bound.
        let (t_final, y_final) = match (&self.certified, &self.never) {
            (Some((t, y)), _) => (*t, y.as_slice()),
            (None, Some((_, _, y))) => (horizon, y.as_slice()),
            (None, None) => (report.t, report.y.as_slice()),
        };
        let psi = &y_final[lay.head()..lay.nq()];
        let (t_s, hold_complete) = self.r_hold.settling_time();
        let (mut t_eps, _) = self.eps_hold.settling_time();
        // A run certified never to settle repeats its last revolutions to
        // the horizon: the last hold window's RMS is theirs.
        let rms = match &self.never {
            Some((_, t, _)) => {
                t_eps = self.eps_at_horizon(*t).flatten();
                let (older, newer) = self.ring.latest(LAG * self.per_rev() as usize);
                let count = older.len() + newer.len();
                (older.iter().chain(newer).sum::<f64>() / count.max(1) as f64).sqrt()
            }
            None => self.ring.rms(),
        };
        Ending {
            rev,
            t_final,
            y_final,
            psi,
            t_s,
            hold_complete,
            t_eps,
            rms,
        }
    }

    /// Identical weights that met and are still one at the end: a result
    /// only if the pair is stable there (real weights would stay together
    /// too); where it is unstable, real weights would have parted, and this
    /// says why the run is not a result.
    #[inline]
    fn merged_apart(&self, end: &Ending) -> Option<String> {
        let (t_final, y_final) = (end.t_final, end.y_final);
        let lay = self.system.layout();
        self.merged.and_then(|(i, j, t_met)| {
            coincident_pair(&[(i, j)], lay, y_final)?;
            let rate = self.parting_rate(t_final, y_final, i, j);
            (rate > 1e-6 * self.omega).then(|| {
                format!(
                    "weights {i} and {j} (identical) coincided at t = {t_met:.4} and moved as one to the end, where the pair is unstable (once apart it would part at {rate:.3e} 1/s): the equations keep identical weights together for ever, real ones would separate; add [sampling.tolerances] to give them the differences real parts have"
                )
            })
        })
    }

    /// The run's outcome and its reason: failures of the integration first,
    /// then merged weights, a certified "not settled", and last the holds.
    #[inline]
    fn classify(
        &self,
        report: &SolveReport,
        end: &Ending,
        merged_apart: Option<&str>,
    ) -> (Outcome, String) {
        match (&self.diverged, &report.status) {
            (Some(why), _) => (Outcome::Diverged, why.clone()),
            (None, Status::Failed(Failure::NonFinite { t })) => {
                (Outcome::Diverged, format!("non-finite state at t = {t}"))
            }
            (None, Status::Failed(f)) if Budget::of_failure(f).is_some() => {
                (Outcome::BudgetExceeded, f.to_string())
            }
            (None, Status::Failed(f)) => (Outcome::SolverFailed, f.to_string()),
            (None, _) if merged_apart.is_some() => (
                Outcome::Merged,
                merged_apart.unwrap_or_default().to_string(),
            ),
            (None, _) if self.never.is_some() => {
                let (never, t, _) = self.never.as_ref().expect("checked");
                (
                    Outcome::NotSettled,
                    format!(
                        "not settled: from t = {t:.4} the state repeats every {LAG} revolutions (changing by at most {:.1e} per {LAG} revolutions, not growing: every later state within {:.1e} of it, scaled); {} to the horizon",
                        never.largest, never.tail, never.why
                    ),
                )
            }
            (None, _) => self.hold_outcome(end),
        }
    }

    /// A run the integration finished and nothing else ended: settled if the
    /// hold completed, else censored, saying how far from settled it was.
    #[inline]
    fn hold_outcome(&self, end: &Ending) -> (Outcome, String) {
        let (rev, y_final, rms) = (end.rev, end.y_final, end.rms);
        match end.t_s {
            Some(t) if end.hold_complete => (
                Outcome::Settled,
                match self.certified {
                    // Say which part of the window was integrated.
                    Some((t_end, _)) => format!(
                        "r ≤ {} A_ref held for {} revolutions from t = {t:.4} (certified: integrated to t = {t_end:.4}, the last {:.1} revolutions bounded on the linearised flow)",
                        self.options.delta,
                        self.options.hold_revs,
                        (t + self.window - t_end.min(t + self.window)) / rev
                    ),
                    None => format!(
                        "r ≤ {} A_ref held for {} revolutions from t = {t:.4}",
                        self.options.delta, self.options.hold_revs
                    ),
                },
            ),
            Some(t) => (
                Outcome::Censored,
                format!(
                    "censored: r ≤ {} A_ref from t = {t:.4} until the end of the run, shorter than the hold window of {} revolutions",
                    self.options.delta, self.options.hold_revs
                ),
            ),
            None => (
                Outcome::Censored,
                match self.operating_since {
                    Some(_) => format!(
                        "censored: {}r/A_ref = {:.3} at the end (band {}), residual {:.3} A_ref",
                        match self.planes_outside_text(y_final) {
                            planes if planes.is_empty() => planes,
                            planes => planes + "the whole rotor's ",
                        },
                        vibration(self.system, y_final) / self.a_ref,
                        self.options.delta,
                        rms / self.a_ref
                    ),
                    None => "censored: the speed never reached its operating value".to_string(),
                },
            ),
        }
    }

    /// The run's metrics from its end and outcome, the last step; the
    /// simulation fills method, fidelity, contact and the bearing orbits.
    #[inline]
    fn run_metrics(
        &self,
        report: &SolveReport,
        end: &Ending,
        outcome: Outcome,
        reason: String,
    ) -> RunMetrics {
        let (rev, t_final, y_final, psi) = (end.rev, end.t_final, end.y_final, end.psi);
        let (t_s, hold_complete, rms) = (end.t_s, end.hold_complete, end.rms);
        let settled = outcome == Outcome::Settled;
        RunMetrics {
            settled,
            settling_time: if settled { t_s } else { None },
            settling_revs: if settled {
                t_s.map(|t| (t - self.t0) / rev)
            } else {
                None
            },
            settling_time_err: self.dt,
            settling_time_eps: end.t_eps,
            hold_complete: settled && hold_complete,
            hold_certified: self.certified.is_some(),
            residual_abs: rms,
            residual_rel: rms / self.a_ref,
            a_ref: self.a_ref,
            balancing_error: balancing_error(self.system, psi, self.u_ref),
            peak_r: self.peak_r,
            final_rel_angles_deg: psi
                .iter()
                .map(|p| p.to_degrees().rem_euclid(360.0))
                .collect(),
            p_final: position_parameter(psi),
            outcome,
            reason,
            t_final,
            steps: report.stats.steps,
            rhs_calls: report.stats.rhs_calls
                + self.certifier.as_ref().map_or(0, |c| c.rhs_calls)
                + self.events.map_or(0, |e| e.rhs_calls()),
            method: String::new(),
            fidelity: String::new(),
            contact_model: None,
            min_gap_rad: self.gap.as_ref().map(|_| self.closest.smallest()),
            censoring_revs: matches!(outcome, Outcome::Censored | Outcome::NotSettled).then(|| {
                let t_op = self.operating_since.unwrap_or(t_final);
                ((t_final - self.window).max(t_op) - self.t0) / rev
            }),
            final_min_gap_rad: self.gap.as_ref().map(|g| g.min_gap(psi)),
            operating_time: self.operating_since,
            final_spin_rate: Some(self.system.spin(t_final, y_final).1),
            pack_slip_rate: pack_slip_rate(self.system, y_final),
            balance_angle_error_deg: None,
            plane_a_ref: self.planes.as_ref().map(|p| p.a_ref.clone()),
            // A run certified never to settle: each plane's last LAG
            // revolutions repeat to the horizon, as the rotor's do.
            plane_residual_abs: self.planes.as_ref().map(|p| {
                p.rings
                    .iter()
                    .map(|ring| match &self.never {
                        Some(_) => ring.latest_rms(LAG * self.per_rev() as usize),
                        None => ring.rms(),
                    })
                    .collect()
            }),
            // Measured after the run, by the simulation (it needs the solver).
            bearing_orbit_peak: None,
            bearing_orbit_rms: None,
            plane_balancing_error: self
                .planes
                .as_ref()
                .and_then(|_| plane_balancing_errors(self.system, psi, self.u_ref)),
            plane_settling_revs: self.planes.as_ref().map(|p| {
                p.holds
                    .iter()
                    .map(|h| h.met_at.map(|t| (t - self.t0) / rev))
                    .collect()
            }),
        }
    }
}

impl SettlingObserver<'_> {
    /// On a rotor with several watched planes, the planes outside their own
    /// band δ·A_ref of the plane at state `y`, each with its whirl and band
    /// ("plane 0 whirls 4.994 µm, above its own band 3.827 µm; "): the
    /// whole rotor's r/A_ref can sit inside its band while one plane,
    /// whose A_ref is smaller, does not.
    fn planes_outside_text(&self, y: &[f64]) -> String {
        let Some(pw) = &self.planes else {
            return String::new();
        };
        let mut r = vec![0.0; pw.a_ref.len()];
        plane_whirls(self.system, y, &mut r);
        r.iter()
            .zip(&pw.a_ref)
            .enumerate()
            .filter(|(_, (r, a))| **r > self.options.delta * **a)
            .map(|(p, (r, a))| {
                format!(
                    "plane {p} whirls {:.3} µm, above its own band δ·A_ref of the plane = {:.3} µm; ",
                    r * 1e6,
                    self.options.delta * a * 1e6
                )
            })
            .collect()
    }
}

/// The weights' mean rate ψ̇ relative to the rotor in state `y` (rad/s);
/// `None` without weights.
fn pack_slip_rate(system: &RotorSystem, y: &[f64]) -> Option<f64> {
    let lay = system.layout();
    let rates = y.get(lay.nq() + lay.head()..2 * lay.nq())?;
    (!rates.is_empty()).then(|| rates.iter().sum::<f64>() / rates.len() as f64)
}
