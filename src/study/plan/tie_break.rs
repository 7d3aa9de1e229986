//! How the part is chosen among designs the data cannot tell apart
//! (`[summary] tie_break`).
//!
//! When the leading designs are not distinguishable at the study's α, the
//! point estimates' order among them is a coin toss that changes with the
//! seed (docs/statistics.md, "The indistinguishable set"). The decision is
//! then a set, and the part is chosen from it by a rule declared up front
//! that does not depend on the noise.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::fmt;

/// The rule that chooses the part among the indistinguishable designs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum TieBreak {
    /// The least balancer mass (every weight in every plane), then the
    /// fewest weights, then the smallest radius ratio, then the design id.
    #[default]
    Mass,
    /// The first by the point estimate of the criterion (#1), as if the
    /// ranking's order were known: depends on the seed when designs tie.
    First,
}

impl TieBreak {
    /// The name in the study file and in `summary.parquet` (`tie_break`).
    pub fn name(self) -> &'static str {
        match self {
            TieBreak::Mass => "mass",
            TieBreak::First => "first",
        }
    }

    /// The rule of a stored name; `None` for a name this build does not know.
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "mass" => Some(TieBreak::Mass),
            "first" => Some(TieBreak::First),
            _ => None,
        }
    }

    /// The rule in words, as the summary prints it ("part by least mass").
    pub fn label(self) -> &'static str {
        match self {
            TieBreak::Mass => "least mass",
            TieBreak::First => "first by the point estimate",
        }
    }
}

impl fmt::Display for TieBreak {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What the tie-break compares of one candidate design.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Design id.
    pub id: u32,
    /// Its place in the ranking (0: #1).
    pub rank: usize,
    /// Total balancer mass, kg (`None`: unknown, ranks last on mass).
    pub mass: Option<f64>,
    /// Weights in every plane together.
    pub weights: u32,
    /// Radius ratio ρ (`None`: unknown).
    pub rho: Option<f64>,
}

/// The candidate `rule` chooses; `None` for no candidates. Deterministic:
/// a total order, the id last.
pub fn choose(rule: TieBreak, candidates: &[Candidate]) -> Option<Candidate> {
    let unknown_last = |v: Option<f64>| v.unwrap_or(f64::INFINITY);
    candidates.iter().copied().min_by(|a, b| match rule {
        TieBreak::First => a.rank.cmp(&b.rank).then(a.id.cmp(&b.id)),
        TieBreak::Mass => unknown_last(a.mass)
            .total_cmp(&unknown_last(b.mass))
            .then(a.weights.cmp(&b.weights))
            .then(unknown_last(a.rho).total_cmp(&unknown_last(b.rho)))
            .then(a.id.cmp(&b.id)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn candidate(id: u32, rank: usize, mass: f64, weights: u32, rho: f64) -> Candidate {
        Candidate {
            id,
            rank,
            mass: Some(mass),
            weights,
            rho: Some(rho),
        }
    }

    /// The lightest wins whatever the ranking's order; equal masses go to
    /// the fewest weights, then the smaller ρ; "first" keeps the ranking.
    #[test]
    fn the_rule_does_not_depend_on_the_ranking_order() {
        let set = [
            candidate(4, 0, 0.088, 4, 0.25),
            candidate(2, 1, 0.066, 3, 0.25),
            candidate(7, 2, 0.066, 6, 0.2),
        ];
        let mut reversed = set;
        reversed.reverse();
        for (i, c) in reversed.iter_mut().enumerate() {
            c.rank = i;
        }
        assert_eq!(choose(TieBreak::Mass, &set).unwrap().id, 2);
        assert_eq!(choose(TieBreak::Mass, &reversed).unwrap().id, 2);
        assert_eq!(choose(TieBreak::First, &set).unwrap().id, 4);
        assert_eq!(choose(TieBreak::First, &reversed).unwrap().id, 7);
        let same_mass = [candidate(1, 0, 0.05, 5, 0.2), candidate(3, 1, 0.05, 5, 0.1)];
        assert_eq!(choose(TieBreak::Mass, &same_mass).unwrap().id, 3);
        assert_eq!(choose(TieBreak::Mass, &[]), None);
    }

    /// The study file's names read back as the rule.
    #[test]
    fn names_round_trip() {
        for rule in [TieBreak::Mass, TieBreak::First] {
            assert_eq!(TieBreak::parse(rule.name()), Some(rule));
        }
        assert_eq!(TieBreak::parse("cheapest"), None);
    }
}
