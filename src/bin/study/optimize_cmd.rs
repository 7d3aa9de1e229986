//! `study optimize`: choose counts, radii and drag for an objective.

use crate::UserError;
use crate::output::{dropped_note, fitted_table, say_err, text_width, wrap};
use autobal::optimize::optimize;
use autobal::optimize::pick::PickStatus;
use autobal::optimize::search::SearchEnd;
use autobal::optimize::spec::Objective;
use autobal::output_file::WhenExists;
use autobal::study::plan::config::load;
use autobal::study::run::study_folder::claim;
use clap::Args;
use std::path::PathBuf;

/// Examples shown under `study optimize --help`.
pub const EXAMPLES: &str = "Examples:
  study optimize studies/optimize_capacity.toml     analytic: Table 1 under a housing limit
  study optimize studies/optimize_settling.toml     simulated: mean settling time, CRN, standard errors";

/// Arguments of `study optimize`.
#[derive(Args)]
pub struct OptimizeArgs {
    /// Study file with an [optimize] table.
    study: PathBuf,
    /// Replace the study folder's optimize.parquet and optimum.parquet if they exist.
    #[arg(long)]
    overwrite: bool,
    /// Worker threads (default: all cores, or RAYON_NUM_THREADS); the results do not depend on it.
    #[arg(long, value_parser = crate::limits::threads)]
    threads: Option<usize>,
}

/// Run `study optimize`.
pub fn run(args: &OptimizeArgs) -> Result<(), UserError> {
    let plan = load(&args.study)?;
    autobal::optimize::checked_spec(&plan)?;
    let _folder = claim(
        &plan,
        "optimize",
        &["optimize.parquet", "optimum.parquet"],
        WhenExists::from_overwrite(args.overwrite),
    )?;
    let out = worker_pool(args.threads)?.install(|| optimize(&plan))?;
    let spec = plan.file.optimize.clone();
    let unit = spec.as_ref().map_or("", |o| o.objective.unit());
    let objective_header = objective_header(spec.as_ref());
    // A residual in metres (µm-sized) would print as 0.00000 at the other
    // objectives' five decimals.
    let metres = plan
        .file
        .optimize
        .as_ref()
        .is_some_and(|o| o.objective == Objective::ResidualP95);
    let shown = |v: f64| {
        if metres {
            format!("{v:.4e}")
        } else {
            format!("{v:.5}")
        }
    };
    // A simulated objective is shown to its standard error's two leading
    // digits: five decimals on a value whose SE is 0.29 claimed precision
    // the estimate does not have.
    let with_se = |v: f64, se: f64| {
        if metres || se <= 0.0 || !se.is_finite() {
            shown(v)
        } else {
            let decimals = (1.0 - se.log10().floor()).clamp(0.0, 6.0) as usize;
            format!("{v:.decimals$}")
        }
    };
    let confirmation = out.confirmation.as_ref();
    // Each scope's optimum on the fresh samples (the overall row: the pick's).
    let confirmed_text = |scope: &str| -> String {
        let Some(c) = confirmation else {
            return "–".into();
        };
        c.row(scope).map_or("–".into(), |r| {
            format!(
                "{} ± {}",
                with_se(r.value, r.std_err),
                with_se(r.std_err, r.std_err)
            )
        })
    };
    let rows: Vec<Vec<String>> = out
        .best
        .iter()
        .map(|b| {
            let e = &b.evaluation;
            let [kind, n, rho] = design_cells(&e.candidate);
            vec![
                b.scope.clone(),
                kind,
                n,
                rho,
                autobal::number_text::significant(e.candidate.drag, 4),
                e.value.map_or("–".into(), |v| with_se(v, e.std_err)),
                with_se(e.std_err, e.std_err),
                confirmed_text(&b.scope),
                e.capacity.map_or("–".into(), |c| format!("{c:.4e}")),
                if e.feasible {
                    "ok".into()
                } else {
                    e.constraint.clone()
                },
            ]
        })
        .collect();
    // The scope and the objective stay; the capacity column (in kg·m
    // beside a capacity objective it repeats) and β go first.
    let header = [
        "scope",
        "kind",
        "n",
        "ρ",
        "β\nN·s/m",
        &objective_header,
        "± SE",
        "on fresh\nsamples ± SE",
        "capacity\nkg·m",
        "constraints",
    ];
    let (table, dropped) = fitted_table(
        &header,
        &rows,
        &[0, 1, 1, 1, 3, 0, 2, 1, 4, 2],
        text_width(),
    );
    print!("{table}");
    print!("{}", wrap(&dropped_note(&dropped), text_width()));
    if let Some(c) = confirmation {
        print!(
            "{}",
            wrap(&confirmation_lines(c, &with_se, unit), text_width())
        );
    }
    print!("{}", wrap(&pick_line(&plan, &out), text_width()));
    for (label, _, why) in &out.terminations {
        say_err(&format!("{label}: {why}"));
    }
    say_err(&format!(
        "{} candidates evaluated; wrote {}/optimize.parquet and optimum.parquet",
        out.evaluations.len(),
        out.dir.display()
    ));
    Ok(())
}

