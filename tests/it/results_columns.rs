//! docs/results-files.md documents every column the shipped studies write,
//! and nothing they do not: each shipped study runs at one sample per design,
//! and the column names of its runs.parquet and summary.parquet (a plane's
//! index written `{p}`) must be exactly the names the doc's tables give for
//! that file.

use autobal::study::results::io::read_parquet;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A column name with a trailing plane index replaced by `{p}`.
fn pattern(name: &str) -> String {
    if name.starts_with("scene.") {
        // One column per uncertain key of the study.
        return "scene.{key}".to_string();
    }
    match name.rsplit_once("_plane") {
        Some((head, tail)) if !tail.is_empty() && tail.bytes().all(|b| b.is_ascii_digit()) => {
            format!("{head}_plane{{p}}")
        }
        _ => name.to_string(),
    }
}

/// The names in the first cell of each table row under `## {file}`.
fn documented(doc: &str, file: &str) -> BTreeSet<String> {
    let heading = format!("## {file}");
    let mut inside = false;
    let mut names = BTreeSet::new();
    for line in doc.lines() {
        if line.starts_with("## ") {
            inside = line.trim() == heading;
            continue;
        }
        if !inside {
            continue;
        }
        if let Some(cell) = line.strip_prefix("| `")
            && let Some(end) = cell.find('`')
        {
            names.insert(cell[..end].to_string());
        }
    }
    names
}

/// Every column name (as a pattern) of `file` over the shipped studies' outputs under `results`.
fn written(results: &Path, file: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for entry in std::fs::read_dir(results).unwrap() {
        let df = read_parquet(&entry.unwrap().path().join(file)).unwrap();
        for column in df.get_column_names() {
            names.insert(pattern(column.as_str()));
        }
    }
    names
}

#[test]
fn every_results_column_is_documented_and_every_documented_column_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let studies = tmp.path().join("studies");
    std::fs::create_dir(&studies).unwrap();
    let mut count = 0;
    for entry in std::fs::read_dir(repo().join("studies")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let text: String = std::fs::read_to_string(&path)
            .unwrap()
            .lines()
            .map(|line| {
                if line.trim_start().starts_with("samples =") {
                    "samples = 1".to_string()
                } else {
                    line.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        let copy = studies.join(path.file_name().unwrap());
        std::fs::write(&copy, text).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .current_dir(tmp.path())
            .arg("run")
            .arg(&copy)
            .arg("--quiet")
            .output()
            .unwrap();
        // A study whose runs fail exits 1 but still writes its files.
        assert!(
            matches!(out.status.code(), Some(0 | 1)),
            "{}: {}",
            path.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        count += 1;
    }
    assert!(count >= 13, "only {count} shipped studies");
    let doc = std::fs::read_to_string(repo().join("docs/results-files.md")).unwrap();
    let results = tmp.path().join("results");
    for file in ["runs.parquet", "summary.parquet"] {
        let written = written(&results, file);
        let documented = documented(&doc, file);
        let missing: Vec<_> = written.difference(&documented).collect();
        let stale: Vec<_> = documented.difference(&written).collect();
        assert!(
            missing.is_empty() && stale.is_empty(),
            "{file}: written but not documented in docs/results-files.md: {missing:?}; documented but written by no shipped study: {stale:?}"
        );
    }
}

#[test]
fn plane_indexes_become_a_pattern() {
    assert_eq!(
        pattern("residual_abs_p95_plane12"),
        "residual_abs_p95_plane{p}"
    );
    assert_eq!(pattern("plane_a_ref"), "plane_a_ref");
    assert_eq!(pattern("settled_plane"), "settled_plane");
}
