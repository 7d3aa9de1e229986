//! Parquet files with provenance, written atomically (temporary file + rename)
//! so that an interrupted run never leaves a half-written file behind.

use polars::prelude::*;
use sha2::{Digest, Sha256};
use std::fs::File;
use std::path::{Path, PathBuf};

/// Provenance stored in every Parquet file's key-value metadata. The study
/// text itself is stored once per folder (`study.toml` beside the files),
/// not in every file and chunk: a long study file would otherwise be copied
/// into each of them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Provenance {
    /// autobal's version.
    pub version: String,
    /// Git commit autobal was built from ("+dirty" with uncommitted
    /// changes, "unknown" outside a git checkout): [`crate::build_info`].
    pub git_commit: String,
    /// SHA-256 of the study text as the folder's `study.toml` holds it
    /// ([`study_sha256`]): `sha256sum study.toml` there gives this value.
    pub study_sha256: String,
    /// The master seed.
    pub seed: u64,
    /// Which part of the study the file holds ("all" or "k/N").
    pub shard: String,
}

impl Provenance {
    /// Provenance for a study text, seed and shard label.
    pub fn new(study_text: &str, seed: u64, shard: &str) -> Self {
        Provenance {
            version: env!("CARGO_PKG_VERSION").to_string(),
            git_commit: crate::build_info::commit_label(),
            study_sha256: study_sha256(study_text),
            seed,
            shard: shard.to_string(),
        }
    }

    /// The key-value pairs stored in a Parquet file's metadata.
    pub(crate) fn pairs(&self) -> Vec<(String, String)> {
        vec![
            ("autobal_version".into(), self.version.clone()),
            ("git_commit".into(), self.git_commit.clone()),
            ("build".into(), crate::build_info::VERSION_LINE.into()),
            ("study_sha256".into(), self.study_sha256.clone()),
            ("seed".into(), self.seed.to_string()),
            ("shard".into(), self.shard.clone()),
        ]
    }
}

/// Hex SHA-256 of a text.
pub fn sha256_hex(text: &str) -> String {
    Sha256::digest(text.as_bytes())
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Temporary sibling path used while writing `path`.
pub(crate) fn temp_path(path: &Path) -> PathBuf {
    let mut name = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(format!(".tmp-{}", std::process::id()));
    path.with_file_name(name)
}

/// What a file that is not Parquet (truncated, overwritten, another format)
/// is called in messages.
const NOT_PARQUET: &str = "not a readable Parquet file";

/// What a Parquet file of the wrong kind, or missing a column, is called in
/// messages (`crate::study::results::results_table` says which).
pub(crate) const WRONG_TABLE: &str = "is not the results table needed";

/// Whether `e` (from [`about`], or `crate::study::results::results_table`) says a file is
/// not readable Parquet or not the table needed: the user's file is damaged
/// or the wrong one, an input error rather than a fault of the tool.
pub fn is_not_parquet(e: &PolarsError) -> bool {
    matches!(e, PolarsError::ComputeError(m) if m.contains(NOT_PARQUET) || m.contains(WRONG_TABLE))
}

/// `e` (met while reading or writing `path`) with the path in front of its
/// message: polars and the OS name neither the file nor the folder.
pub fn about(path: &Path, e: PolarsError) -> PolarsError {
    let text = e.to_string();
    let damaged = text.contains("out of specification") || text.contains("magic");
    let text = if damaged {
        format!("{NOT_PARQUET} ({text})")
    } else {
        text
    };
    let message = format!("{}: {text}", path.display());
    match e {
        PolarsError::IO { error, .. } if !damaged => PolarsError::IO {
            error,
            msg: Some(message.into()),
        },
        _ => PolarsError::ComputeError(message.into()),
    }
}

/// `e`, met while writing `path`, as the write failure it is, naming
/// `path`: a write cut short reads in polars' words like a damaged file
/// ("out of specification", "Invalid thrift"), which would blame the
/// user's input. When the file system has no room left, says that. Call it
/// before the partial temporary file is removed, which frees its room.
pub fn about_writing(path: &Path, e: PolarsError) -> PolarsError {
    let full = no_room_left(path);
    let cause = if full {
        "no space left on device".to_string()
    } else {
        e.to_string()
    };
    let kind = if full {
        std::io::ErrorKind::StorageFull
    } else {
        std::io::ErrorKind::Other
    };
    PolarsError::IO {
        error: std::sync::Arc::new(std::io::Error::new(kind, cause.clone())),
        msg: Some(format!("{}: could not be written: {cause}", path.display()).into()),
    }
}

/// Whether the file system holding `path` has less than a mebibyte left
/// for this process (statvfs: no crate offers it for a path).
fn no_room_left(path: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let Ok(name) = std::ffi::CString::new(folder.as_os_str().as_bytes()) else {
        return false;
    };
    // SAFETY: `name` is a NUL-terminated path and `stats` a plain struct
    // statvfs fills; both outlive the call.
    let mut stats: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(name.as_ptr(), &mut stats) } != 0 {
        return false;
    }
    u128::from(stats.f_bavail) * u128::from(stats.f_frsize) < 1 << 20
}

