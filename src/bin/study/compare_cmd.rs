//! `study compare`: two designs side by side, paired when they met the same
//! unbalances, with a verdict at a stated α.

use crate::UserError;
use crate::output::{p_value_text, say, text_table};
use crate::plot_cmd::{check_figure_path, plot_error};
use autobal::decide::compare_designs::{
    DesignComparison, PairVerdict, Pairing, Side, common_scale, compare_sides, median_with_interval,
};
use autobal::decide::plane_summary::PlaneStats;
use autobal::decide::verdict::{Comparison, Favours};
use autobal::plot::km::{KmCurve, SecondsAxis, plot_kaplan_meier};
use autobal::study::plan::criterion::Criterion;
use autobal::study::results::measured_runs::Scale;
use clap::Args;
use std::path::{Path, PathBuf};

/// Examples shown under `study compare --help`.
pub const EXAMPLES: &str = "Examples:
  study compare results/three_balls --designs 0,7       two designs of one study
  study compare results/a results/b                     the only design of each folder
  study compare results/a results/b --designs 2,0       design 2 of a against design 0 of b
  study compare results/three_balls --designs 0,7 --plot km.svg
                                                        and their Kaplan–Meier curves (.svg or .png)";

/// Arguments of `study compare`.
#[derive(Args)]
pub struct CompareArgs {
    /// One results folder (two of its designs) or two (one design of each).
    #[arg(required = true, num_args = 1..=2)]
    folders: Vec<PathBuf>,
    /// Design ids A,B (with one folder: required; with two: when a folder holds several designs).
    // No file names: a shell offers none and shows "A,B" (the ids are the
    // ranking's id column).
    #[arg(long, value_delimiter = ',', value_name = "A,B", value_hint = clap::ValueHint::Other)]
    designs: Option<Vec<u32>>,
    /// Significance level of the verdict.
    #[arg(long, default_value_t = 0.05, value_parser = crate::limits::significance)]
    alpha: f64,
    /// Also draw both designs' Kaplan–Meier curves into this file (.svg or .png, by extension).
    #[arg(long, value_name = "FILE")]
    plot: Option<PathBuf>,
    /// The measure the verdict rests on (default: the first study's `[summary] rank_by`):
    /// median, mean, p90, settled_fraction, settled_by:<X>rev|s, residual_p95, p_residual_below:<X>m.
    #[arg(long, value_parser = crate::completion_values::CriterionParser, hide_possible_values = true, value_name = "CRITERION")]
    rank_by: Option<Criterion>,
}

/// "= 0.0123" or "< 0.0001".
fn p_eq(p: f64) -> String {
    let text = p_value_text(p);
    if text.starts_with('<') {
        text
    } else {
        format!("= {text}")
    }
}

/// Run `study compare`.
pub fn run(args: &CompareArgs) -> Result<(), UserError> {
    if let Some(path) = &args.plot {
        check_figure_path("--plot", path)?;
    }
    let (dir_a, dir_b) = match args.folders.as_slice() {
        [one] => (one, one),
        [a, b] => (a, b),
        _ => unreachable!("clap takes one or two folders"),
    };
    let (design_a, design_b) = design_pair(args, dir_a, dir_b)?;
    let a = Side::load(dir_a, design_a)?;
    let b = Side::load(dir_b, design_b)?;
    let criterion = args.rank_by.unwrap_or(a.default_criterion);
    let scale = common_scale(&a, &b);
    let result = compare_sides(&a, &b, 0, criterion);
    print_side_table(&a, &b, &scale);
    say_settling_test(&a, &result);
    // Every measure of this one pair, Holm-adjusted over the measures; the
    // verdict is the library's (DesignComparison::verdict).
    let verdict = result.verdict(args.alpha);
    say_measures(&result.comparison, &verdict);
    say(&format!(
        "verdict: {}",
        verdict_text(&verdict, criterion, args.alpha)
    ));
    for line in disagreement_lines(&verdict) {
        say(&line);
    }
    if let Some(path) = &args.plot {
        plot_sides(&a, &b, path)?;
        say(&format!("wrote {}", path.display()));
    }
    Ok(())
}

