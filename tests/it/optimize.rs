//! `study optimize`: analytic optimum = Table 1, constraints, common random
//! numbers, determinism; the paper's complete optimisation.

use autobal::design::Shape;
use autobal::design::complete::{complete_optimization, rho_excess_onset};
use autobal::design::geometry::excess_weights;
use autobal::design::optimum::optimal_rho;
use autobal::model::balancer::Kind;
use autobal::optimize::evaluate::{Candidate, Evaluator};
use autobal::optimize::optimize;
use autobal::study::plan::config::{StudyFile, StudyPlan};
use std::path::Path;

fn plan(output: &Path, designs: &str, sampling: &str, optimize: &str) -> StudyPlan {
    let text = format!(
        r#"
name = "opt"
seed = 11
output = "{}"
[scene.rotor]
mass = 10.0
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
[scene.speed]
mode = "constant"
omega = 300.0
[designs]
race_radius = 0.05
roller_height = 0.01
{designs}
[sampling]
{sampling}
[metrics]
t_end_revs = 300
[optimize]
{optimize}
"#,
        output.display()
    );
    StudyFile::parse(&text, "opt.toml")
        .unwrap()
        .plan(&text, "opt.toml")
        .unwrap()
}

const FIXED: &str = "samples = 1\nunbalance = { distribution = \"fixed\", value = 0.5, relative_to = \"capacity\" }";

#[test]
fn analytic_capacity_optimum_is_table_1() {
    let tmp = tempfile::tempdir().unwrap();
    let p = plan(
        tmp.path(),
        "kind = [\"ball\", \"roller\"]\nn = [1, 2, 3, 4, 5, 6, 7, 8]\nrho = \"optimal\"\ndrag = 10.0",
        FIXED,
        "objective = \"capacity\"",
    );
    let out = optimize(&p).unwrap();
    for b in out.best.iter().filter(|b| {
        b.scope.contains('_') && !b.scope.starts_with("complete") && !b.scope.starts_with("per_n")
    }) {
        let c = b.evaluation.candidate;
        let want = optimal_rho(c.kind.model().shape(), c.n).unwrap().rho;
        assert!(
            (c.rho - want).abs() < 2e-3,
            "{}: ρ {} vs Table 1 {want}",
            b.scope,
            c.rho
        );
    }
    assert!(out.dir.join("optimize.parquet").exists() && out.dir.join("optimum.parquet").exists());
}

#[test]
fn every_constraint_is_respected() {
    let tmp = tempfile::tempdir().unwrap();
    let p = plan(
        tmp.path(),
        "kind = \"ball\"\nn = [2, 3, 4, 5, 6]\nrho = \"optimal\"\ndrag = 10.0",
        FIXED,
        "objective = \"capacity\"\nhousing_rho_max = 0.27\nsafety_factor = 1.5\nmax_unbalance = 0.004\nmin_n = 3",
    );
    let out = optimize(&p).unwrap();
    let ns: Vec<u32> = out.evaluations.iter().map(|e| e.candidate.n).collect();
    assert!(ns.iter().all(|&n| n >= 3), "min_n");
    for e in out.evaluations.iter().filter(|e| e.feasible) {
        assert!(
            e.candidate.rho <= 0.27 + 1e-12,
            "housing: {}",
            e.candidate.rho
        );
        assert!(
            e.capacity.unwrap() >= 1.5 * 0.004,
            "capacity {:?}",
            e.capacity
        );
    }
    // Some candidates were pushed against the capacity constraint and marked.
    assert!(
        out.evaluations
            .iter()
            .any(|e| !e.feasible && e.constraint.contains("capacity"))
    );
    for b in &out.best {
        assert!(b.evaluation.feasible, "{}", b.scope);
    }
}

