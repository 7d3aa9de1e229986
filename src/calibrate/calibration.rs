//! A calibration run from start to end: prior draws, the fit's restarts
//! from the best of them, proposal draws around the fit, the weighted
//! posterior, the unknowns' intervals and every point's prediction with
//! its band (the held-out points are the test). The problem says what is
//! predicted, [`super::fit`] and [`super::posterior`] how the unknowns are
//! estimated; this file only runs them in order. Deterministic for a seed,
//! whatever the thread count: every draw has a stream of its own and every
//! evaluation is a pure function of the unknowns' values.

use super::fit::{Restart, restarts};
use super::misfit::{FAILED, loss, z};
use super::posterior::{
    Proposal, effective_size, log_weight, normalised, predictive_quantile, weighted_quantile,
};
use super::problem::{Prediction, RigProblem};
use crate::study::plan::stream::{Purpose, stream};
use rand::RngExt;
use rayon::prelude::*;
use std::sync::Arc;

/// First sample index of the proposal's draws in the calibration stream.
const PROPOSAL_STREAM: u64 = 1 << 40;

/// First sample index of the synthetic data's noise.
const NOISE_STREAM: u64 = 1 << 41;

/// How much work a calibration does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Draws from the priors.
    pub prior_draws: usize,
    /// Draws from the proposal around the fit.
    pub proposal_draws: usize,
    /// Nelder–Mead restarts (from the best prior draws).
    pub restarts: usize,
    /// Most evaluations per restart.
    pub budget: u64,
    /// Seed of every draw.
    pub seed: u64,
}

/// One evaluated draw of the unknowns.
#[derive(Debug, Clone)]
pub struct Draw {
    /// From the priors (true) or the proposal.
    pub from_prior: bool,
    /// Probability coordinates (u).
    pub u: Vec<f64>,
    /// The unknowns' values.
    pub values: Vec<f64>,
    /// Every point's prediction.
    pub predictions: Arc<Vec<Prediction>>,
    /// Robust loss over the fitted points.
    pub loss: f64,
}

/// One unknown's estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// The scene key.
    pub key: String,
    /// The fitted value (the loss's minimum).
    pub fit: f64,
    /// Posterior 2.5 %, 50 % and 97.5 % quantiles.
    pub interval: [f64; 3],
    /// The prior's support.
    pub prior: (f64, f64),
}

/// One point's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct PointOutcome {
    /// The measured value used (the file's, or the synthetic one).
    pub measured: f64,
    /// The model at the fit.
    pub at_fit: Prediction,
    /// (model at fit − measured)/sd.
    pub z: Option<f64>,
    /// The model's posterior 2.5 %, 50 % and 97.5 % quantiles.
    pub band: Option<[f64; 3]>,
    /// The predictive 95 % band (model band widened by the measurement's sd).
    pub predictive: Option<[f64; 2]>,
}

impl PointOutcome {
    /// True when the measured value lies in the predictive band.
    pub fn inside(&self) -> Option<bool> {
        self.predictive
            .map(|[lo, hi]| lo <= self.measured && self.measured <= hi)
    }
}

/// Everything a calibration found.
#[derive(Debug, Clone)]
pub struct Calibration {
    /// Each unknown's fit and interval, in key order.
    pub estimates: Vec<Estimate>,
    /// Each point's outcome, in the rig file's order.
    pub points: Vec<PointOutcome>,
    /// The loss at the fit.
    pub loss: f64,
    /// Every restart.
    pub restarts: Vec<Restart>,
    /// Every draw, prior draws first.
    pub draws: Vec<Draw>,
    /// Each draw's normalised importance weight.
    pub weights: Vec<f64>,
    /// Effective sample size of the weights.
    pub effective_size: f64,
    /// Evaluations of the model (each a run or sweep per case), memo hits
    /// included.
    pub evaluations: u64,
}

/// `k` uniforms from sample `index` of the calibration stream of `seed`.
fn uniforms(seed: u64, index: u64, k: usize) -> Vec<f64> {
    let mut rng = stream(seed, None, index, Purpose::Calibration);
    (0..k).map(|_| rng.random::<f64>()).collect()
}

