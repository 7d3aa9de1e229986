//! Why a design's runs do not settle, as experiments tell it: the samples
//! that did not settle, re-run with each effect removed in turn (the
//! runner's `causes.parquet`), name as the cause the effect whose removal
//! restores settling. A floor compared with the band (the dead band, the
//! race's whirl) only says what could stop a run; this says what does
//! (docs/statistics.md, "Causes by counterfactual re-runs").

use crate::simulation::counterfactual::Counterfactual;
use crate::study::results::causes_file::CauseRun;

/// The stored key when no single effect's removal restores settling.
pub const NO_SINGLE_EFFECT: &str = "no_single_effect";

/// What removing one effect did to the re-run samples.
#[derive(Debug, Clone, PartialEq)]
pub struct EffectTally {
    /// The effect removed.
    pub counterfactual: Counterfactual,
    /// Samples re-run without it (those it applied to).
    pub reruns: usize,
    /// Of those, the ones that settled.
    pub settled: usize,
    /// Of those, the ones that failed (a row with a reason in causes.parquet).
    pub failed: usize,
}

impl EffectTally {
    /// Removing the effect settles at least half the samples re-run
    /// without it: the rule that names it a cause.
    pub fn restores(&self) -> bool {
        self.settled > 0 && 2 * self.settled >= self.reruns
    }
}

/// The experiment's finding for one design.
#[derive(Debug, Clone, PartialEq)]
pub struct CauseFinding {
    /// The design.
    pub design_id: u32,
    /// Its runs.
    pub runs: usize,
    /// Its runs that did not settle (censored or not settled; failures aside).
    pub unsettled: usize,
    /// The samples re-run (the first of the unsettled ones by sample id).
    pub tested: usize,
    /// Per effect that applied, in [`Counterfactual::ALL`] order.
    pub tallies: Vec<EffectTally>,
}

impl CauseFinding {
    /// The finding of `rows` (one design's re-runs), the design having
    /// `runs` runs of which `unsettled` did not settle.
    pub fn from_rows(design_id: u32, runs: usize, unsettled: usize, rows: &[CauseRun]) -> Self {
        let mut samples: Vec<u32> = rows.iter().map(|r| r.sample_id).collect();
        samples.sort_unstable();
        samples.dedup();
        let tallies = Counterfactual::ALL
            .into_iter()
            .filter_map(|c| {
                let mine: Vec<&CauseRun> = rows.iter().filter(|r| r.counterfactual == c).collect();
                (!mine.is_empty()).then(|| EffectTally {
                    counterfactual: c,
                    reruns: mine.len(),
                    settled: mine.iter().filter(|r| r.settled).count(),
                    failed: mine.iter().filter(|r| r.outcome.is_failure()).count(),
                })
            })
            .collect();
        CauseFinding {
            design_id,
            runs,
            unsettled,
            tested: samples.len(),
            tallies,
        }
    }

    /// The effects named as causes: those whose removal restores settling,
    /// the most restoring first (ties in [`Counterfactual::ALL`] order).
    pub fn causes(&self) -> Vec<&EffectTally> {
        let mut named: Vec<&EffectTally> = self.tallies.iter().filter(|t| t.restores()).collect();
        // Compare shares by cross-multiplying: exact in integers.
        named.sort_by(|a, b| (b.settled * a.reruns).cmp(&(a.settled * b.reruns)));
        named
    }

    /// The stored key: the causes' keys joined by "+", or [`NO_SINGLE_EFFECT`].
    pub fn key(&self) -> String {
        let causes = self.causes();
        if causes.is_empty() {
            NO_SINGLE_EFFECT.to_string()
        } else {
            causes
                .iter()
                .map(|t| t.counterfactual.key())
                .collect::<Vec<_>>()
                .join("+")
        }
    }
}

/// "6 of 6", with the failed re-runs when there were any.
fn counts(t: &EffectTally) -> String {
    let failed = if t.failed > 0 {
        format!(" ({} failed)", t.failed)
    } else {
        String::new()
    };
    format!("{} of {}{failed}", t.settled, t.reruns)
}

impl std::fmt::Display for CauseFinding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let which = if self.tested < self.unsettled {
            format!("the first {} of them", self.tested)
        } else {
            format!("the {}", self.tested)
        };
        write!(
            f,
            "why {} of {} runs do not settle ({which} re-run with each effect removed in turn): ",
            self.unsettled, self.runs
        )?;
        if self.tallies.is_empty() {
            return write!(
                f,
                "no effect that can be removed is on (race eccentricity, rolling resistance, couple, gravity, contact, run-up)"
            );
        }
        let causes = self.causes();
        let named: Vec<String> = causes
            .iter()
            .map(|t| format!("{} — removing it settles {}", t.counterfactual, counts(t)))
            .collect();
        let others: Vec<String> = self
            .tallies
            .iter()
            .filter(|t| !causes.contains(t))
            .map(|t| format!("{} {}", t.counterfactual, counts(t)))
            .collect();
        if named.is_empty() {
            write!(
                f,
                "no single effect — removing each settles {}",
                others.join("; ")
            )
        } else if others.is_empty() {
            write!(f, "{}", named.join("; "))
        } else {
            write!(f, "{}; {}", named.join("; "), others.join("; "))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::Outcome;

    fn row(sample_id: u32, counterfactual: Counterfactual, outcome: Outcome) -> CauseRun {
        CauseRun {
            design_id: 0,
            sample_id,
            counterfactual,
            outcome,
            settled: outcome == Outcome::Settled,
            settling_revs: None,
            residual_rel: None,
            reason: String::new(),
        }
    }

    /// The effect whose removal settles the runs is named with its counts;
    /// one that settles none is listed after it, not named.
    #[test]
    fn the_effect_whose_removal_settles_is_named() {
        let mut rows = Vec::new();
        for s in 0..4 {
            rows.push(row(s, Counterfactual::RaceEccentricity, Outcome::Settled));
            rows.push(row(s, Counterfactual::RollingResistance, Outcome::Censored));
        }
        let finding = CauseFinding::from_rows(0, 16, 4, &rows);
        assert_eq!(finding.key(), "race_eccentricity");
        let text = finding.to_string();
        assert!(
            text.contains(
                "race eccentricity — removing it settles 4 of 4; rolling resistance 0 of 4"
            ),
            "{text}"
        );
        assert!(text.starts_with("why 4 of 16 runs do not settle"), "{text}");
    }

    /// Below half restored, nothing is named; a failed re-run is counted
    /// and said.
    #[test]
    fn no_single_effect_when_none_restores_half() {
        let rows = vec![
            row(0, Counterfactual::Gravity, Outcome::Settled),
            row(1, Counterfactual::Gravity, Outcome::Censored),
            row(2, Counterfactual::Gravity, Outcome::SolverFailed),
        ];
        let finding = CauseFinding::from_rows(0, 10, 5, &rows);
        assert_eq!(finding.key(), NO_SINGLE_EFFECT);
        let text = finding.to_string();
        assert!(text.contains("the first 3 of them"), "{text}");
        assert!(
            text.contains("no single effect — removing each settles gravity 1 of 3 (1 failed)"),
            "{text}"
        );
    }
}
