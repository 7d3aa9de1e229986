//! `study compare`: two designs, from one results folder or two, compared on
//! paired runs when they met the same sampled unbalances, unpaired (log-rank)
//! otherwise, with the reason pairing was refused.

use crate::decide::verdict::{
    Comparison, Favours, SettlingClock, compare, design_runs, favoured, measure_scale,
};
use crate::stats::holm::holm_adjust;
use crate::stats::interval::wilson_interval;
use crate::stats::survival::{KaplanMeier, Transform};
use crate::study::plan::config::{StudyFile, StudyPlan};
use crate::study::plan::criterion::Criterion;
use crate::study::results::measured_runs::{DesignRuns, Scale};
use polars::prelude::*;
use std::path::{Path, PathBuf};

/// Why two designs cannot be compared.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// The folder holds no finished study.
    #[error("{0}: no finished study here (runs.parquet and study.toml are needed)")]
    NotAStudy(String),
    /// The design is not in the folder.
    #[error("{folder}: no design {design} (it holds designs {available})")]
    NoSuchDesign {
        /// The folder.
        folder: String,
        /// The design asked for.
        design: u32,
        /// What is there.
        available: String,
    },
    /// The folder holds several designs and none was named.
    #[error("{0}: holds {1} designs; say which with --designs A,B")]
    WhichDesign(String, usize),
    /// The folder's runs recorded another study or seed than its study.toml.
    #[error("{0} does not hold the runs of the study.toml beside it: {1}")]
    ForeignTable(String, String),
    /// The study text stored in the folder is invalid.
    #[error("{0}: {1}")]
    BadStudy(String, String),
    /// Reading failed.
    #[error("{0}")]
    Polars(#[from] PolarsError),
}

/// One side of a comparison: a design's runs and where they came from.
#[derive(Debug, Clone)]
pub struct Side {
    /// The results folder.
    pub dir: PathBuf,
    /// A short description: kind, n, ρ, β (and M_s).
    pub label: String,
    /// The same with units, for a figure's legend.
    pub figure_label: String,
    /// Its runs, in sample order.
    pub runs: DesignRuns,
    /// Latest settling time its runs can show (revolutions).
    pub horizon: f64,
    /// τ and the revolution of the side's study.
    pub scale: Scale,
    /// Where its settling times count from.
    pub clock: SettlingClock,
    /// The criterion its study ranks by (`[summary] rank_by`).
    pub default_criterion: Criterion,
    /// Each watched plane's statistics (rotors with several planes; empty
    /// otherwise).
    pub plane_stats: Vec<crate::decide::plane_summary::PlaneStats>,
    /// The sampled unbalance of each run as it was drawn (kg·m, or the
    /// fraction of capacity) and its direction.
    draws: Vec<(Option<f64>, Option<f64>)>,
    /// Whether the study drew unbalances in kg·m (else as fractions of
    /// each design's capacity).
    absolute: bool,
}

impl Side {
    /// Load design `design` of the study in `dir` (`None`: its only design).
    pub fn load(dir: &Path, design: Option<u32>) -> Result<Side, CompareError> {
        let shown = dir.display().to_string();
        let text = std::fs::read_to_string(dir.join("study.toml"))
            .map_err(|_| CompareError::NotAStudy(shown.clone()))?;
        let runs_path = dir.join("runs.parquet");
        if !runs_path.exists() {
            return Err(CompareError::NotAStudy(shown));
        }
        let plan: StudyPlan = StudyFile::parse(&text, &shown)
            .and_then(|f| f.plan(&text, &shown))
            .map_err(|e| CompareError::BadStudy(shown.clone(), e.to_string()))?;
        if let Some(reason) =
            crate::study::results::io::foreign_table(&runs_path, &plan.text, plan.file.seed, None)?
        {
            return Err(CompareError::ForeignTable(
                runs_path.display().to_string(),
                reason,
            ));
        }
        let id = match design {
            Some(id) => id,
            None if plan.designs.len() == 1 => plan.designs[0].id,
            None => return Err(CompareError::WhichDesign(shown, plan.designs.len())),
        };
        let Some(d) = plan.designs.iter().find(|d| d.id == id) else {
            return Err(CompareError::NoSuchDesign {
                folder: shown,
                design: id,
                available: format!("0..={}", plan.designs.len().saturating_sub(1)),
            });
        };
        let df = crate::study::results::results_table::read_table(
            &runs_path,
            crate::study::results::results_table::TableKind::Runs,
        )?;
        let mine = df.filter(&df.column("design_id")?.u32()?.equal(id))?;
        let mine = mine.sort(["sample_id"], SortMultipleOptions::default())?;
        let scale = measure_scale(&plan);
        let horizon = scale.tau;
        let clock = SettlingClock::of(&plan);
        let runs = design_runs(&mine, horizon, clock)?
            .into_iter()
            .next()
            .ok_or_else(|| CompareError::NotAStudy(format!("{shown} (design {id} has no runs)")))?;
        let rows: Vec<usize> = (0..mine.height()).collect();
        let plane_stats = match crate::decide::plane_summary::PlaneRuns::read(&mine)? {
            Some(planes) => (0..planes.planes)
                .map(|p| planes.stats(&rows, p, (horizon, plan.file.metrics.delta), clock))
                .collect(),
            None => Vec::new(),
        };
        // Runs pair when they shared the draw itself: the unbalance in kg·m
        // for an absolute study (its fraction differs with the capacity),
        // the fraction for a capacity-relative one.
        let absolute = plan.file.sampling.unbalance.scale()
            == crate::study::plan::distribution::Scale::Absolute;
        let drawn = if absolute {
            "unbalance"
        } else {
            "unbalance_fraction"
        };
        let fraction = mine.column(drawn)?.f64()?;
        let direction = mine.column("direction_deg")?.f64()?;
        Ok(Side {
            dir: dir.to_path_buf(),
            label: crate::study::plan::plane_designs::short_label(d),
            figure_label: crate::study::plan::plane_designs::figure_label(d),
            plane_stats,
            runs,
            horizon,
            scale,
            clock,
            default_criterion: plan.file.summary.rank_by,
            draws: fraction.iter().zip(direction.iter()).collect(),
            absolute,
        })
    }

