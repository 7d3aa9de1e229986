//! The user documentation (README, docs, and the shipped study, scene and
//! rig files) speaks to users: it cites no internal issue or pull-request
//! numbers (a reader cannot open them), dates nothing by working sessions,
//! and promises nothing that has already shipped.

use std::path::{Path, PathBuf};

/// Developer documents, which may cite the project's issues; every other
/// Markdown file of the README and docs/ is read by users.
const DEVELOPER_DOCS: [&str; 3] = [
    "CHANGELOG.md",
    "docs/architecture.md",
    "docs/rigid-contact-plan.md",
];

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// README.md, docs/*.md but the developer documents, and the shipped
/// studies/, scenes/ and rigs/ files, as paths relative to the repository.
fn user_docs() -> Vec<String> {
    let mut docs = vec!["README.md".to_string()];
    for entry in std::fs::read_dir(repo().join("docs")).expect("docs/") {
        let name = entry.expect("docs/ entry").file_name();
        let name = name.to_string_lossy();
        if name.ends_with(".md") {
            docs.push(format!("docs/{name}"));
        }
    }
    // The shipped study, scene and rig files are read by users too: their
    // headers explain them.
    for folder in ["studies", "scenes", "rigs"] {
        for entry in std::fs::read_dir(repo().join(folder)).expect(folder) {
            let name = entry.expect("entry").file_name();
            let name = name.to_string_lossy();
            if name.ends_with(".toml") {
                docs.push(format!("{folder}/{name}"));
            }
        }
    }
    docs.retain(|d| !DEVELOPER_DOCS.contains(&d.as_str()));
    docs.sort();
    docs
}

/// Where `line` dates something by how the project was worked on ("this
/// session", "an earlier session") rather than by a date a reader can use.
fn working_history(line: &str) -> Option<String> {
    let text = line.to_lowercase();
    text.split(|c: char| !c.is_alphanumeric())
        .any(|w| w == "session" || w == "sessions")
        .then(|| line.to_string())
}

/// Where `line` cites an issue: "issue 32", "Issue #32", "issues 4 and 5",
/// "(#32)", "PR 7", or "the issue's" (a reference to an unnamed one).
fn issue_reference(line: &str) -> Option<String> {
    let text = line.to_lowercase();
    for word in ["issues", "issue", "pr", "pull request"] {
        let mut from = 0;
        while let Some(at) = text[from..].find(word) {
            let start = from + at;
            let end = start + word.len();
            from = end;
            let before_ok = text[..start]
                .chars()
                .next_back()
                .is_none_or(|c| !c.is_alphanumeric());
            let rest = text[end..].trim_start_matches([' ', '#']);
            if before_ok
                && text[end..].starts_with([' ', '#'])
                && rest.starts_with(|c: char| c.is_ascii_digit())
            {
                return Some(line.to_string());
            }
        }
    }
    // " (#32)": a number alone in parentheses after a space, as GitHub
    // cites a pull request; "#1" is the ranking's first design, which the
    // docs name throughout ("t_s(#1)", "(#1 by the restricted mean …)").
    let mut from = 0;
    while let Some(at) = text[from..].find("(#") {
        let start = from + at;
        from = start + 2;
        let digits = text[from..]
            .chars()
            .take_while(char::is_ascii_digit)
            .count();
        let spaced = text[..start]
            .chars()
            .next_back()
            .is_none_or(char::is_whitespace);
        if spaced && digits > 0 && text[from + digits..].starts_with(')') {
            return Some(line.to_string());
        }
    }
    for phrase in ["the issue's", "the issue was", "the issue names"] {
        if text.contains(phrase) {
            return Some(line.to_string());
        }
    }
    None
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn user_docs_cite_no_internal_issue_numbers_nor_sessions() {
    let docs = user_docs();
    assert!(
        docs.len() >= 10,
        "expected the README and docs/*.md, found {docs:?}"
    );
    let mut found = Vec::new();
    for doc in &docs {
        for (k, line) in read(&repo().join(doc)).lines().enumerate() {
            if let Some(hit) = issue_reference(line).or_else(|| working_history(line)) {
                found.push(format!("{doc}:{}: {hit}", k + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "user docs cite internal issues or date things by working sessions (say what changed or since when instead; developer docs are listed in DEVELOPER_DOCS):\n{}",
        found.join("\n")
    );
}

#[test]
fn the_issue_check_sees_the_forms_it_forbids() {
    for line in [
        "Still to come (issue 32): a design per plane",
        "as Issue #45 asked",
        "fixed in PR 7",
        "fixed (#12)",
        "3.35× the issue's starting point",
    ] {
        assert!(issue_reference(line).is_some(), "missed: {line}");
    }
    for line in ["measured this session", "# Sessions 3-4 found"] {
        assert!(working_history(line).is_some(), "missed: {line}");
    }
    assert_eq!(working_history("an ODE solver's possession"), None);
    for line in [
        "the test against #1 (at 80 columns)",
        "#1 (design 2) is better than 17",
        "t_s(this) − t_s(#1), design 0 (#1 by the median)",
        "a tissue 3 mm thick",
        "Every issue the check finds is named",
    ] {
        assert_eq!(issue_reference(line), None, "false alarm: {line}");
    }
}

#[test]
fn the_study_file_promises_nothing_that_has_shipped() {
    let text = read(&repo().join("docs/study-file.md"));
    assert!(
        text.contains("[[designs.per_plane]]"),
        "docs/study-file.md documents a design per plane"
    );
    assert!(
        !text.contains("Still to come"),
        "docs/study-file.md still announces work as to come"
    );
}
