//! `study --version`, `study completions` and `study man`.

use std::process::Command;

fn study(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn version_names_the_commit_and_the_tree_state() {
    let out = study(&["--version"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(
        text.trim(),
        format!("study {}", autobal::build_info::VERSION_LINE)
    );
    assert!(text.starts_with(&format!("study {} (commit ", env!("CARGO_PKG_VERSION"))));
    let tree = autobal::build_info::GIT_TREE;
    assert!(["clean", "dirty", "unknown"].contains(&tree), "{tree}");
    let commit = autobal::build_info::GIT_COMMIT;
    // The build script asks git: in this checkout it knows the commit.
    assert!(
        commit == "unknown"
            || (commit.len() == 40 && commit.chars().all(|c| c.is_ascii_hexdigit())),
        "{commit}"
    );
}

#[test]
fn completions_cover_every_shell_and_every_verb() {
    for shell in ["bash", "zsh", "fish", "powershell", "elvish"] {
        let out = study(&["completions", shell]);
        assert!(out.status.success(), "{shell}");
        let script = String::from_utf8(out.stdout).unwrap();
        for verb in ["run", "compare", "check", "completions", "man"] {
            assert!(script.contains(verb), "{shell}: no {verb}");
        }
    }
    let out = study(&["completions", "tcsh"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("tcsh"));
}

#[test]
fn the_man_page_is_roff_with_the_version_and_the_verbs() {
    let out = study(&["man"]);
    assert!(out.status.success());
    let page = String::from_utf8(out.stdout).unwrap();
    assert!(
        page.contains(".TH study 1"),
        "{}",
        &page[..200.min(page.len())]
    );
    assert!(page.contains(autobal::build_info::GIT_COMMIT));
    for verb in [
        "run",
        "merge",
        "compare",
        "check",
        "completions",
        "report",
        "plot run",
    ] {
        assert!(
            page.contains(&format!(".SS \"study {verb}\"")),
            "no section for {verb}"
        );
    }
    // One page: no reference to pages it cannot produce (study-run(1), …).
    assert!(
        !page.contains("\\-run(1)") && !page.contains("-run(1)"),
        "dangling page reference"
    );
    // Plain roff: groff renders it without a UTF-8 preprocessor.
    assert!(page.is_ascii(), "non-ASCII characters in the roff");
    assert!(page.contains("\\[u03C1]"), "ρ as a groff escape");
    // The footer: short fields, the full version line in its own section.
    let th = page.lines().find(|l| l.starts_with(".TH")).unwrap();
    assert!(!th.contains("commit") && th.contains("autobal 0."), "{th}");
    assert!(page.contains(".SH VERSION"));
}

/// The page's sections by their `.SH` heading, in order.
fn sections(page: &str) -> Vec<(String, String)> {
    page.split("\n.SH ")
        .skip(1)
        .map(|s| {
            let (head, body) = s.split_once('\n').unwrap_or((s, ""));
            (head.trim_matches('"').to_string(), body.to_string())
        })
        .collect()
}

#[test]
fn the_man_page_is_short_with_examples_and_no_repeated_entries() {
    let out = study(&["man"]);
    assert!(out.status.success());
    let page = String::from_utf8(out.stdout).unwrap();
    let lines = page.lines().count();
    assert!(lines <= 800, "the man page has {lines} lines (at most 800)");
    let sections = sections(&page);
    let body = |name: &str| {
        sections
            .iter()
            .find(|(head, _)| head == name)
            .map(|(_, body)| body.clone())
            .unwrap_or_else(|| panic!("no {name} section"))
    };
    // Each verb once, and no "study help …" entries repeating them.
    let commands = body("COMMANDS");
    let mut entries: Vec<&str> = commands.lines().filter(|l| l.starts_with(".SS ")).collect();
    assert!(entries.len() >= 20, "{entries:?}");
    assert!(
        !entries.iter().any(|e| e.contains(" help")),
        "help entries: {entries:?}"
    );
    let count = entries.len();
    entries.sort();
    entries.dedup();
    assert_eq!(entries.len(), count, "a verb is described twice");
    // The help flag and --wide once, under the tool's own options.
    assert_eq!(page.matches("Print help").count(), 1, "-h repeated");
    assert_eq!(
        page.lines().filter(|l| *l == "\\fB\\-\\-wide\\fR").count(),
        1,
        "--wide repeated on every verb"
    );
    // Examples from the verbs' --help, under their verb.
    let examples = body("EXAMPLES");
    for (verb, example) in [
        ("study run", "study run studies/three_balls.toml"),
        (
            "study report",
            "study report results/three_balls \\-\\-out three_balls.html",
        ),
        ("study completions", "study completions bash"),
        ("study plot", "study plot run scenes/three_balls.toml"),
    ] {
        assert!(
            examples.contains(&format!(".SS \"{verb}\"")),
            "no examples of {verb}"
        );
        assert!(examples.contains(example), "no example {example:?}");
    }
}

#[test]
fn completions_offer_the_values_of_rank_by_and_no_file_names_for_designs() {
    for shell in ["bash", "zsh", "fish"] {
        let out = study(&["completions", shell]);
        assert!(out.status.success(), "{shell}");
        let script = String::from_utf8(out.stdout).unwrap();
        for criterion in [
            "median",
            "p90",
            "settled_fraction",
            "residual_p95",
            "settled_by:",
            "p_residual_below:",
        ] {
            // zsh escapes the colon of a stem.
            let written = if shell == "zsh" {
                criterion.replace(':', "\\:")
            } else {
                criterion.to_string()
            };
            assert!(script.contains(&written), "{shell}: no {criterion}");
        }
    }
    // bash: the value list follows --rank-by, and --designs completes to
    // what was typed rather than to file names.
    let bash = String::from_utf8(study(&["completions", "bash"]).stdout).unwrap();
    let after = |flag: &str| {
        let at = bash
            .find(&format!("{flag})"))
            .unwrap_or_else(|| panic!("no {flag} case"));
        bash[at..].lines().take(3).collect::<Vec<_>>().join("\n")
    };
    let rank_by = after("--rank-by");
    assert!(
        rank_by.contains("compgen -W") && rank_by.contains("mean median p90"),
        "{rank_by}"
    );
    let designs = after("--designs");
    assert!(!designs.contains("compgen -f"), "{designs}");
}
