//! What a shell offers after a flag whose values are not file names: the
//! forms of `--rank-by` (the parameterised ones as their stem, such as
//! `settled_by:`, for the user to finish), carried by the flags' value
//! parsers so that every completion script clap_complete writes has them.

use autobal::study::plan::criterion::Criterion;
use clap::builder::{PossibleValue, TypedValueParser};

/// `--rank-by`: parsed by [`parse_criterion`], completed
/// to the criterion names (hidden from `--help`, whose text lists the forms
/// with their parameters).
#[derive(Clone, Copy)]
pub struct CriterionParser;

/// `--rank-by` as clap parses it (every verb that takes it).
fn parse_criterion(text: &str) -> Result<Criterion, String> {
    Criterion::parse(text)
}

/// The criterion forms a shell offers, with what each ranks by.
const CRITERIA: [(&str, &str); 7] = [
    ("mean", "restricted mean settling time (the default)"),
    ("median", "median settling time (Kaplan-Meier)"),
    ("p90", "90th percentile of the settling time"),
    ("settled_fraction", "share of runs that settle"),
    (
        "settled_by:",
        "share settled by a time: settled_by:30rev or settled_by:0.5s",
    ),
    (
        "residual_p95",
        "95th percentile of the residual whirl over A_ref",
    ),
    (
        "p_residual_below:",
        "share with a residual below a level: p_residual_below:2e-5m",
    ),
];

impl TypedValueParser for CriterionParser {
    type Value = Criterion;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<Criterion, clap::Error> {
        // The same parser and messages as before completion knew the values.
        parse_criterion.parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(
            CRITERIA
                .iter()
                .map(|&(name, help)| PossibleValue::new(name).help(help)),
        ))
    }
}
