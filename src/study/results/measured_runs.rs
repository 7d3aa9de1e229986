//! A design's runs as the criteria measure them: its settling observations
//! and residuals ([`DesignRuns`]) and the scale that turns them into numbers
//! (the horizon τ and the length of a revolution, [`Scale`]).
//!
//! Plain data with no reference to a plan: the criteria ([`crate::study::plan::criterion`])
//! measure it, the study file declares a criterion, and reading the runs
//! ([`crate::study::results::design_runs`]) needs the plan's horizon and clock, so the data
//! sit below all three.

use crate::stats::survival::{KaplanMeier, Observation};

/// The runs of one design, in sample order: its settling observations and
/// residual vibrations.
#[derive(Debug, Clone)]
pub struct DesignRuns {
    /// The design.
    pub design_id: u32,
    /// Sample index of each run (what pairs runs of two designs).
    pub sample_ids: Vec<u32>,
    /// Settled at t (revolutions), or censored: at `censoring_revs` for a
    /// run simulated to its end, at the horizon for one that diverged,
    /// failed or ran out of budget (it never settled within the run).
    pub settling: Vec<Observation>,
    /// Residual vibration / A_ref of runs simulated to their end.
    pub residual: Vec<Option<f64>>,
    /// Residual vibration (m) of runs simulated to their end.
    pub residual_abs: Vec<Option<f64>>,
}

impl DesignRuns {
    /// The mean settling time of the runs that settled; `None` when none did.
    pub fn settled_mean(&self) -> Option<f64> {
        let times: Vec<f64> = self
            .settling
            .iter()
            .filter(|o| o.settled)
            .map(|o| o.time)
            .collect();
        (!times.is_empty()).then(|| times.iter().sum::<f64>() / times.len() as f64)
    }

    /// Its first `n` runs (all of them when it has fewer).
    pub fn first(&self, n: usize) -> DesignRuns {
        let n = n.min(self.sample_ids.len());
        DesignRuns {
            design_id: self.design_id,
            sample_ids: self.sample_ids[..n].to_vec(),
            settling: self.settling[..n].to_vec(),
            residual: self.residual[..n].to_vec(),
            residual_abs: self.residual_abs[..n].to_vec(),
        }
    }

    /// The Kaplan–Meier estimate of its settling.
    pub fn kaplan_meier(&self) -> Option<KaplanMeier> {
        KaplanMeier::fit(&self.settling)
    }
}

/// What turns the runs into numbers: the restricted-mean horizon τ (rev)
/// and the length of a revolution (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    /// τ: the restricted mean and the capped times run up to it (rev).
    pub tau: f64,
    /// One revolution of the nominal speed (s).
    pub rev_seconds: f64,
}
