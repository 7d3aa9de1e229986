//! Records which source autobal was built from — the git commit and whether
//! the tree had uncommitted changes — for `study --version` and the
//! provenance of every result folder. Asking git at run time instead would
//! report whatever the source tree holds then, not what the binary was built
//! from. A tree that is not a git checkout says "unknown".

use std::path::PathBuf;
use std::process::Command;

/// Trimmed standard output of a successful git command in the crate folder.
fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .arg("-C")
        .arg(env!("CARGO_MANIFEST_DIR"))
        .args(args)
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    // A build without git (e.g. in a container) can be told the commit.
    println!("cargo:rerun-if-env-changed=AUTOBAL_BUILD_COMMIT");
    let given = std::env::var("AUTOBAL_BUILD_COMMIT")
        .ok()
        .filter(|c| !c.is_empty() && c != "unknown");
    let commit = git(&["rev-parse", "HEAD"])
        .or(given)
        .unwrap_or_else(|| "unknown".into());
    let tree = match git(&["status", "--porcelain", "--untracked-files=no"]) {
        Some(changes) if changes.is_empty() => "clean",
        Some(_) => "dirty",
        None => "unknown",
    };
    println!("cargo:rustc-env=AUTOBAL_GIT_COMMIT={commit}");
    println!("cargo:rustc-env=AUTOBAL_GIT_TREE={tree}");
    // Run again when the sources change (they may make the tree dirty) or
    // when git moves HEAD or stages something; only paths that exist, as a
    // missing one would make cargo run this script on every build.
    let mut watched = vec!["src".to_string(), "Cargo.toml".into(), "build.rs".into()];
    if let Some(dir) = git(&["rev-parse", "--absolute-git-dir"]) {
        for name in ["HEAD", "index", "logs/HEAD"] {
            watched.push(PathBuf::from(&dir).join(name).display().to_string());
        }
    }
    for path in watched {
        if std::path::Path::new(&path).exists()
            || PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join(&path)
                .exists()
        {
            println!("cargo:rerun-if-changed={path}");
        }
    }
}