/// The side-by-side table first, so the reader sees both designs before any
/// test; the clock and horizon note says how its times were counted.
fn print_side_table(a: &Side, b: &Side, scale: &Scale) {
    let (ca, cb) = (side_column(a, scale), side_column(b, scale));
    let names = [
        "design",
        "runs",
        "settled [95% CI]",
        "t_s median [95% CI] (rev)",
        "t_s mean to τ [95% CI] (rev)",
        "t_s p90 (rev)",
        "residual/A_ref, median",
        "residual/A_ref, p95",
        "residual p95 (µm)",
        "folder",
    ];
    let mut rows: Vec<Vec<String>> = names
        .iter()
        .enumerate()
        .map(|(i, n)| vec![n.to_string(), ca[i].clone(), cb[i].clone()])
        .collect();
    // Before the folder row, which closes the table.
    let folder = rows.pop();
    rows.extend(plane_rows(a, b));
    rows.extend(folder);
    print!("{}", text_table(&["", "A", "B"], &rows));
    say(&format!(
        "(settling times counted {}; a run that did not settle counts as censored; restricted mean and p90 up to τ = {:.1} rev, the earlier horizon of the two)",
        a.clock.describe(),
        scale.tau
    ));
}

/// One design's column of the side-by-side table, on the pair's common
/// horizon so both columns measure the same thing.
fn side_column(side: &Side, scale: &Scale) -> Vec<String> {
    let f = |v: Option<f64>, d: usize| v.map_or("–".to_string(), |x| format!("{x:.d$}"));
    let end = |v: Option<f64>| v.map_or("∞".to_string(), |x| format!("{x:.1}"));
    let (settled, runs, (lo, hi)) = side.settled();
    let km = side.kaplan_meier();
    let (median, (m_lo, m_hi)) = km
        .as_ref()
        .map_or((None, (None, None)), median_with_interval);
    let rmst = km.map(|k| k.restricted_mean(scale.tau));
    let residual_values: Vec<f64> = side.runs.residual.iter().flatten().copied().collect();
    let residual = autobal::stats::quantile::median(&residual_values);
    let p90 = Criterion::P90.value(&side.runs, scale);
    let residual_p95 = Criterion::ResidualP95.value(&side.runs, scale);
    vec![
        side.label.clone(),
        format!("{runs}"),
        format!(
            "{:.3} [{lo:.2}, {hi:.2}]",
            settled as f64 / runs.max(1) as f64
        ),
        match median {
            Some(m) => format!("{m:.1} [{}, {}]", end(m_lo), end(m_hi)),
            None => "beyond the run".into(),
        },
        rmst.map_or("–".into(), |r| {
            // The same bounded interval as summary.parquet's.
            let i = r.bounded_interval(0.95);
            format!("{:.1} [{:.1}, {:.1}]", r.estimate, i.lower, i.upper)
        }),
        p90.map_or("beyond the run".into(), |x| format!("{x:.1}")),
        f(residual, 4),
        f(residual_p95, 4),
        {
            let mut abs: Vec<f64> = side.runs.residual_abs.iter().flatten().copied().collect();
            abs.sort_by(f64::total_cmp);
            autobal::stats::quantile::quantile_sorted(
                &abs,
                0.95,
                autobal::stats::quantile::Interpolation::Linear,
            )
            .map_or("–".into(), |r| format!("{:.2}", r * 1e6))
        },
        side.dir.display().to_string(),
    ]
}

