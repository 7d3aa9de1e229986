//! Evaluating one candidate design: analytic figures in microseconds, or a
//! Monte Carlo sample with common random numbers, with its standard error.

use super::spec::{Objective, OptimizeSpec};
use crate::decide::verdict::settling_horizon;
use crate::design::transient::a_tilde;
use crate::metrics::{RunMetrics, peak_whirl};
use crate::model::balancer::Kind;
use crate::model::scene::{DesignSpec, RhoChoice};
use crate::stats::bootstrap;
use crate::stats::quantile::{Interpolation, quantile};
use crate::study::plan::config::StudyPlan;
use crate::study::plan::design::Design;
use crate::study::plan::stream::{Purpose, stream};
use crate::study::run::run_design_sample;
use rayon::prelude::*;

/// A run's residual vibration for the robust-design objectives: the
/// measured `residual_abs` (m) of a run simulated to its end or to its
/// settling (settled, censored, or integrated and certified not to settle:
/// the residual is observed either way, as the RMS over the last hold
/// window), +∞ for a run that has none (diverged, failed, out of budget, or
/// only estimated), so that it never meets a spec.
pub fn measured_residual(m: &crate::metrics::RunMetrics) -> f64 {
    if m.has_measured_residual() {
        m.residual_abs
    } else {
        f64::INFINITY
    }
}

/// Share of runs whose [`measured_residual`] lies below `spec` (m): the
/// value of `p_residual_below`.
pub fn share_below(metrics: &[crate::metrics::RunMetrics], spec: f64) -> f64 {
    let below = metrics
        .iter()
        .filter(|m| measured_residual(m) < spec)
        .count();
    below as f64 / metrics.len() as f64
}

/// A point of the design space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Balancer kind (plane 0's, with a design per plane).
    pub kind: Kind,
    /// Number of weights (plane 0's).
    pub n: u32,
    /// Radius ratio (plane 0's).
    pub rho: f64,
    /// Drag β (N·s/m), every plane's.
    pub drag: f64,
    /// Balancer plane 1's own design, when the study gives planes designs
    /// of their own (`[[designs.per_plane]]`); `None`: plane 0's in every plane.
    pub plane1: Option<PlaneChoice>,
}

/// Balancer plane 1's part of a [`Candidate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneChoice {
    /// Balancer kind.
    pub kind: Kind,
    /// Number of weights.
    pub n: u32,
    /// Radius ratio.
    pub rho: f64,
}

/// One evaluated candidate, as written to `optimize.parquet`.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// The candidate.
    pub candidate: Candidate,
    /// Objective value in its natural sign (None when infeasible).
    pub value: Option<f64>,
    /// Monte Carlo standard error of the value (0 for analytic objectives).
    pub std_err: f64,
    /// Capacity of the candidate (kg·m), when it could be built.
    pub capacity: Option<f64>,
    /// True when every constraint holds.
    pub feasible: bool,
    /// Which constraint failed, or "ok".
    pub constraint: String,
    /// Which search produced it (scan, brent, nelder_mead, analytic).
    pub phase: &'static str,
    /// Median over its runs of `peak_r / a_ref`, the start-up whirl
    /// ([`crate::metrics::peak_whirl`]); `None` when it was not simulated.
    pub peak_whirl_over_a_ref: Option<f64>,
}

/// Evaluates candidates of one study plan against one objective.
pub struct Evaluator<'a> {
    /// The study (scene, sampling, solver, metrics).
    pub plan: &'a StudyPlan,
    /// The optimisation settings.
    pub spec: &'a OptimizeSpec,
    /// Monte Carlo samples per candidate.
    pub samples: u32,
}

