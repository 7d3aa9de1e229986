//! `study report` (issue 34): one self-contained HTML page of a finished
//! study. The browser check itself is `scripts/check-report.sh` (CI runs it
//! where Chromium is installed); here the page's contents are checked.

use std::path::Path;
use std::process::Command;

fn study(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

#[test]
fn the_report_holds_question_ranking_verdicts_figures_curves_and_provenance_and_fetches_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let text = "# Does a fourth ball help?\n# (a test study)\n".to_string()
        + &crate::bad_input::study(Path::new("results")).replace("n = 3\n", "n = [3, 4]\n");
    std::fs::write(dir.join("s.toml"), text).unwrap();
    assert!(study(dir, &["run", "s.toml", "--quiet"]).status.success());
    let made = study(dir, &["report", "results/corpus", "--out", "r.html"]);
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    let page = std::fs::read_to_string(dir.join("r.html")).unwrap();
    assert!(page.contains("Does a fourth ball help? (a test study)"));
    assert!(page.contains("<table id=\"ranking-table\">"));
    assert_eq!(
        page.matches("<tr>").count(),
        1 + 2,
        "header and two designs"
    );
    assert!(page.contains("verdict"), "no verdict");
    // The study figures and the Kaplan–Meier curves of both designs.
    assert!(page.matches("<svg").count() >= 4, "too few figures");
    assert!(page.contains("Kaplan–Meier curves of the 2 leading designs"));
    assert!(page.contains("#1 (design ") && page.contains("#2 (design "));
    for what in [
        "git commit",
        "study file SHA-256",
        "seed",
        "study run results/corpus/study.toml",
    ] {
        assert!(page.contains(what), "provenance lacks {what}");
    }
    assert!(page.contains("<dd><code>5</code></dd>"), "the seed");
    assert_eq!(layout_problems(&page), Vec::<String>::new());
    // Self-contained: nothing is fetched.
    for external in [
        "<script",
        "<link",
        " src=",
        "href=\"http",
        "url(http",
        "@import",
    ] {
        assert!(!page.contains(external), "the page has {external}");
    }
    // The output policy: an existing report needs --overwrite.
    let again = study(dir, &["report", "results/corpus", "--out", "r.html"]);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("--overwrite"));
    let not_a_study = study(dir, &["report", ".", "--out", "x.html"]);
    assert_eq!(not_a_study.status.code(), Some(2));
    assert!(!dir.join("x.html").exists());
}

/// A finished study of the bad-input corpus in `dir` (name "corpus"),
/// with `edit` applied to its text and `extra` given to `study run`.
fn finished(dir: &Path, edit: &dyn Fn(String) -> String, extra: &[&str]) {
    let text = edit(crate::bad_input::study(Path::new("results")));
    std::fs::write(dir.join("s.toml"), text).unwrap();
    let mut args = vec!["run", "s.toml", "--quiet"];
    args.extend(extra);
    let run = study(dir, &args);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// `study report` of `folder` into `out`: (exit code, stderr, the page if written).
fn report(dir: &Path, folder: &str, out: &str) -> (Option<i32>, String, Option<String>) {
    let made = study(dir, &["report", folder, "--out", out]);
    (
        made.status.code(),
        String::from_utf8_lossy(&made.stderr).to_string(),
        std::fs::read_to_string(dir.join(out)).ok(),
    )
}

#[test]
fn a_damaged_folder_is_refused_naming_the_file_and_what_is_missing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    finished(dir, &|t| t, &[]);
    let folder = dir.join("results/corpus");
    let summary_path = folder.join("summary.parquet");
    let summary = autobal::study::results::io::read_parquet(&summary_path).unwrap();
    let stored = std::fs::read_to_string(folder.join("study.toml")).unwrap();
    // A column every summary has, and one only the ranking reads.
    for column in ["rank_by", "vs_best_verdict"] {
        let mut damaged = summary.drop(column).unwrap();
        autobal::study::results::io::write_parquet(
            &summary_path,
            &mut damaged,
            &autobal::study::results::io::Provenance::new(&stored, 5, "all"),
        )
        .unwrap();
        let (code, err, page) = report(dir, "results/corpus", "r.html");
        assert_eq!(code, Some(2), "{err}");
        assert!(
            err.contains("results/corpus/summary.parquet")
                && err.contains(&format!("\"{column}\"")),
            "{err}"
        );
        assert!(page.is_none());
    }
    // A summary in place of the runs: both named, with what the file is.
    std::fs::copy(folder.join("runs.parquet"), dir.join("runs.keep")).unwrap();
    let mut summary = summary;
    autobal::study::results::io::write_parquet(
        &summary_path,
        &mut summary,
        &autobal::study::results::io::Provenance::new(&stored, 5, "all"),
    )
    .unwrap();
    std::fs::copy(&summary_path, folder.join("runs.parquet")).unwrap();
    let (code, err, page) = report(dir, "results/corpus", "r.html");
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("results/corpus/runs.parquet")
            && err.contains("\"outcome\"")
            && err.contains("summary.parquet"),
        "{err}"
    );
    assert!(page.is_none());
    // No runs at all.
    std::fs::remove_file(folder.join("runs.parquet")).unwrap();
    let (code, err, _) = report(dir, "results/corpus", "r.html");
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("results/corpus/runs.parquet"), "{err}");
}

