//! Whether the overall pick may be called final: only when the search that
//! found it converged. A search that ran out of evaluations, or found a
//! better point it had no budget left to search from, gives its best point
//! seen, which is a candidate, not an optimum; printing it as the part to
//! build (as `study optimize` did when every count's search ended on its
//! budget) claims more than the search showed.

use super::search::SearchEnd;

/// One (kind, n) search as the pick's verdict sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct SearchStop {
    /// "ball n = 4" (with a design per plane, plane 1's too).
    pub label: String,
    /// Its scope in optimum.parquet ("ball_4").
    pub scope: String,
    /// How it ended.
    pub end: SearchEnd,
    /// Evaluations it spent (its own and the cross-check's).
    pub evaluations: usize,
}

/// Whether the overall pick is final.
#[derive(Debug, Clone, PartialEq)]
pub enum PickStatus {
    /// The pick's own search converged.
    Final,
    /// The pick's own search did not converge: the best candidate found is
    /// not a final part.
    Unconfirmed {
        /// The pick's search.
        pick: SearchStop,
        /// `optimize.max_evaluations`, the budget of each search.
        budget: u64,
        /// How many searches ran, and how many of them did not converge.
        searches: usize,
        /// How many of them did not converge (the pick's included).
        unconverged: usize,
    },
    /// No feasible candidate: there is no pick.
    None,
}

/// The pick's status: `pick_scope` is the scope the overall pick came
/// from (`None`: no feasible candidate), `stops` every search's end.
pub fn pick_status(pick_scope: Option<&str>, stops: &[SearchStop], budget: u64) -> PickStatus {
    let Some(scope) = pick_scope else {
        return PickStatus::None;
    };
    let Some(own) = stops.iter().find(|s| s.scope == scope) else {
        // A pick that no search produced (none at present) is not a searched optimum.
        return PickStatus::None;
    };
    if own.end == SearchEnd::Converged {
        return PickStatus::Final;
    }
    PickStatus::Unconfirmed {
        pick: own.clone(),
        budget,
        searches: stops.len(),
        unconverged: stops
            .iter()
            .filter(|s| s.end != SearchEnd::Converged)
            .count(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stop(n: u32, end: SearchEnd) -> SearchStop {
        SearchStop {
            label: format!("ball n = {n}"),
            scope: format!("ball_{n}"),
            end,
            evaluations: 25,
        }
    }

    #[test]
    fn a_pick_is_final_only_when_its_own_search_converged() {
        let stops = [
            stop(3, SearchEnd::Budget),
            stop(4, SearchEnd::Converged),
            stop(5, SearchEnd::Unconfirmed),
        ];
        assert_eq!(pick_status(Some("ball_4"), &stops, 25), PickStatus::Final);
        assert_eq!(
            pick_status(Some("ball_3"), &stops, 25),
            PickStatus::Unconfirmed {
                pick: stops[0].clone(),
                budget: 25,
                searches: 3,
                unconverged: 2,
            }
        );
        assert!(matches!(
            pick_status(Some("ball_5"), &stops, 25),
            PickStatus::Unconfirmed { .. }
        ));
        assert_eq!(pick_status(None, &stops, 25), PickStatus::None);
    }
}
