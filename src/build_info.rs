//! Which source this build of autobal came from (recorded by `build.rs`):
//! shown by `study --version` and stored in every result's provenance.

/// Git commit of the source tree at build time, or "unknown".
pub const GIT_COMMIT: &str = env!("AUTOBAL_GIT_COMMIT");

/// "clean", "dirty" (uncommitted changes to tracked files) or "unknown".
pub const GIT_TREE: &str = env!("AUTOBAL_GIT_TREE");

/// The commit as stored in provenance: the hash, with "+dirty" when the
/// tree had uncommitted changes (a dirty build is not the commit's code).
pub fn commit_label() -> String {
    if GIT_TREE == "dirty" {
        format!("{GIT_COMMIT}+dirty")
    } else {
        GIT_COMMIT.to_string()
    }
}

/// One line: version, commit and tree state, e.g.
/// "0.1.0 (commit 8b82cfa…, clean tree)".
pub const VERSION_LINE: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("AUTOBAL_GIT_COMMIT"),
    ", ",
    env!("AUTOBAL_GIT_TREE"),
    " tree)"
);
