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