#[test]
fn common_random_numbers_rank_the_better_design_first() {
    // In the fast regime (drag below the optimum) more drag settles faster.
    let tmp = tempfile::tempdir().unwrap();
    let p = plan(
        tmp.path(),
        "kind = \"ball\"\nn = 3\nrho = \"optimal\"\ndrag = 2.0",
        "samples = 12\nunbalance = { distribution = \"uniform\", min = 0.002, max = 0.006, relative_to = \"absolute\" }\nrequire_balanceable = false",
        "objective = \"settling_mean\"",
    );
    let spec = p.file.optimize.clone().unwrap();
    let ev = Evaluator {
        plan: &p,
        spec: &spec,
        samples: 12,
    };
    let at = |drag| {
        ev.evaluate(
            Candidate {
                kind: Kind::Ball,
                n: 3,
                rho: 0.36,
                drag,
                plane1: None,
            },
            "test",
        )
    };
    let (slow, fast) = (at(2.0), at(8.0));
    let (vs, vf) = (slow.value.unwrap(), fast.value.unwrap());
    assert!(
        vf < vs,
        "β = 8 ({vf} ± {}) should beat β = 2 ({vs} ± {})",
        fast.std_err,
        slow.std_err
    );
    assert!(slow.std_err > 0.0 && fast.std_err > 0.0);
    // The same candidate evaluates identically (same streams).
    assert_eq!(at(2.0).value, slow.value);
}

