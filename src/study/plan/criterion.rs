//! What "best" means: the declared criterion designs are ranked by
//! (`[summary] rank_by`, `--rank-by`), each with the paired test that fits
//! it (docs/statistics.md, "Ranking criteria").
//!
//! Settling criteria count every run: a run that did not settle within the
//! run counts as settling at the horizon τ for the restricted mean and the
//! p90 (never dropped), and as "not settled" for the shares. How a
//! criterion is measured on runs and two designs compared on it is the
//! decision's (`crate::decide::measure`).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::fmt;

/// A measure designs are ranked and compared by.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(try_from = "String", into = "String")]
#[schemars(with = "CriterionText")]
pub enum Criterion {
    /// Kaplan–Meier median settling time (lower is better).
    Median,
    /// Restricted mean settling time up to τ (lower is better): counts the tail.
    Mean,
    /// 90th percentile of the settling time over every run (lower is better).
    P90,
    /// Share of runs that settled within the run (higher is better).
    SettledFraction,
    /// Share of runs settled within a stated time (higher is better).
    SettledBy(Within),
    /// 95th percentile of residual vibration / A_ref (lower is better).
    ResidualP95,
    /// Share of runs whose residual vibration is below a level in m (higher is better).
    ResidualBelow(f64),
}

/// A time limit of [`Criterion::SettledBy`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Within {
    /// Revolutions (of the nominal speed).
    Revs(f64),
    /// Seconds.
    Seconds(f64),
}

/// The text form of a criterion, for the schema: median | mean | p90 |
/// settled_fraction | settled_by:<X>rev | settled_by:<X>s | residual_p95 |
/// p_residual_below:<X>m.
#[derive(JsonSchema)]
#[allow(dead_code)] // only its schema is used
struct CriterionText(
    #[schemars(regex(
        pattern = r"^(median|mean|p90|settled_fraction|residual_p95|settled_by:[0-9.eE+-]+(rev|s)|p_residual_below:[0-9.eE+-]+m)$"
    ))]
    String,
);

/// Whole criteria in the given units for a value that lacks one: the
/// number the user typed when it is one, else a typical level, so that
/// each suggestion parses as it stands (`settled_by:30min` once suggested
/// `30mins`, itself refused).
fn suggest(key: &str, value: &str, units: &[&str]) -> String {
    let typed = value.trim();
    let digits = typed
        .char_indices()
        .map(|(i, c)| i + c.len_utf8())
        .rfind(|&end| {
            typed[..end]
                .parse::<f64>()
                .is_ok_and(|v| v.is_finite() && v > 0.0)
        })
        .map(|end| &typed[..end]);
    units
        .iter()
        .map(|unit| {
            let level = digits.unwrap_or(match *unit {
                "m" => "2e-5",
                "s" => "0.5",
                _ => "30",
            });
            format!("{key}:{level}{unit}")
        })
        .collect::<Vec<_>>()
        .join(" or ")
}

/// The forms `--rank-by` and `rank_by` accept, for messages.
pub const CRITERION_FORMS: &str = "median, mean (restricted mean up to the horizon), p90, settled_fraction, settled_by:<X>rev or settled_by:<X>s, residual_p95, p_residual_below:<X>m";

impl Default for Criterion {
    /// The restricted mean: it counts every run, the slow tail included
    /// (docs/statistics.md says why it is the default).
    fn default() -> Self {
        Criterion::Mean
    }
}

impl Criterion {
    /// The four measures every verdict reports on, whatever it ranks by.
    pub const REPORTED: [Criterion; 4] = [
        Criterion::Median,
        Criterion::Mean,
        Criterion::P90,
        Criterion::ResidualP95,
    ];