impl RigProblem {
    /// The points' measured values as the rig file gives them.
    pub fn measured(&self) -> Vec<f64> {
        self.rig.points.iter().map(|p| p.value).collect()
    }

    /// Synthetic measurements: the model at `truth` plus normal noise of
    /// each point's sd (repetition `rep` of the noise stream); `Err` names
    /// a point the model cannot predict at the truth.
    pub fn synthetic(&self, truth: &[f64], rep: u64, seed: u64) -> Result<Vec<f64>, String> {
        use rand_distr::{Distribution, StandardNormal};
        let at_truth = self.predict(truth);
        let mut rng = stream(seed, None, NOISE_STREAM + rep, Purpose::Calibration);
        self.rig
            .points
            .iter()
            .zip(at_truth.iter())
            .enumerate()
            .map(|(i, (p, predicted))| {
                let x = predicted
                    .as_ref()
                    .map_err(|why| format!("point[{i}] at the truth: {why}"))?;
                let e: f64 = StandardNormal.sample(&mut rng);
                Ok(x + p.sd * e)
            })
            .collect()
    }

    /// Calibrate the unknowns to `measured` (one value per point).
    pub fn calibrate(&self, measured: &[f64], settings: &Settings) -> Calibration {
        let k = self.rig.unknowns.len();
        let points = &self.rig.points;
        let evaluate = |u: Vec<f64>, from_prior: bool| {
            let values = self.values_at(&u);
            let predictions = self.predict(&values);
            let loss = loss(points, measured, &predictions);
            Draw {
                from_prior,
                u,
                values,
                predictions,
                loss,
            }
        };
        let mut draws: Vec<Draw> = (0..settings.prior_draws as u64)
            .into_par_iter()
            .map(|i| evaluate(uniforms(settings.seed, i, k), true))
            .collect();
        let mut order: Vec<usize> = (0..draws.len()).collect();
        order.sort_by(|&a, &b| draws[a].loss.total_cmp(&draws[b].loss).then(a.cmp(&b)));
        let starts: Vec<Vec<f64>> = order
            .iter()
            .take(settings.restarts.max(1))
            .map(|&i| draws[i].u.clone())
            .collect();
        let objective =
            |u: &[f64]| loss(points, measured, &self.predict_fitted(&self.values_at(u)));
        let ends = restarts(&objective, &starts, settings.budget);
        let best = ends
            .iter()
            .min_by(|a, b| a.loss.total_cmp(&b.loss))
            .expect("at least one restart");
        let fit_u = best.end.clone();
        let prior_lw: Vec<f64> = draws.iter().map(|d| log_likelihood(d.loss)).collect();
        let prior_u: Vec<Vec<f64>> = draws.iter().map(|d| d.u.clone()).collect();
        let proposal = Proposal::around(&fit_u, &prior_u, &prior_lw);
        let more: Vec<Draw> = (0..settings.proposal_draws as u64)
            .into_par_iter()
            .map(|j| {
                let v = uniforms(settings.seed, PROPOSAL_STREAM + j, k);
                evaluate(proposal.at(&v), false)
            })
            .collect();
        draws.extend(more);
        let mix = (settings.prior_draws, settings.proposal_draws);
        let log_weights: Vec<f64> = draws
            .iter()
            .map(|d| log_weight(log_likelihood(d.loss), &d.u, mix, Some(&proposal)))
            .collect();
        let weights = normalised(&log_weights);
        let fit_values = self.values_at(&fit_u);
        let at_fit = self.predict(&fit_values);
        let estimates = self.estimates(&fit_values, &draws, &weights);
        let outcomes = self.outcomes(measured, &at_fit, &draws, &weights);
        let evaluations = draws.len() as u64 + ends.iter().map(|r| r.evaluations).sum::<u64>() + 1;
        Calibration {
            estimates,
            points: outcomes,
            loss: objective(&fit_u),
            restarts: ends,
            effective_size: effective_size(&weights),
            draws,
            weights,
            evaluations,
        }
    }