impl Evaluator<'_> {
    /// The candidate as a part to build ("5 balls of 3.2 mm diameter, …";
    /// each plane's with a design per plane); `None` when it cannot be built.
    pub fn part(&self, c: &Candidate) -> Option<String> {
        let design = self.design(c).ok()?;
        let one = |d: &Design| {
            crate::study::plan::design::part_text(
                d.spec.kind.name(),
                d.spec.n,
                (d.rho, d.spec.race_radius),
                d.weight_mass,
                d.spec.drag,
                d.roller_length(),
            )
        };
        Some(match design.plane_designs.first() {
            Some(other) => format!("plane 0: {}; plane 1: {}", one(&design), one(other)),
            None => one(&design),
        })
    }

    /// Build the candidate as a design, or say which constraint it breaks.
    fn design(&self, c: &Candidate) -> Result<Design, String> {
        let rhos = std::iter::once(c.rho).chain(c.plane1.map(|p| p.rho));
        if let Some(h) = self.spec.housing_rho_max
            && let Some(rho) = rhos.clone().find(|&r| r > h)
        {
            return Err(format!("ρ = {rho:.4} exceeds the housing limit {h}"));
        }
        let g = &self.plan.file.designs;
        let spec = |kind, n, rho, plane| DesignSpec {
            kind,
            n,
            rho: RhoChoice::Value(rho),
            race_radius: g.race_radius,
            density: g.density,
            roller_height: g.roller_height,
            drag: c.drag,
            plane,
        };
        let resolve = |s: DesignSpec| {
            self.plan
                .file
                .resolve_design(u32::MAX, s)
                .map_err(|e| e.to_string())
        };
        let mut design = resolve(spec(c.kind, c.n, c.rho, 0))?;
        if let Some(p) = c.plane1 {
            let other = resolve(spec(p.kind, p.n, p.rho, 1))?;
            design.capacity = design.capacity.min(other.capacity);
            design.plane_designs = vec![other];
        }
        if let (Some(sf), Some(u)) = (self.spec.safety_factor, self.spec.max_unbalance)
            && design.capacity < sf * u
        {
            return Err(format!(
                "capacity {:.4e} kg·m below {sf} × {u:.4e} kg·m",
                design.capacity
            ));
        }
        Ok(design)
    }

    /// Evaluate a candidate (deterministic for a given plan and seed).
    pub fn evaluate(&self, c: Candidate, phase: &'static str) -> Evaluation {
        let design = match self.design(&c) {
            Ok(d) => d,
            Err(why) => {
                return Evaluation {
                    candidate: c,
                    value: None,
                    std_err: 0.0,
                    capacity: None,
                    feasible: false,
                    constraint: why,
                    phase,
                    peak_whirl_over_a_ref: None,
                };
            }
        };
        // Runs on the search's samples 0..N, for a simulated objective or
        // for the start-up whirl constraint.
        let runs = (self.spec.objective.simulated() || self.spec.max_peak_over_a_ref.is_some())
            .then(|| self.run_metrics(&design, 0..u64::from(self.samples)));
        let peak = runs.as_ref().and_then(|m| {
            peak_whirl::median_and_p95(m.iter().filter_map(peak_whirl::of_run)).map(|s| s.0)
        });
        let (value, std_err) = match self.spec.objective {
            Objective::Capacity => (design.capacity, 0.0),
            Objective::ATilde => {
                // With a design per plane, the slower plane's ã.
                let planes = std::iter::once((c.kind, c.n, c.rho))
                    .chain(c.plane1.map(|p| (p.kind, p.n, p.rho)));
                let value = planes
                    .map(|(kind, n, rho)| a_tilde(kind.model().shape(), n, rho).unwrap_or(0.0))
                    .fold(f64::INFINITY, f64::min);
                (value, 0.0)
            }
            objective => {
                let values = self.values_of(runs.as_deref().unwrap_or_default(), objective);
                estimate(self.plan, objective, &values)
            }
        };
        let too_high = self
            .spec
            .max_peak_over_a_ref
            .and_then(|max| peak_too_high(peak, max));
        Evaluation {
            candidate: c,
            value: too_high.is_none().then_some(value),
            std_err,
            capacity: Some(design.capacity),
            feasible: too_high.is_none(),
            constraint: too_high.unwrap_or_else(|| "ok".into()),
            phase,
            peak_whirl_over_a_ref: peak,
        }
    }

    /// The candidate as a design, or the constraint it breaks.
    pub fn build(&self, c: &Candidate) -> Result<Design, String> {
        self.design(c)
    }

    /// Each run's contribution to a simulated objective, for samples
    /// `samples` (common random numbers: sample k draws the same for every
    /// design), in index order whatever the thread count.
    pub fn run_values(
        &self,
        design: &Design,
        samples: std::ops::Range<u64>,
        objective: Objective,
    ) -> Vec<f64> {
        self.values_of(&self.run_metrics(design, samples), objective)
    }

    /// The metrics of the design's runs on `samples`, in index order
    /// whatever the thread count.
    fn run_metrics(&self, design: &Design, samples: std::ops::Range<u64>) -> Vec<RunMetrics> {
        let ids: Vec<u64> = samples.collect();
        ids.into_par_iter()
            .with_max_len(1) // one simulation per job, as runs (study::run)
            .map(|k| run_design_sample(self.plan, design, k, k).metrics)
            .collect()
    }

    /// Each run's contribution to a simulated objective.
    fn values_of(&self, metrics: &[RunMetrics], objective: Objective) -> Vec<f64> {
        // A run that never settles counts as the horizon, the latest settling
        // time a run can show: right-censored there, so the mean is the
        // restricted mean and the quantiles are the Kaplan–Meier ones.
        let horizon = settling_horizon(self.plan);
        let yes = |b: bool| if b { 1.0 } else { 0.0 };
        metrics
            .iter()
            .map(|m| match objective {
                Objective::SettlingMean | Objective::SettlingMedian | Objective::SettlingP90 => {
                    m.settling_revs.unwrap_or(horizon).min(horizon)
                }
                Objective::SettledFraction => yes(m.settled),
                Objective::Residual => m.residual_rel,
                Objective::ResidualP95 => measured_residual(m),
                Objective::PResidualBelow => {
                    yes(measured_residual(m) < self.spec.residual_spec.expect("validated"))
                }
                Objective::Capacity | Objective::ATilde => {
                    unreachable!("analytic objectives are not simulated")
                }
            })
            .collect()
    }
}