    /// What two paired runs of this side's study shared.
    pub fn shared(&self) -> &'static str {
        if self.absolute {
            "the same unbalance in kg·m"
        } else {
            "the same fraction of each design's capacity"
        }
    }

    /// Kaplan–Meier estimate of the side's settling.
    pub fn kaplan_meier(&self) -> Option<KaplanMeier> {
        self.runs.kaplan_meier()
    }

    /// Settled runs, runs, and the Wilson 95 % interval of the fraction.
    pub fn settled(&self) -> (u64, u64, (f64, f64)) {
        let settled = self.runs.settling.iter().filter(|o| o.settled).count() as u64;
        let runs = self.runs.settling.len() as u64;
        (settled, runs, wilson_interval(settled, runs))
    }
}

/// Why the runs of two sides cannot be paired, if they cannot: pairs must
/// be the same samples (or the first of the other's) and have met the same unbalance (fraction of
/// capacity) from the same direction.
pub fn pairing_refusal(a: &Side, b: &Side) -> Option<String> {
    // A design that left a race ran the first samples of the others: the
    // two pair on those.
    if crate::decide::verdict::shared_prefix(&a.runs, &b.runs).is_none() {
        return Some(format!(
            "the designs have different samples ({} runs against {})",
            a.runs.sample_ids.len(),
            b.runs.sample_ids.len()
        ));
    }
    if a.absolute != b.absolute {
        return Some(
            "one study drew unbalances in kg·m, the other as fractions of capacity".to_string(),
        );
    }
    let what = if a.absolute {
        "unbalance (kg·m"
    } else {
        "unbalance (fraction"
    };
    let differ = a
        .draws
        .iter()
        .zip(&b.draws)
        .zip(&a.runs.sample_ids)
        .find(|((x, y), _)| x != y);
    differ.map(|(((fa, da), (fb, db)), sample)| {
        format!(
            "sample {sample} met a different {what} {:.4e} at {:.1}° against {:.4e} at {:.1}°): the runs were drawn from different streams (another seed, or common_random_numbers = false)",
            fa.unwrap_or(f64::NAN),
            da.unwrap_or(f64::NAN),
            fb.unwrap_or(f64::NAN),
            db.unwrap_or(f64::NAN)
        )
    })
}

/// A compared pair: the comparison, and why it is unpaired if it is.
#[derive(Debug, Clone)]
pub struct DesignComparison {
    /// A against B.
    pub comparison: Comparison,
    /// Whether the runs were paired, or why not.
    pub pairing: Pairing,
}

/// Whether two sides' runs pair: the same draws (seed, sample ids, common
/// random numbers), or why not.
#[derive(Debug, Clone, PartialEq)]
pub enum Pairing {
    /// Run k of A and run k of B met the same draws.
    Paired,
    /// Why they cannot be paired.
    Refused(String),
}

/// The verdict of A against B on the criterion, and the other measures that
/// disagree with it, each measure's p-value Holm-adjusted over the measures.
#[derive(Debug, Clone, PartialEq)]
pub struct PairVerdict {
    /// Which side the criterion favours (`None`: not distinguishable).
    pub criterion_favours: Option<Favours>,
    /// Holm-adjusted p-value of each measure, in the comparison's order.
    pub p_holm: Vec<f64>,
    /// Measures other than the criterion that significantly favour a side
    /// the criterion did not choose (the other side, or either side when
    /// the criterion cannot tell them apart), with the side each favours.
    pub disagreeing: Vec<(Criterion, Favours)>,
}

