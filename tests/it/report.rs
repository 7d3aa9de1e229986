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