/// The settling test the pairing allowed: paired sign test (and the paired
/// residual test) when the runs met the same draws, else why not and the
/// log-rank test.
fn say_settling_test(a: &Side, result: &DesignComparison) {
    let c = &result.comparison;
    let rev = |x: f64| {
        if x.is_finite() {
            format!("{x:.1}")
        } else {
            "∞".into()
        }
    };
    match (&c.paired, &result.pairing) {
        (Some(pair), _) => {
            say(&format!(
                "paired on {} samples that met {}: A settles sooner in {:.0} % [{:.0}, {:.0}], B in {:.0} %, ties {:.0} %",
                pair.n,
                a.shared(),
                100.0 * pair.a_sooner_share,
                100.0 * pair.a_sooner_share_interval.0,
                100.0 * pair.a_sooner_share_interval.1,
                100.0 * pair.b_sooner as f64 / pair.n as f64,
                100.0 * pair.ties as f64 / pair.n as f64
            ));
            let (d, (lo, hi)) = (pair.median_difference, pair.median_difference_interval);
            // "∞" is explained only where it is printed.
            let infinite = [d, lo, hi].iter().any(|x| !x.is_finite());
            say(&format!(
                "paired difference t_B − t_A: median {} rev [{}, {}]{}; sign test p {}",
                rev(d),
                rev(lo),
                rev(hi),
                if infinite {
                    " (∞: B did not settle in half the pairs or more)"
                } else {
                    ""
                },
                p_eq(pair.sign_test_p)
            ));
            if let (Some(w), Some((ratio, (lo, hi)))) = (&c.residual_test, c.residual_ratio) {
                say(&format!(
                    "residual vibration: median ratio A/B {ratio:.3} [{lo:.3}, {hi:.3}], Wilcoxon signed-rank p {} ({} pairs)",
                    p_eq(w.p_value),
                    w.n
                ));
            }
        }
        (None, Pairing::Refused(why)) => {
            say(&format!("not paired: {why}"));
            match &c.unpaired {
                Some(lr) => say(&format!(
                    "log-rank test: χ² = {:.3}, p {} (A settled {:.0} times, {:.1} expected if both settle alike)",
                    lr.chi_squared,
                    p_eq(lr.p_value),
                    lr.observed_a,
                    lr.expected_a
                )),
                None => say("log-rank test: no run settled in either design"),
            }
        }
        (None, Pairing::Paired) => say("nothing to compare: no runs"),
    }
}

/// One line per measure with its own test and its Holm-adjusted p-value, so
/// the verdict below can be checked against every measure.
fn say_measures(c: &Comparison, verdict: &PairVerdict) {
    for (m, p_holm) in c.measures.iter().zip(&verdict.p_holm) {
        let Some(d) = m.difference else {
            say(&format!("{}: nothing to compare", m.criterion.label()));
            continue;
        };
        let unit = m.criterion.unit();
        let scale_by = if unit == "%" { 100.0 } else { 1.0 };
        let show = |x: f64| {
            if x.is_finite() {
                format!("{:.3}", scale_by * x)
            } else {
                "∞".into()
            }
        };
        // The log-rank test gives no interval of the difference of medians.
        let interval = if d.interval.0.is_finite() || d.interval.1.is_finite() {
            format!(" [{}, {}]", show(d.interval.0), show(d.interval.1))
        } else {
            String::new()
        };
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        // The sign test's difference is the median of the paired
        // differences, not the difference of the two medians shown.
        let what = if d.test == "sign" {
            "median of the paired differences A − B"
        } else {
            "A − B"
        };
        say(&format!(
            "{}: A {} vs B {}, {what} {}{interval}{unit}, {} p {} (Holm over the {} measures: {})",
            m.criterion.label(),
            show(d.a),
            show(d.b),
            show(d.difference),
            d.test,
            p_eq(d.p_value),
            c.measures.len(),
            p_value_text(*p_holm)
        ));
    }
}

/// The verdict sentence on the criterion alone, naming the level it was
/// reached at.
fn verdict_text(verdict: &PairVerdict, criterion: Criterion, alpha: f64) -> String {
    match verdict.criterion_favours {
        Some(Favours::A) => format!(
            "A is better than B on the {} (α = {})",
            criterion.label(),
            alpha
        ),
        Some(Favours::B) => format!(
            "B is better than A on the {} (α = {})",
            criterion.label(),
            alpha
        ),
        None => format!(
            "not distinguishable on the {} at α = {}",
            criterion.label(),
            alpha
        ),
    }
}

/// How one plane statistic is shown ("–" where it is missing).
type PlaneCell = dyn Fn(&PlaneStats) -> Option<String>;

/// Each watched plane's settled share, median settling time and residual
/// p95 for sides on rotors with several planes (a side without them shows "–").
fn plane_rows(a: &Side, b: &Side) -> Vec<Vec<String>> {
    let planes = a.plane_stats.len().max(b.plane_stats.len());
    let cell = |side: &Side, p: usize, f: &PlaneCell| {
        side.plane_stats
            .get(p)
            .and_then(f)
            .unwrap_or_else(|| "–".into())
    };
    let mut rows = Vec::new();
    for p in 0..planes {
        let named: [(String, &PlaneCell); 3] = [
            (format!("plane {p}: settled"), &|s| {
                s.settled_fraction.map(|f| format!("{f:.3}"))
            }),
            (
                format!("plane {p}: t_s median, Kaplan–Meier (rev)"),
                &|s| {
                    Some(
                        s.settling_median_km
                            .map_or("beyond the run".into(), |m| format!("{m:.1}")),
                    )
                },
            ),
            (format!("plane {p}: residual p95 (µm)"), &|s| {
                s.residual_abs_p95.map(|r| format!("{:.1}", r * 1e6))
            }),
        ];
        for (name, f) in named {
            rows.push(vec![name, cell(a, p, f), cell(b, p, f)]);
        }
    }
    rows
}