/// Write `df` to `path` atomically, with provenance in the key-value metadata.
pub fn write_parquet(path: &Path, df: &mut DataFrame, provenance: &Provenance) -> PolarsResult<()> {
    let tmp = temp_path(path);
    let written = File::create(&tmp)
        .map_err(PolarsError::from)
        .and_then(|file| {
            ParquetWriter::new(file)
                .with_key_value_metadata(Some(KeyValueMetadata::from_static(provenance.pairs())))
                .finish(df)
        })
        .and_then(|_| move_into_place(&tmp, path).map_err(PolarsError::from))
        .map_err(|e| about_writing(path, e));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written.map(|_| ())
}

/// A study's chunk of finished runs, atomically, as an Arrow IPC file:
/// chunks are read once, into `runs.parquet`, and deleted, so they need no
/// Parquet encoding — which, in the dev profile's unoptimised polars, took
/// 90 ms per 4 096 runs on the receiving thread while the runs go on,
/// against 7 ms for IPC. The study's provenance is in `plan.sha256`.
pub fn write_chunk(path: &Path, df: &mut DataFrame) -> PolarsResult<()> {
    let tmp = temp_path(path);
    let written = File::create(&tmp)
        .map_err(PolarsError::from)
        .and_then(|file| IpcWriter::new(file).finish(df))
        .and_then(|_| move_into_place(&tmp, path).map_err(PolarsError::from))
        .map_err(|e| about_writing(path, e));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// Read a Parquet file written by [`write_parquet`].
pub fn read_parquet(path: &Path) -> PolarsResult<DataFrame> {
    File::open(path)
        .map_err(PolarsError::from)
        .and_then(|file| ParquetReader::new(file).finish())
        .map_err(|e| about(path, e))
}

/// Read the key-value metadata of a Parquet file as (key, value) pairs.
pub fn read_metadata(path: &Path) -> PolarsResult<Vec<(String, String)>> {
    let mut reader = ParquetReader::new(File::open(path).map_err(|e| about(path, e.into()))?);
    let meta = reader.get_metadata().map_err(|e| about(path, e))?;
    Ok(meta
        .key_value_metadata()
        .as_ref()
        .map(|kv| {
            kv.iter()
                .map(|p| (p.key.clone(), p.value.clone().unwrap_or_default()))
                .collect()
        })
        .unwrap_or_default())
}

/// The study text as a results folder keeps it (`study.toml`): without a
/// first line `#:schema …`, whose path is relative to the study file's own
/// folder and resolves nowhere from the results folder (editors and taplo
/// would flag the copy).
pub fn folder_copy(study_text: &str) -> String {
    match study_text.split_once('\n') {
        Some((first, rest)) if first.trim_start().starts_with("#:schema") => rest.to_string(),
        None if study_text.trim_start().starts_with("#:schema") => String::new(),
        _ => study_text.to_string(),
    }
}

/// SHA-256 of a study text as its results folder keeps it ([`folder_copy`]),
/// so that the recorded hash is that of the stored `study.toml`, byte for byte.
pub fn study_sha256(study_text: &str) -> String {
    sha256_hex(&folder_copy(study_text))
}

/// Whether `recorded` is the hash of `study_text`: as [`study_sha256`] gives
/// it, or of the whole file (its `#:schema` line included), as it was
/// recorded before the two were made to agree: older baselines stay valid.
pub fn same_study(recorded: &str, study_text: &str) -> bool {
    recorded == study_sha256(study_text) || recorded == sha256_hex(study_text)
}

/// Why the table at `path` does not hold runs of `study_text` with `seed`
/// (and, when given, of shard `shard`), from the provenance it recorded
/// when written; None when it does. A table copied in from another
/// study, seed or shard must not be continued, merged or compared as if
/// it were this one's.
pub fn foreign_table(
    path: &Path,
    study_text: &str,
    seed: u64,
    shard: Option<&str>,
) -> PolarsResult<Option<String>> {
    let recorded = read_metadata(path)?;
    let get = |key: &str| {
        recorded
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    };
    let short = |hash: &str| hash.chars().take(12).collect::<String>();
    Ok(match (get("study_sha256"), get("seed"), get("shard")) {
        (None, ..) | (_, None, _) => {
            Some("it records no study and seed: autobal's study runs did not write it".into())
        }
        (Some(hash), ..) if !same_study(hash, study_text) => Some(format!(
            "it was written by another study file (sha256 {}…, not {}… of the study.toml beside it)",
            short(hash),
            short(&study_sha256(study_text))
        )),
        (_, Some(s), _) if s != seed.to_string() => Some(format!(
            "it was written with seed {s}, not the study's {seed}"
        )),
        (_, _, found) => match (shard, found) {
            (Some(want), Some(found)) if found != want => {
                Some(format!("it holds shard {found}, not {want}"))
            }
            _ => None,
        },
    })
}

/// Write a text file atomically.
pub fn write_text(path: &Path, text: &str) -> std::io::Result<()> {
    let tmp = temp_path(path);
    std::fs::write(&tmp, text)
        .and_then(|_| move_into_place(&tmp, path))
        .inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })
}