    fn estimates(&self, fit: &[f64], draws: &[Draw], weights: &[f64]) -> Vec<Estimate> {
        self.rig
            .unknowns
            .iter()
            .enumerate()
            .map(|(j, (key, prior))| {
                let values: Vec<f64> = draws.iter().map(|d| d.values[j]).collect();
                let q = |p| weighted_quantile(&values, weights, p).unwrap_or(f64::NAN);
                Estimate {
                    key: key.clone(),
                    fit: fit[j],
                    interval: [q(0.025), q(0.5), q(0.975)],
                    prior: prior.support(),
                }
            })
            .collect()
    }

    fn outcomes(
        &self,
        measured: &[f64],
        at_fit: &[Prediction],
        draws: &[Draw],
        weights: &[f64],
    ) -> Vec<PointOutcome> {
        self.rig
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let model: Vec<f64> = draws
                    .iter()
                    .map(|d| d.predictions[i].as_ref().copied().unwrap_or(f64::NAN))
                    .collect();
                let q = |x| weighted_quantile(&model, weights, x);
                let band = match (q(0.025), q(0.5), q(0.975)) {
                    (Some(a), Some(b), Some(c)) => Some([a, b, c]),
                    _ => None,
                };
                // A reading cannot leave its quantity's range (no negative
                // ratio, no offset past 180°): the Gaussian reading's
                // quantiles, clipped to it, are those of the reading.
                let (lo, hi) = p.quantity.range();
                let pq = |x| predictive_quantile(&model, weights, p.sd, x).map(|v| v.clamp(lo, hi));
                let predictive = pq(0.025).zip(pq(0.975)).map(|(a, b)| [a, b]);
                PointOutcome {
                    measured: measured[i],
                    z: at_fit[i].as_ref().ok().map(|&x| z(p, measured[i], x)),
                    at_fit: at_fit[i].clone(),
                    band,
                    predictive,
                }
            })
            .collect()
    }
}

/// The log-likelihood of a loss (−loss/2; none for a failed prediction).
fn log_likelihood(loss: f64) -> f64 {
    if loss >= FAILED {
        f64::NEG_INFINITY
    } else {
        -0.5 * loss
    }
}

/// How often the intervals of repeated calibrations on synthetic data
/// covered the truth.
#[derive(Debug, Clone, PartialEq)]
pub struct Coverage {
    /// The truth (values, in key order).
    pub truth: Vec<f64>,
    /// Per repetition, per key: whether the 95 % interval held the truth.
    pub covered: Vec<Vec<bool>>,
    /// Per repetition: the fitted values.
    pub fits: Vec<Vec<f64>>,
    /// Per repetition: the effective sample size.
    pub effective_sizes: Vec<f64>,
}

impl Coverage {
    /// The share of repetitions whose interval held key `j`'s truth.
    pub fn share(&self, j: usize) -> f64 {
        let hits = self.covered.iter().filter(|c| c[j]).count();
        hits as f64 / self.covered.len().max(1) as f64
    }
}

impl RigProblem {
    /// Calibrate `repeats` times on synthetic data generated at `truth`
    /// with fresh noise each time (an identifiability check: can these
    /// points, with these uncertainties, pin these unknowns?).
    pub fn coverage(
        &self,
        truth: &[f64],
        repeats: u64,
        settings: &Settings,
    ) -> Result<Coverage, String> {
        let mut out = Coverage {
            truth: truth.to_vec(),
            covered: Vec::new(),
            fits: Vec::new(),
            effective_sizes: Vec::new(),
        };
        for rep in 0..repeats {
            let data = self.synthetic(truth, rep, settings.seed)?;
            let c = self.calibrate(&data, settings);
            out.covered.push(
                c.estimates
                    .iter()
                    .zip(truth)
                    .map(|(e, &t)| e.interval[0] <= t && t <= e.interval[2])
                    .collect(),
            );
            out.fits.push(c.estimates.iter().map(|e| e.fit).collect());
            out.effective_sizes.push(c.effective_size);
        }
        Ok(out)
    }
}