    /// Parse the text form (see [`CRITERION_FORMS`]).
    pub fn parse(text: &str) -> Result<Self, String> {
        let text = text.trim();
        let number = |key: &str, value: &str, units: &[&str]| -> Result<f64, String> {
            let unit = units.iter().find(|u| value.trim().ends_with(**u));
            let v: f64 = unit
                .and_then(|u| value.trim().strip_suffix(*u))
                .ok_or_else(|| {
                    format!(
                        "{text:?}: give the unit, e.g. {}",
                        suggest(key, value, units)
                    )
                })?
                .trim()
                .parse()
                .map_err(|_| format!("{text:?}: {value:?} is not a number"))?;
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(format!("{text:?}: the level must be a positive number"))
            }
        };
        Ok(match text.split_once(':') {
            None => match text {
                "median" => Criterion::Median,
                "mean" => Criterion::Mean,
                "p90" => Criterion::P90,
                "settled_fraction" => Criterion::SettledFraction,
                "residual_p95" => Criterion::ResidualP95,
                "settled_by" | "p_residual_below" => {
                    return Err(format!(
                        "{text:?} needs a level, e.g. settled_by:30rev, settled_by:0.5s or p_residual_below:2e-5m"
                    ));
                }
                _ => {
                    return Err(format!(
                        "{text:?} is not a criterion; one of: {CRITERION_FORMS}"
                    ));
                }
            },
            Some(("settled_by", value)) if value.trim().ends_with("rev") => {
                Criterion::SettledBy(Within::Revs(number("settled_by", value, &["rev"])?))
            }
            Some(("settled_by", value)) => {
                Criterion::SettledBy(Within::Seconds(number("settled_by", value, &["s", "rev"])?))
            }
            Some(("p_residual_below", value)) => {
                Criterion::ResidualBelow(number("p_residual_below", value, &["m"])?)
            }
            Some(_) => {
                return Err(format!(
                    "{text:?} is not a criterion; one of: {CRITERION_FORMS}"
                ));
            }
        })
    }

    /// Whether a lower value is better.
    pub fn lower_is_better(self) -> bool {
        matches!(
            self,
            Criterion::Median | Criterion::Mean | Criterion::P90 | Criterion::ResidualP95
        )
    }

    /// Short label for tables and sentences, with the level.
    pub fn label(self) -> String {
        match self {
            Criterion::Median => "median settling time".into(),
            Criterion::Mean => "restricted mean settling time".into(),
            Criterion::P90 => "p90 settling time".into(),
            Criterion::SettledFraction => "settled share".into(),
            Criterion::SettledBy(Within::Revs(x)) => format!("share settled by {x} rev"),
            Criterion::SettledBy(Within::Seconds(x)) => format!("share settled by {x} s"),
            Criterion::ResidualP95 => "p95 residual/A_ref".into(),
            Criterion::ResidualBelow(m) => format!("share with residual below {m:e} m"),
        }
    }

    /// Unit of the value (and of differences): "rev", "" or "%" (shares are
    /// printed in percent).
    pub fn unit(self) -> &'static str {
        match self {
            Criterion::Median | Criterion::Mean | Criterion::P90 => "rev",
            Criterion::ResidualP95 => "",
            _ => "%",
        }
    }

    /// The test this criterion's comparisons use, paired or not.
    pub fn test_name(self, paired: bool) -> &'static str {
        match (self, paired) {
            (Criterion::Median, true) => "sign test",
            (Criterion::Median, false) => "bootstrap of the medians",
            (Criterion::Mean, true) => "paired t-test on min(t, τ)",
            (Criterion::Mean, false) => "bootstrap of the means of min(t, τ)",
            (Criterion::P90 | Criterion::ResidualP95, true) => "paired bootstrap",
            (Criterion::P90 | Criterion::ResidualP95, false) => "bootstrap",
            (_, true) => "McNemar's exact test",
            (_, false) => "two-proportion z-test",
        }
    }

    /// Whether A is better than B by the sign of their difference A − B.
    pub fn a_better(self, difference: f64) -> bool {
        if self.lower_is_better() {
            difference < 0.0
        } else {
            difference > 0.0
        }
    }

    /// Order of two values, better first (`None`, beyond the run or no runs, last).
    pub fn order(self, x: Option<f64>, y: Option<f64>) -> std::cmp::Ordering {
        match (x, y) {
            (Some(x), Some(y)) if self.lower_is_better() => x.total_cmp(&y),
            (Some(x), Some(y)) => y.total_cmp(&x),
            (Some(_), None) => std::cmp::Ordering::Less,
            (None, Some(_)) => std::cmp::Ordering::Greater,
            (None, None) => std::cmp::Ordering::Equal,
        }
    }
}

impl TryFrom<String> for Criterion {
    type Error = String;
    fn try_from(text: String) -> Result<Self, String> {
        Criterion::parse(&text)
    }
}

impl From<Criterion> for String {
    fn from(c: Criterion) -> String {
        c.to_string()
    }
}

impl fmt::Display for Criterion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Criterion::Median => write!(f, "median"),
            Criterion::Mean => write!(f, "mean"),
            Criterion::P90 => write!(f, "p90"),
            Criterion::SettledFraction => write!(f, "settled_fraction"),
            Criterion::SettledBy(Within::Revs(x)) => write!(f, "settled_by:{x}rev"),
            Criterion::SettledBy(Within::Seconds(x)) => write!(f, "settled_by:{x}s"),
            Criterion::ResidualP95 => write!(f, "residual_p95"),
            Criterion::ResidualBelow(m) => write!(f, "p_residual_below:{m:e}m"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_form_round_trips() {
        for text in [
            "median",
            "mean",
            "p90",
            "settled_fraction",
            "settled_by:30rev",
            "settled_by:0.5s",
            "residual_p95",
            "p_residual_below:2e-5m",
        ] {
            let c = Criterion::parse(text).unwrap();
            assert_eq!(Criterion::parse(&c.to_string()).unwrap(), c, "{text}");
        }
    }

    #[test]
    fn a_level_needs_its_unit() {
        assert!(
            Criterion::parse("settled_by:30")
                .unwrap_err()
                .contains("unit")
        );
        assert!(Criterion::parse("p_residual_below:-1m").is_err());
        assert!(
            Criterion::parse("fastest")
                .unwrap_err()
                .contains("median, mean")
        );
    }
}