/// The pool the searches and their runs share, of `--threads` workers
/// (default: rayon's), as `study run --threads` builds its own.
fn worker_pool(threads: Option<usize>) -> Result<rayon::ThreadPool, UserError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(crate::limits::capped_threads(threads).unwrap_or(0))
        .build()
        .map_err(|e| UserError::internal(e.to_string()))
}

/// The objective column's header: its name, and its unit below.
fn objective_header(spec: Option<&autobal::optimize::spec::OptimizeSpec>) -> String {
    let objective = spec.map_or("", |o| o.objective.name());
    let unit = spec.map_or("", |o| o.objective.unit());
    if unit.is_empty() {
        objective.to_string()
    } else {
        format!("{objective}\n{unit}")
    }
}

/// A candidate's kind, n and ρ cells: "plane 0/plane 1" where a second
/// plane's weights are its own.
fn design_cells(c: &autobal::optimize::evaluate::Candidate) -> [String; 3] {
    match c.plane1 {
        Some(p) => [
            if p.kind != c.kind {
                format!("{}/{}", c.kind, p.kind)
            } else {
                c.kind.to_string()
            },
            format!("{}/{}", c.n, p.n),
            format!("{:.3}/{:.3}", c.rho, p.rho),
        ],
        None => [c.kind.to_string(), c.n.to_string(), format!("{:.3}", c.rho)],
    }
}

/// What the confirmation on fresh samples found: the overall pick and why,
/// and the scopes tied with it.
fn confirmation_lines(
    c: &autobal::optimize::confirm::Confirmation,
    shown: &dyn Fn(f64, f64) -> String,
    unit: &str,
) -> String {
    let pick = &c.rows[c.overall];
    let mut text = format!(
        "overall: {} is the best of the (kind, n) optima on {} fresh samples (samples {}–{}, which the search never used): {} ± {}{}",
        pick.scope,
        c.samples,
        c.first_sample,
        c.first_sample + u64::from(c.samples) - 1,
        shown(pick.value, pick.std_err),
        shown(pick.std_err, pick.std_err),
        if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        },
    );
    if c.search_pick != c.overall {
        let own = &c.rows[c.search_pick];
        text += &format!(
            "; the search's own values picked {}, which gives {} ± {} on them",
            own.scope,
            shown(own.value, own.std_err),
            shown(own.std_err, own.std_err),
        );
    }
    text += "\n";
    let ties: Vec<String> = c
        .ties()
        .map(|r| {
            let d = r.vs_overall.expect("a tie has a difference");
            format!(
                "{} (Δ {} [{}, {}])",
                r.scope,
                shown(d.difference, pick.std_err),
                shown(d.interval.0, pick.std_err),
                shown(d.interval.1, pick.std_err),
            )
        })
        .collect();
    if ties.is_empty() {
        text += &format!(
            "every other (kind, n) optimum differs from {} on the fresh samples (its {:.0} % paired bootstrap interval of the difference excludes 0, and the difference is at least 1 %)\n",
            pick.scope,
            100.0 * c.level
        );
    } else {
        text += &format!(
            "tied with {} on the fresh samples (the {:.0} % paired bootstrap interval of the difference covers 0, or the difference is under 1 %), so choose among them by cost or another measure: {}\n",
            pick.scope,
            100.0 * c.level,
            ties.join(", ")
        );
    }
    text
}

/// The overall pick as a part to build, in mm and g ("pick: 5 balls of …");
/// "pick: unconfirmed — why" and the best candidate found when the pick's
/// own search did not converge.
fn pick_line(
    plan: &autobal::study::plan::config::StudyPlan,
    out: &autobal::optimize::OptimizeOutput,
) -> String {
    let Some(spec) = plan.file.optimize.as_ref() else {
        return String::new();
    };
    let Some(pick) = out.best.iter().find(|b| b.scope == "overall") else {
        return String::new();
    };
    let evaluator = autobal::optimize::evaluate::Evaluator {
        plan,
        spec,
        samples: 0,
    };
    let Some(part) = evaluator.part(&pick.evaluation.candidate) else {
        return String::new();
    };
    match &out.pick {
        PickStatus::Unconfirmed {
            pick,
            budget,
            searches,
            unconverged,
        } => format!(
            "pick: unconfirmed — {}; {unconverged} of {searches} searches did not converge (raise optimize.max_evaluations). Best candidate found, not a final part: {part}\n",
            unconverged_why(pick, *budget)
        ),
        PickStatus::Final | PickStatus::None => format!("pick: {part}\n"),
    }
}

/// Why a search's optimum is not final, in a clause.
fn unconverged_why(s: &autobal::optimize::pick::SearchStop, budget: u64) -> String {
    match s.end {
        SearchEnd::Budget => format!(
            "the search for {} ended on its budget of {budget} evaluations without converging",
            s.label
        ),
        SearchEnd::Unconfirmed => format!(
            "the search for {} found a point better than its optimum with too little of its budget of {budget} evaluations left to search from there",
            s.label
        ),
        SearchEnd::Infeasible => format!("the search for {} found no feasible candidate", s.label),
        SearchEnd::Converged => format!("the search for {} converged", s.label),
    }
}