#[test]
fn another_studys_summary_beside_these_runs_is_refused_naming_both_files() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    finished(dir, &|t| t, &[]);
    let other = tempfile::tempdir().unwrap();
    finished(other.path(), &|t| t.replace("seed = 5", "seed = 6"), &[]);
    std::fs::copy(
        other.path().join("results/corpus/summary.parquet"),
        dir.join("results/corpus/summary.parquet"),
    )
    .unwrap();
    let (code, err, page) = report(dir, "results/corpus", "r.html");
    assert_eq!(code, Some(2), "{err}");
    for needle in [
        "results/corpus/summary.parquet",
        "results/corpus/runs.parquet",
        "hashes differ",
    ] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    assert!(page.is_none());
}

#[test]
fn a_study_where_nothing_settled_is_reported_with_a_sentence_for_each_figure_it_cannot_give() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // The hold window (50 rev) fills the run but for 2 rev: nothing settles.
    finished(
        dir,
        &|t| t.replace("t_end_revs = 100", "t_end_revs = 52"),
        &[],
    );
    let summary =
        autobal::study::results::io::read_parquet(&dir.join("results/corpus/summary.parquet"))
            .unwrap();
    let settled: u64 = summary
        .column("settled")
        .unwrap()
        .u64()
        .unwrap()
        .iter()
        .flatten()
        .sum();
    assert_eq!(settled, 0, "a run settled");
    let (code, err, page) = report(dir, "results/corpus", "r.html");
    assert_eq!(code, Some(0), "{err}");
    let page = page.unwrap();
    assert!(page.contains("<table id=\"ranking-table\">"));
    assert!(page.contains("<section id=\"verdicts\">"));
    assert!(
        page.contains("settling time: not drawn, because there is nothing to plot"),
        "no sentence in place of the figure"
    );
}

#[test]
fn a_bom_keeps_the_question_and_the_reproducing_command_keeps_the_ranking() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    finished(
        dir,
        &|t| format!("\u{feff}# Which drag settles soonest?\n{t}"),
        &["--rank-by", "median"],
    );
    let (code, err, page) = report(dir, "results/corpus", "r.html");
    assert_eq!(code, Some(0), "{err}");
    let page = page.unwrap();
    assert!(
        page.contains("<p>Which drag settles soonest?</p>"),
        "the question is lost"
    );
    assert!(
        page.contains("study run results/corpus/study.toml --overwrite --rank-by median"),
        "the command reproduces another ranking"
    );
}

/// What would make the page spill out of its column at 1 280 px, read from
/// the HTML (the browser check, scripts/check-report.sh, measures it where
/// Chromium is installed): a table outside a scrolling box, a caption or
/// paragraph showing Markdown backticks, figures or preformatted text
/// without a rule that keeps them inside the column.
fn layout_problems(page: &str) -> Vec<String> {
    let mut problems = Vec::new();
    let style = page
        .split_once("<style>")
        .and_then(|(_, rest)| rest.split_once("</style>"))
        .map_or("", |(style, _)| style);
    // The rule whose selector list names `selector`, compacted.
    let rule = |selector: &str| -> Option<String> {
        style.lines().find_map(|line| {
            let (selectors, body) = line.split_once('{')?;
            selectors
                .split(',')
                .any(|s| s.trim() == selector)
                .then(|| body.replace(' ', ""))
        })
    };
    for (selector, needs) in [
        (".scroll", "overflow-x:auto"),
        ("figure svg", "max-width:100%"),
        ("img", "max-width:100%"),
        ("pre", "overflow-x:auto"),
    ] {
        if !rule(selector).is_some_and(|r| r.contains(needs)) {
            problems.push(format!("no rule `{selector} {{ {needs} }}`"));
        }
    }
    let mut at = 0;
    while let Some(found) = page[at..].find("<table") {
        let start = at + found;
        if !page[..start].ends_with("<div class=\"scroll\">") {
            problems.push(format!("a table outside a scrolling box at byte {start}"));
        }
        at = start + 1;
    }
    for tag in ["figcaption", "p", "td", "th", "dd"] {
        let close = format!("</{tag}>");
        for open in [format!("<{tag}>"), format!("<{tag} ")] {
            for piece in page.split(open.as_str()).skip(1) {
                let text = piece.split(close.as_str()).next().unwrap_or("");
                if text.contains('`') {
                    problems.push(format!("a literal backtick in <{tag}>{text}"));
                }
            }
        }
    }
    problems
}

#[test]
fn the_layout_check_finds_a_page_that_spills() {
    let bad = "<style>\nfigure svg { display: block; }\n</style><table></table><figure><svg></svg><figcaption>as `study plot` draws it</figcaption></figure>";
    let problems = layout_problems(bad);
    for expected in [
        "no rule `.scroll",
        "no rule `figure svg",
        "no rule `img",
        "no rule `pre",
        "a table outside a scrolling box",
        "a literal backtick in <figcaption",
    ] {
        assert!(
            problems.iter().any(|p| p.starts_with(expected)),
            "missed {expected:?} in {problems:?}"
        );
    }
    let page = autobal::report::Report {
        title: "t".into(),
        header: vec!["a".into()],
        rows: vec![vec!["+12.4 [+7.6, +17.2]".into()]],
        legend: vec!["see `study tradeoff`".into()],
        figures: vec![autobal::report::Figure {
            caption: "settling time (as `study plot study` draws it).".into(),
            svg: "<svg></svg>".into(),
        }],
        ..Default::default()
    }
    .html();
    assert_eq!(layout_problems(&page), Vec::<String>::new(), "{page}");
}