/// The figure's title, naming the study folder (or both, when the sides
/// come from two studies).
fn compare_title(a: &Side, b: &Side) -> String {
    let folder = |s: &Side| {
        s.dir
            .canonicalize()
            .unwrap_or_else(|_| s.dir.clone())
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| s.dir.display().to_string())
    };
    let (fa, fb) = (folder(a), folder(b));
    let studies = if fa == fb {
        fa
    } else {
        format!("{fa} vs {fb}")
    };
    format!("{studies}: fraction of runs settled by t")
}

/// Draw the Kaplan–Meier curves of both sides into `path`.
fn plot_sides(a: &Side, b: &Side, path: &Path) -> Result<(), UserError> {
    let curve = |name: &str, side: &Side| KmCurve {
        label: format!("{name}: {}", side.figure_label),
        observations: side.runs.settling.clone(),
        horizon: side.horizon,
    };
    let curves = [curve("A", a), curve("B", b)];
    let title = compare_title(a, b);
    // Seconds only where both sides count on the same clock.
    let axis = |s: &Side| SecondsAxis::for_clock(s.clock, s.scale.rev_seconds);
    let seconds = Some(axis(a)).filter(|x| *x == axis(b));
    plot_kaplan_meier(&curves, &title, seconds, path).map_err(|e| {
        let UserError(message, code) = plot_error(e);
        UserError(format!("--plot {}: {message}", path.display()), code)
    })
}

/// The other measures that favour a side the criterion did not choose, one
/// line per side ("but B is significantly better on …: the measures
/// disagree"; "yet A is …" when the criterion chose neither).
fn disagreement_lines(verdict: &PairVerdict) -> Vec<String> {
    let mut lines = Vec::new();
    for side in [Favours::A, Favours::B] {
        let on: Vec<String> = verdict
            .disagreeing
            .iter()
            .filter(|(_, s)| *s == side)
            .map(|(m, _)| m.label())
            .collect();
        if on.is_empty() {
            continue;
        }
        let name = if side == Favours::A { "A" } else { "B" };
        let chosen = verdict.criterion_favours.is_some();
        lines.push(format!(
            "{} {name} is significantly better on the {}{}",
            if chosen { "but" } else { "yet" },
            on.join(" and the "),
            if chosen {
                ": the measures disagree"
            } else {
                ""
            }
        ));
    }
    lines
}

/// Whether two folder arguments name the same folder (the same path, or
/// the same folder once links and `..` are resolved).
fn same_folder(a: &std::path::Path, b: &std::path::Path) -> bool {
    a == b
        || matches!(
            (std::fs::canonicalize(a), std::fs::canonicalize(b)),
            (Ok(x), Ok(y)) if x == y
        )
}

/// The two design ids asked for (`None`: the folder's only design), or a
/// refusal: not two ids, none with one folder, a design against itself.
fn design_pair(
    args: &CompareArgs,
    dir_a: &std::path::Path,
    dir_b: &std::path::Path,
) -> Result<(Option<u32>, Option<u32>), UserError> {
    Ok(match (&args.designs, args.folders.len()) {
        (Some(d), _) if d.len() != 2 => {
            return Err(UserError(
                format!(
                    "--designs: two design ids A,B are needed, {} given",
                    d.len()
                ),
                2,
            ));
        }
        // One folder's design against itself (one folder, or the same folder
        // twice): every paired difference is 0.
        (Some(d), _) if d[0] == d[1] && same_folder(dir_a, dir_b) => {
            return Err(UserError(
                format!(
                    "--designs {},{}: a design compared with itself; name two different designs of {}",
                    d[0],
                    d[1],
                    dir_a.display()
                ),
                2,
            ));
        }
        (Some(d), _) => (Some(d[0]), Some(d[1])),
        (None, 1) => {
            return Err(UserError(
                "one folder: say which two of its designs to compare with --designs A,B".into(),
                2,
            ));
        }
        (None, _) => (None, None),
    })
}