#[test]
fn optimisation_is_identical_for_any_thread_count() {
    let run = |threads| {
        let tmp = tempfile::tempdir().unwrap();
        let p = plan(
            tmp.path(),
            "kind = \"ball\"\nn = [3, 4]\nrho = \"optimal\"\ndrag = 10.0",
            "samples = 8\nunbalance = { distribution = \"uniform\", min = 0.2, max = 0.8, relative_to = \"capacity\" }",
            "objective = \"settling_mean\"\nmax_evaluations = 8",
        );
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| optimize(&p).unwrap()).evaluations
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn complete_optimisation_drops_weights_as_they_become_excess() {
    let limit = optimal_rho(Shape::Ball, 3).unwrap().rho;
    let c = complete_optimization(Shape::Ball, 10, limit).unwrap();
    assert_eq!(c.n, 3);
    assert_eq!(
        excess_weights(c.n, c.rho).unwrap(),
        0,
        "final design has no excess weight"
    );
    assert!(
        excess_weights(c.n + 1, c.rho).unwrap() > 0,
        "one more weight would be excess"
    );
    // Stages hand over exactly where the outermost weight reaches the horizontal.
    for w in c.stages.windows(2) {
        assert_eq!(w[0].rho_to, w[1].rho_from);
        assert_eq!(w[0].rho_to, rho_excess_onset(w[0].n).unwrap().unwrap());
        assert_eq!(w[1].n, w[0].n - 1);
    }
    assert_eq!(c.stages.first().unwrap().n, 10);
}

#[test]
fn nelder_mead_searches_rho_and_drag_within_bounds() {
    let tmp = tempfile::tempdir().unwrap();
    let p = plan(
        tmp.path(),
        "kind = \"ball\"\nn = 3\nrho = \"optimal\"\ndrag = 3.0",
        "samples = 6\nunbalance = { distribution = \"uniform\", min = 0.2, max = 0.8, relative_to = \"capacity\" }",
        "objective = \"settling_mean\"\nfree = [\"rho\", \"drag\"]\nrho_bounds = [0.2, 0.4]\ndrag_bounds = [1.0, 40.0]\nmax_evaluations = 24",
    );
    let out = optimize(&p).unwrap();
    assert!(out.evaluations.iter().all(|e| e.phase == "nelder_mead"));
    let best = &out
        .best
        .iter()
        .find(|b| b.scope == "overall")
        .unwrap()
        .evaluation;
    assert!(
        (0.2..=0.4).contains(&best.candidate.rho) && (1.0..=40.0).contains(&best.candidate.drag)
    );
    // Starting from β = 3 (under-damped weights), the search moves to more drag.
    let start = out.evaluations[0].value.unwrap();
    assert!(
        best.value.unwrap() <= start,
        "{} vs start {start}",
        best.value.unwrap()
    );
    assert!(best.candidate.drag > 3.0, "drag {}", best.candidate.drag);
}

/// The optimiser's settling objectives and the study summary count every
/// run alike: on the same samples, `settling_mean` is the summary's
/// restricted mean and `settling_median` its Kaplan–Meier median (two code
/// paths: order statistics of censored times, and the survival curve).
#[test]
fn settling_objectives_equal_the_summarys_censoring_aware_statistics() {
    use autobal::study::run::{NoProgress, RunOptions, run_study};
    let tmp = tempfile::tempdir().unwrap();
    let value = |objective: &str| {
        let p = plan(
            tmp.path(),
            "kind = \"ball\"\nn = 3\nrho = 0.3\ndrag = 0.15",
            "samples = 15\nunbalance = { distribution = \"uniform\", min = 0.2, max = 0.9, relative_to = \"capacity\" }",
            &format!("objective = \"{objective}\""),
        );
        let spec = p.file.optimize.clone().unwrap();
        let ev = Evaluator {
            plan: &p,
            spec: &spec,
            samples: 15,
        };
        let c = Candidate {
            kind: Kind::Ball,
            n: 3,
            rho: p.designs[0].rho,
            drag: 0.15,
            plane1: None,
        };
        (ev.evaluate(c, "test").value.unwrap(), p)
    };
    let (mean, p) = value("settling_mean");
    let (median, _) = value("settling_median");
    let summary = run_study(&p, &RunOptions::default(), &NoProgress)
        .unwrap()
        .summary
        .unwrap();
    let get = |name: &str| summary.column(name).unwrap().f64().unwrap().get(0);
    let settled = get("settled_fraction").unwrap();
    assert!(
        settled < 1.0 && settled > 0.5,
        "the case needs censored runs and a bounded median: settled {settled}"
    );
    let rmst = get("settling_revs_rmst").unwrap();
    assert!((mean - rmst).abs() <= 1e-9 * rmst, "{mean} vs {rmst}");
    assert_eq!(Some(median), get("settling_revs_median_km"));
}

/// The issue's study: an 8 kg rotor on soft supports at 1200 rpm, steel
/// balls in a 25 mm race, absolute unbalances, settling_mean over (ρ, β).
fn soft_rotor_plan(output: &Path, max_evaluations: u64) -> StudyPlan {
    let text = soft_rotor_text(output, max_evaluations);
    StudyFile::parse(&text, "soft.toml")
        .unwrap()
        .plan(&text, "soft.toml")
        .unwrap()
}

/// The text of [`soft_rotor_plan`].
fn soft_rotor_text(output: &Path, max_evaluations: u64) -> String {
    format!(
        r#"
name = "soft"
output = "{}"
{}drag = 0.5
[sampling]
samples = 48
unbalance = {{ distribution = "uniform", min = 2e-5, max = 2e-4, relative_to = "absolute" }}
initial = "clustered"
[optimize]
objective = "settling_mean"
free = ["rho", "drag"]
drag_bounds = [0.05, 20.0]
max_evaluations = {max_evaluations}
"#,
        output.display(),
        crate::fixtures::SOFT_ROTOR
    )
}

#[test]
fn the_simplex_optimum_is_the_grids_best_within_its_standard_error() {
    let tmp = tempfile::tempdir().unwrap();
    let plan = soft_rotor_plan(tmp.path(), 30);
    let out = optimize(&plan).unwrap();
    let (_, _, why) = &out.terminations[0];
    let best = out.best.iter().find(|b| b.scope == "ball_3").unwrap();
    let (value, se) = (best.evaluation.value.unwrap(), best.evaluation.std_err);
    // A 9 × 9 grid over ρ × ln β on the same samples.
    let spec = plan.file.optimize.clone().unwrap();
    let evaluator = Evaluator {
        plan: &plan,
        spec: &spec,
        samples: 48,
    };
    let rho_hi = autobal::optimize::search::rho_interval(&evaluator, 3).1;
    let mut grid_best = f64::INFINITY;
    for i in 0..9 {
        for j in 0..9 {
            let rho = 0.02 + (rho_hi - 0.02) * f64::from(i) / 8.0;
            let drag = (0.05f64.ln() + (20.0f64 / 0.05).ln() * f64::from(j) / 8.0).exp();
            let e = evaluator.evaluate(
                Candidate {
                    kind: Kind::Ball,
                    n: 3,
                    rho,
                    drag,
                    plane1: None,
                },
                "grid",
            );
            if let Some(v) = e.value {
                grid_best = grid_best.min(v);
            }
        }
    }
    assert!(
        value <= grid_best + se,
        "optimum {value} ± {se}, grid best {grid_best}: {why}"
    );
}

#[test]
fn a_budget_stop_is_never_called_converged() {
    let tmp = tempfile::tempdir().unwrap();
    let out = optimize(&soft_rotor_plan(tmp.path(), 12)).unwrap();
    let (_, _, why) = &out.terminations[0];
    assert!(
        why.contains("budget: optimize.max_evaluations = 12 used up"),
        "{why}"
    );
    assert!(!why.contains("converged:"), "{why}");
}

/// The issue's case: on 48 samples the (ρ, β) search over 3, 4 and 5 balls
/// picks n = 3, whose two rare runs that never settle are not among the 48.
/// Confirmed on 300 fresh samples, that pick is worse than the n = 4
/// optimum, which becomes the overall pick (before, the search's own values
/// chose, and the overall row was n = 3).
#[test]
fn the_overall_pick_is_the_best_on_fresh_samples_not_on_the_searchs_own() {
    let tmp = tempfile::tempdir().unwrap();
    let text = soft_rotor_text(tmp.path(), 150)
        .replace("n = 3\n", "n = [3, 4, 5]\n")
        .replace("[optimize]\n", "[optimize]\nconfirm_samples = 300\n");
    let plan = StudyFile::parse(&text, "soft.toml")
        .unwrap()
        .plan(&text, "soft.toml")
        .unwrap();
    let out = optimize(&plan).unwrap();
    let c = out
        .confirmation
        .as_ref()
        .expect("a simulated objective is confirmed");
    assert_eq!((c.first_sample, c.samples), (48, 300));
    let search = &c.rows[c.search_pick];
    let pick = &c.rows[c.overall];
    assert_eq!(search.scope, "ball_3");
    assert_ne!(c.overall, c.search_pick);
    // The search's pick is worse on the fresh samples, beyond its interval.
    let d = search.vs_overall.unwrap();
    assert!(d.difference > 0.0 && d.interval.0 > 0.0, "{d:?}");
    assert!(
        search.value > pick.value + 2.0 * pick.std_err,
        "{search:?} {pick:?}"
    );
    let overall = out.best.iter().find(|b| b.scope == "overall").unwrap();
    assert_eq!(overall.evaluation.candidate, pick.candidate);
}

/// Optima that the fresh samples cannot tell apart are stated as ties: at
/// a horizon every run settles within, every count settles in all runs, so
/// each difference of the settled share is exactly 0 and covers it.
#[test]
fn ties_between_counts_are_stated() {
    let tmp = tempfile::tempdir().unwrap();
    let p = plan(
        tmp.path(),
        "kind = \"ball\"\nn = [3, 4]\nrho = \"optimal\"\ndensity = 7850.0\ndrag = 10.0",
        "samples = 4\nunbalance = { distribution = \"uniform\", min = 0.2, max = 0.6, relative_to = \"capacity\" }",
        "objective = \"settled_fraction\"\nmax_evaluations = 5\nconfirm_samples = 8",
    );
    let out = optimize(&p).unwrap();
    let c = out.confirmation.unwrap();
    assert!(c.rows.iter().all(|r| r.value == 1.0), "{:?}", c.rows);
    let ties: Vec<&str> = c.ties().map(|r| r.scope.as_str()).collect();
    assert_eq!(ties.len(), 1, "{ties:?}");
    assert_ne!(ties[0], c.rows[c.overall].scope);
}

/// Issue 46: each (kind, n) search spent one evaluation over
/// `max_evaluations` (4 gave 5, 10 gave 11): the scan, Brent's start and
/// the simplex now stay within it.
#[test]
fn no_search_spends_more_than_max_evaluations() {
    for (free, max) in [("", 4), ("", 10), ("free = [\"rho\", \"drag\"]\n", 5)] {
        let tmp = tempfile::tempdir().unwrap();
        let p = plan(
            tmp.path(),
            "kind = \"ball\"\nn = 3\nrho = \"optimal\"\ndrag = 10.0",
            "samples = 2\nunbalance = { distribution = \"uniform\", min = 0.2, max = 0.8, relative_to = \"capacity\" }",
            &format!(
                "objective = \"settling_mean\"\n{free}max_evaluations = {max}\nconfirm_samples = 0"
            ),
        );
        let out = optimize(&p).unwrap();
        let searched = out
            .evaluations
            .iter()
            .filter(|e| e.phase != "confirm")
            .count();
        assert!(
            (1..=max).contains(&searched),
            "{free}max_evaluations = {max}: {searched} evaluations"
        );
    }
}

/// An optical drive with ρ and β free whose searches start on a slow
/// plateau (β = 0.2 N·s/m, most runs counted at the 150-rev horizon).
fn optical_drive_plan(output: &Path) -> StudyPlan {
    let text = crate::decisions::optical_drive(output, "od", 200)
        .replace("n = 4\nrho = 0.067", "n = [3, 4, 5]\nrho = 0.1")
        .replace("drag = 3e-5", "drag = 0.2")
        .replace("samples = 4", "samples = 12")
        + "[optimize]\nobjective = \"settling_mean\"\nfree = [\"rho\", \"drag\"]\nrho_bounds = [0.05, 0.2]\ndrag_bounds = [0.001, 1.0]\nmax_evaluations = 20\n";
    assert!(
        text.contains("n = [3, 4, 5]")
            && text.contains("drag = 0.2")
            && text.contains("samples = 12")
    );
    StudyFile::parse(&text, "od.toml")
        .unwrap()
        .plan(&text, "od.toml")
        .unwrap()
}

/// A count's search is checked against the optima the other counts found,
/// on its own samples: none may end better than its printed optimum by more
/// than their standard errors, and the 5-ball search, whose own optimum the
/// 4-ball one beats, is not called converged and prints the better point
/// (before, each count's search knew nothing of the others').
#[test]
fn a_counts_optimum_is_checked_against_the_other_counts_optima() {
    let tmp = tempfile::tempdir().unwrap();
    let plan = optical_drive_plan(tmp.path());
    let out = optimize(&plan).unwrap();
    for n in [3, 4, 5] {
        let best = out
            .best
            .iter()
            .find(|b| b.scope == format!("ball_{n}"))
            .unwrap();
        let checked: Vec<(f64, f64)> = out
            .evaluations
            .iter()
            .filter(|e| e.candidate.n == n && e.phase == "cross_check")
            .map(|e| (e.candidate.rho, e.candidate.drag))
            .collect();
        // Exactly the other counts' optima, each tried once.
        let mut others: Vec<(f64, f64)> = out
            .best
            .iter()
            .filter(|b| b.scope.starts_with("ball_") && b.scope != best.scope)
            .map(|b| (b.evaluation.candidate.rho, b.evaluation.candidate.drag))
            .collect();
        assert_eq!(checked.len(), 2, "n = {n}: one check per other count");
        others.retain(|p| !checked.contains(p));
        // A count whose search moved after the check (n = 5) has a new optimum.
        assert!(others.len() <= 1, "n = {n}: {others:?} not checked");
    }
    let (_, _, why) = out
        .terminations
        .iter()
        .find(|(_, scope, _)| scope == "ball_5")
        .unwrap();
    assert!(
        why.starts_with("unconfirmed: the optimum of ball n = 4")
            || why.starts_with("restarted: the optimum of ball n = 4"),
        "{why}"
    );
    let four = out.best.iter().find(|b| b.scope == "ball_4").unwrap();
    let five = out.best.iter().find(|b| b.scope == "ball_5").unwrap();
    assert_eq!(
        (
            five.evaluation.candidate.rho,
            five.evaluation.candidate.drag
        ),
        (
            four.evaluation.candidate.rho,
            four.evaluation.candidate.drag
        ),
        "the 5-ball optimum printed is the 4-ball point, better on its samples"
    );
}

/// `study optimize` names the pick as a part to build, in mm and g
/// (before: (ρ, β) only).
#[test]
fn the_pick_is_printed_as_a_part() {
    let tmp = tempfile::tempdir().unwrap();
    let text = crate::bad_input::study(&tmp.path().join("results"))
        .replace("n = 3\n", "n = [3, 4]\n")
        + "[optimize]\nobjective = \"capacity\"\nfree = [\"rho\"]\n";
    let path = tmp.path().join("s.toml");
    std::fs::write(&path, text).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["optimize", path.to_str().unwrap(), "--wide"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let pick = stdout
        .lines()
        .find(|l| l.starts_with("pick: "))
        .unwrap_or_else(|| panic!("no pick line: {stdout}"));
    assert!(
        pick.contains(" balls of ") && pick.contains(" mm diameter, ") && pick.contains(" g each"),
        "{pick}"
    );
}

/// `study optimize` on `text` (written to `dir`/s.toml) with `args`.
fn optimize_cli(dir: &Path, text: &str, args: &[&str]) -> std::process::Output {
    let path = dir.join("s.toml");
    std::fs::write(&path, text).unwrap();
    std::process::Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["optimize", path.to_str().unwrap(), "--wide"])
        .args(args)
        .output()
        .unwrap()
}

/// The corpus study with a simulated objective and `max_evaluations`.
fn settling_text(results: &Path, max_evaluations: u64) -> String {
    crate::bad_input::study(results)
        + &format!(
            "[optimize]\nobjective = \"settling_mean\"\nmax_evaluations = {max_evaluations}\nconfirm_samples = 0\n"
        )
}

/// A search that ends on its budget gives a candidate, not a part: with
/// `max_evaluations = 4` the ρ scan spends the whole budget, and the last
/// line says "pick: unconfirmed" with why, then the best candidate (before,
/// it printed "pick: 3 balls of …" as final).
#[test]
fn a_pick_whose_search_ended_on_its_budget_is_printed_unconfirmed() {
    let tmp = tempfile::tempdir().unwrap();
    let out = optimize_cli(
        tmp.path(),
        &settling_text(&tmp.path().join("results"), 4),
        &[],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let pick = stdout
        .lines()
        .find(|l| l.starts_with("pick: "))
        .unwrap_or_else(|| panic!("no pick line: {stdout}"));
    assert!(
        pick.starts_with(
            "pick: unconfirmed — the search for ball n = 3 ended on its budget of 4 evaluations without converging; 1 of 1 searches did not converge"
        ),
        "{pick}"
    );
    assert!(
        pick.contains("Best candidate found, not a final part: 3 balls of "),
        "{pick}"
    );
    // The library says so, typed: the pick's own search ended on its budget.
    let plan = {
        let text = settling_text(&tmp.path().join("again"), 4);
        StudyFile::parse(&text, "s.toml")
            .unwrap()
            .plan(&text, "s.toml")
            .unwrap()
    };
    match optimize(&plan).unwrap().pick {
        autobal::optimize::pick::PickStatus::Unconfirmed { pick, budget, .. } => {
            assert_eq!(
                (pick.end, budget),
                (autobal::optimize::search::SearchEnd::Budget, 4)
            );
        }
        other => panic!("{other:?}"),
    }
}

/// `--threads 1` and `--threads 2` print the same and write the same
/// optimize.parquet and optimum.parquet, bit for bit.
#[test]
fn optimize_threads_give_identical_outputs() {
    use autobal::study::results::io::read_parquet;
    let run = |threads: &str| {
        let tmp = tempfile::tempdir().unwrap();
        let text = settling_text(&tmp.path().join("results"), 6)
            .replace("n = 3\n", "n = [3, 4]\n")
            .replace("confirm_samples = 0", "confirm_samples = 2");
        let out = optimize_cli(tmp.path(), &text, &["--threads", threads]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let folder = tmp.path().join("results").join("corpus");
        let frames =
            ["optimize.parquet", "optimum.parquet"].map(|f| read_parquet(&folder.join(f)).unwrap());
        (String::from_utf8_lossy(&out.stdout).to_string(), frames)
    };
    let (one, two) = (run("1"), run("2"));
    assert_eq!(one.0, two.0);
    for (a, b) in one.1.iter().zip(&two.1) {
        assert!(a.height() > 0);
        assert!(a.equals_missing(b), "{a}\n{b}");
    }
}

/// `optimize.max_peak_over_a_ref` makes the candidates whose median
/// start-up whirl exceeds it infeasible: set just below the unconstrained
/// pick's, that pick is excluded, and every candidate is feasible exactly
/// when its median is within the limit.
#[test]
fn a_start_up_whirl_limit_excludes_the_candidates_above_it() {
    let constrained = |limit: Option<f64>| {
        let tmp = tempfile::tempdir().unwrap();
        let p = plan(
            tmp.path(),
            "kind = \"ball\"\nn = [2, 3, 4]\nrho = \"optimal\"\ndrag = 10.0",
            "samples = 4\nunbalance = { distribution = \"uniform\", min = 0.2, max = 0.8, relative_to = \"capacity\" }\ninitial = \"clustered\"",
            &format!(
                "objective = \"settling_mean\"\nmax_evaluations = 6\nconfirm_samples = 0\n{}",
                limit.map_or(String::new(), |l| format!("max_peak_over_a_ref = {l}"))
            ),
        );
        optimize(&p).unwrap()
    };
    let free = constrained(None);
    let pick = |out: &autobal::optimize::OptimizeOutput| {
        out.best
            .iter()
            .find(|b| b.scope == "overall")
            .map(|b| b.evaluation.clone())
    };
    let before = pick(&free).unwrap();
    let peak = before.peak_whirl_over_a_ref.unwrap();
    assert!(
        peak > 1.0,
        "the clustered start whirls beyond A_ref: {peak}"
    );
    // Without the limit the whirl is recorded and nothing is excluded for it.
    assert!(free.evaluations.iter().all(|e| e.feasible));
    let limit = 0.999 * peak;
    let out = constrained(Some(limit));
    let mut excluded = 0;
    for e in &out.evaluations {
        let p = e.peak_whirl_over_a_ref.unwrap();
        assert_eq!(e.feasible, p <= limit, "{e:?}");
        if !e.feasible {
            excluded += 1;
            assert!(
                e.constraint.contains("optimize.max_peak_over_a_ref"),
                "{e:?}"
            );
            assert_eq!(e.value, None);
        }
    }
    assert!(excluded > 0);
    match pick(&out) {
        Some(after) => {
            assert_ne!(after.candidate, before.candidate);
            assert!(after.peak_whirl_over_a_ref.unwrap() <= limit);
        }
        None => assert_eq!(out.pick, autobal::optimize::pick::PickStatus::None),
    }
}

/// A start-up whirl limit that is not positive is refused, naming the key.
#[test]
fn a_bad_start_up_whirl_limit_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let text = settling_text(&tmp.path().join("results"), 6)
        .replace("[optimize]\n", "[optimize]\nmax_peak_over_a_ref = -1.0\n");
    let out = optimize_cli(tmp.path(), &text, &[]);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("optimize.max_peak_over_a_ref = -1: must be positive and finite"),
        "{stderr}"
    );
    assert!(!tmp.path().join("results").exists());
}

/// The summary's start-up whirl columns are the median and 95th
/// percentile of each design's `peak_r / a_ref`, recomputed here from
/// runs.parquet.
#[test]
fn the_summarys_start_up_whirl_is_the_runs_peak_over_a_ref() {
    use autobal::study::results::io::read_parquet;
    use autobal::study::run::{NoProgress, RunOptions, run_study};
    let tmp = tempfile::tempdir().unwrap();
    let p = plan(
        tmp.path(),
        "kind = \"ball\"\nn = [3, 4]\nrho = \"optimal\"\ndrag = 10.0",
        "samples = 5\nunbalance = { distribution = \"uniform\", min = 0.2, max = 0.8, relative_to = \"capacity\" }\ninitial = \"clustered\"",
        "objective = \"settling_mean\"",
    );
    let out = run_study(&p, &RunOptions::default(), &NoProgress).unwrap();
    let summary = out.summary.unwrap();
    let runs = read_parquet(&out.dir.join("runs.parquet")).unwrap();
    let col = |name: &str| -> Vec<f64> {
        runs.column(name)
            .unwrap()
            .f64()
            .unwrap()
            .into_no_null_iter()
            .collect()
    };
    let (peak, a_ref) = (col("peak_r"), col("a_ref"));
    let design: Vec<u32> = runs
        .column("design_id")
        .unwrap()
        .u32()
        .unwrap()
        .into_no_null_iter()
        .collect();
    let outcome: Vec<String> = runs
        .column("outcome")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|o| o.unwrap().to_string())
        .collect();
    assert!(outcome.iter().all(|o| o == "settled" || o == "censored"));
    let ids = summary.column("design_id").unwrap().u32().unwrap().clone();
    let median = summary
        .column("peak_whirl_over_a_ref_median")
        .unwrap()
        .f64()
        .unwrap()
        .clone();
    let p95 = summary
        .column("peak_whirl_over_a_ref_p95")
        .unwrap()
        .f64()
        .unwrap()
        .clone();
    for (row, id) in ids.into_no_null_iter().enumerate() {
        let mut r: Vec<f64> = (0..runs.height())
            .filter(|&i| design[i] == id)
            .map(|i| peak[i] / a_ref[i])
            .collect();
        r.sort_by(f64::total_cmp);
        assert_eq!(r.len(), 5);
        // Five runs: the median is the third, the p95 0.8 of the way from the fourth to the fifth.
        assert_eq!(median.get(row), Some(r[2]));
        let want = r[3] + 0.8 * (r[4] - r[3]);
        let got = p95.get(row).unwrap();
        assert!((got - want).abs() <= 1e-12 * want, "{got} vs {want}");
        assert!(r[2] > 1.0, "clustered weights whirl beyond A_ref: {r:?}");
    }
}