/// Rename a finished temporary file to `path`, removing it if that fails
/// (e.g. `path` is a folder), so that a refused write leaves nothing behind.
pub(crate) fn move_into_place(tmp: &Path, path: &Path) -> std::io::Result<()> {
    std::fs::rename(tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(tmp);
    })
}

/// A sampled time history as a DataFrame: t, x, y, r, eps, psi_0 … psi_{n−1}.
pub fn series_dataframe(series: &crate::metrics::observer::Series) -> PolarsResult<DataFrame> {
    let mut columns = vec![
        Column::new("t".into(), series.t.clone()),
        Column::new("x".into(), series.x.clone()),
        Column::new("y".into(), series.y.clone()),
        Column::new("r".into(), series.r.clone()),
        Column::new("eps".into(), series.eps.clone()),
    ];
    for (j, psi) in series.psi.iter().enumerate() {
        columns.push(Column::new(format!("psi_{j}").into(), psi.clone()));
    }
    for (b, (x, y)) in series.bearing_x.iter().zip(&series.bearing_y).enumerate() {
        columns.push(Column::new(format!("bearing_{b}_x").into(), x.clone()));
        columns.push(Column::new(format!("bearing_{b}_y").into(), y.clone()));
    }
    DataFrame::new(series.t.len(), columns)
}

/// Write a time history atomically: Parquet for `.parquet`, CSV otherwise.
pub fn write_series(
    path: &Path,
    series: &crate::metrics::observer::Series,
    provenance: &Provenance,
) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    let mut df = series_dataframe(series)?;
    if path.extension().is_some_and(|e| e == "parquet") {
        write_parquet(path, &mut df, provenance)?;
        return Ok(());
    }
    let tmp = temp_path(path);
    let written = write_series_csv(&tmp, &df).and_then(|_| Ok(move_into_place(&tmp, path)?));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written.map_err(|e| format!("{}: {e}", path.display()).into())
}

/// The series' columns as CSV in `tmp`.
fn write_series_csv(
    tmp: &Path,
    df: &DataFrame,
) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    {
        let mut w = csv::Writer::from_path(tmp)?;
        let names: Vec<String> = df
            .get_column_names()
            .iter()
            .map(|c| c.to_string())
            .collect();
        w.write_record(&names)?;
        let cols: Vec<Vec<f64>> = df
            .columns()
            .iter()
            .map(|c| c.f64().map(|ca| ca.no_null_iter().collect()))
            .collect::<PolarsResult<_>>()?;
        for i in 0..df.height() {
            w.write_record(cols.iter().map(|c| c[i].to_string()))?;
        }
        w.flush()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each field of the recorded provenance is checked: the study's hash,
    /// its seed, the shard, and a table that records none is foreign too.
    #[test]
    fn a_tables_recorded_study_seed_and_shard_must_all_match() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("runs.parquet");
        let mut df = df!("run_id" => [0u64, 1]).unwrap();
        let text = "name = \"s\"\nseed = 5\n";
        write_parquet(&path, &mut df, &Provenance::new(text, 5, "1/2")).unwrap();
        let check = |text: &str, seed: u64, shard: Option<&str>| {
            foreign_table(&path, text, seed, shard).unwrap()
        };
        assert_eq!(check(text, 5, Some("1/2")), None);
        assert_eq!(check(text, 5, None), None);
        assert!(
            check("name = \"t\"\n", 5, None)
                .unwrap()
                .contains("another study file")
        );
        assert!(
            check(text, 6, None)
                .unwrap()
                .contains("seed 5, not the study's 6")
        );
        assert!(
            check(text, 5, Some("all"))
                .unwrap()
                .contains("shard 1/2, not all")
        );
        let bare = dir.path().join("bare.parquet");
        let mut file = File::create(&bare).unwrap();
        ParquetWriter::new(&mut file).finish(&mut df).unwrap();
        assert!(
            foreign_table(&bare, text, 5, None)
                .unwrap()
                .unwrap()
                .contains("records no study")
        );
    }
}