impl DesignComparison {
    /// The verdict at level `alpha`, by the rule of every verdict ([`favoured`]).
    pub fn verdict(&self, alpha: f64) -> PairVerdict {
        let measures = &self.comparison.measures;
        let raw: Vec<f64> = measures
            .iter()
            .map(|m| m.difference.map_or(1.0, |d| d.p_value))
            .collect();
        let p_holm = holm_adjust(&raw);
        let favours = |k: usize| {
            measures[k]
                .difference
                .and_then(|d| favoured(measures[k].criterion, &d, p_holm[k], alpha))
        };
        let criterion_favours = if measures.is_empty() {
            None
        } else {
            favours(0)
        };
        let disagreeing = (1..measures.len())
            .filter_map(|k| {
                let side = favours(k)?;
                (criterion_favours != Some(side)).then_some((measures[k].criterion, side))
            })
            .collect();
        PairVerdict {
            criterion_favours,
            p_holm,
            disagreeing,
        }
    }
}

/// Compare side A with side B (paired when [`pairing_refusal`] allows) on
/// `criterion` first, then on every measure of [`Criterion::REPORTED`],
/// with one τ for both sides (the earlier of their horizons).
pub fn compare_sides(a: &Side, b: &Side, seed: u64, criterion: Criterion) -> DesignComparison {
    let refusal = pairing_refusal(a, b);
    let mut measures = vec![criterion];
    measures.extend(Criterion::REPORTED.iter().filter(|&&c| c != criterion));
    DesignComparison {
        comparison: compare(
            &a.runs,
            &b.runs,
            refusal.is_none(),
            &measures,
            &common_scale(a, b),
            seed,
        ),
        pairing: refusal.map_or(Pairing::Paired, Pairing::Refused),
    }
}

/// The τ both sides are compared up to: the earlier of their horizons.
pub fn common_scale(a: &Side, b: &Side) -> Scale {
    Scale {
        tau: a.scale.tau.min(b.scale.tau),
        rev_seconds: a.scale.rev_seconds,
    }
}

/// The Kaplan–Meier median of a side with its 95 % log-log interval.
pub fn median_with_interval(km: &KaplanMeier) -> (Option<f64>, (Option<f64>, Option<f64>)) {
    (
        km.median(),
        km.median_interval(crate::decide::verdict::LEVEL, Transform::LogLog),
    )
}

#[cfg(test)]
mod verdict_tests {
    use super::*;
    use crate::decide::verdict::MeasureComparison;
    use crate::stats::paired_measures::Difference;

    /// A measure where A's value is `a`, B's `b`, at raw p-value `p`.
    fn measure(criterion: Criterion, a: f64, b: f64, p: f64) -> MeasureComparison {
        MeasureComparison {
            criterion,
            difference: Some(Difference {
                a,
                b,
                scale: a.abs().max(b.abs()),
                difference: a - b,
                interval: (a - b - 1.0, a - b + 1.0),
                p_value: p,
                test: "paired_t",
            }),
            p_holm: p,
        }
    }

    fn comparison(measures: Vec<MeasureComparison>) -> DesignComparison {
        DesignComparison {
            comparison: Comparison {
                a: 0,
                b: 1,
                runs: (20, 20),
                medians: (None, None),
                paired: None,
                unpaired: None,
                residual_test: None,
                residual_ratio: None,
                measures,
            },
            pairing: Pairing::Paired,
        }
    }

    /// Another measure that significantly favours a side is a finding
    /// whichever side the criterion chose, or when it chose none: B better
    /// on p90 while the criterion favours B is not one; A better on p90
    /// while the criterion favours B, or cannot tell, is.
    #[test]
    fn other_measures_disagree_whichever_side_the_criterion_takes() {
        let mean_b = measure(Criterion::Mean, 60.0, 40.0, 1e-6);
        let mean_tie = measure(Criterion::Mean, 50.0, 50.5, 0.6);
        let p90_a = measure(Criterion::P90, 40.0, 80.0, 1e-6);
        let p90_b = measure(Criterion::P90, 90.0, 50.0, 1e-6);
        let v = comparison(vec![mean_b.clone(), p90_a.clone()]).verdict(0.05);
        assert_eq!(v.criterion_favours, Some(Favours::B));
        assert_eq!(v.disagreeing, [(Criterion::P90, Favours::A)]);
        let v = comparison(vec![mean_b, p90_b]).verdict(0.05);
        assert!(v.disagreeing.is_empty());
        let v = comparison(vec![mean_tie, p90_a]).verdict(0.05);
        assert_eq!(v.criterion_favours, None);
        assert_eq!(v.disagreeing, [(Criterion::P90, Favours::A)]);
    }
}