/// Why a candidate whose runs' median start-up whirl is `peak` (over
/// A_ref) breaks `optimize.max_peak_over_a_ref = max`; `None` when it holds.
fn peak_too_high(peak: Option<f64>, max: f64) -> Option<String> {
    match peak {
        Some(p) if p <= max => None,
        Some(p) => Some(format!(
            "start-up whirl: median peak_r/A_ref {p:.3} above optimize.max_peak_over_a_ref = {max}"
        )),
        None => Some(format!(
            "start-up whirl: no run recorded a whole peak to check against optimize.max_peak_over_a_ref = {max}"
        )),
    }
}

/// The objective's statistic of per-run values: the mean, or a quantile
/// (settling median and p90, residual p95).
pub fn statistic(objective: Objective, values: &mut [f64]) -> f64 {
    match objective {
        Objective::SettlingMedian => quantile(values, 0.5, Interpolation::Linear),
        Objective::SettlingP90 => quantile(values, 0.9, Interpolation::Linear),
        Objective::ResidualP95 => quantile(values, 0.95, Interpolation::Linear),
        _ => Some(values.iter().sum::<f64>() / values.len() as f64),
    }
    .unwrap_or(f64::NAN)
}

/// The objective's value on per-run values and its standard error: the
/// sample's for a mean, the binomial one for a share, a bootstrap one for a
/// quantile.
pub fn estimate(plan: &StudyPlan, objective: Objective, values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let value = statistic(objective, &mut values.to_vec());
    let bootstrap_se = || {
        bootstrap::std_error(
            values,
            |v| statistic(objective, &mut v.to_vec()),
            &mut stream(plan.file.seed, None, 0, Purpose::Bootstrap),
        )
    };
    match objective {
        Objective::SettlingMedian | Objective::SettlingP90 => (value, bootstrap_se()),
        // Resamples that reach a +∞ run make the spread +∞ or NaN.
        Objective::ResidualP95 => {
            let se = bootstrap_se();
            (value, if se.is_finite() { se } else { 0.0 })
        }
        Objective::SettledFraction | Objective::PResidualBelow => {
            (value, (value * (1.0 - value) / n).sqrt())
        }
        _ => {
            let var = if values.len() > 1 {
                values.iter().map(|x| (x - value).powi(2)).sum::<f64>() / (n - 1.0)
            } else {
                0.0
            };
            (value, (var / n).sqrt())
        }
    }
}
