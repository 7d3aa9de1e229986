//! The runs table on disk. `runs.parquet` is assembled from pieces (a run's
//! chunks, a resumed folder's earlier table, the shards of a merge), each
//! sorted by run id, one window of run ids at a time: memory holds an index
//! of run ids (8 bytes a run) and one window of rows, whatever the number of
//! runs. The window boundaries lie in run-id space, so the same runs give the
//! same file however they were split into pieces (threads, resumes, shards).

use crate::study::results::io::{Provenance, about, about_writing, temp_path};
use polars::prelude::*;
use std::fs::File;
use std::path::{Path, PathBuf};

/// Run ids per row group of `runs.parquet`: a few tens of megabytes of rows
/// in memory while writing, few enough row groups to read fast.
pub const WINDOW_RUNS: u64 = 32_768;

/// Columns the per-design summary reads (a slim projection of the runs).
pub const SUMMARY_COLUMNS: [&str; 14] = [
    "design_id",
    "sample_id",
    "outcome",
    "settled",
    "settling_revs",
    "censoring_revs",
    "residual_rel",
    "residual_abs",
    "a_ref",
    "unbalance_fraction",
    "contact",
    "min_gap_rad",
    "operating_time_s",
    "final_spin_rate",
];

/// One file of runs, with its run ids (ascending): Parquet (a finished
/// table, a shard) or Arrow IPC (a study's chunk, `.arrow`).
#[derive(Debug)]
pub struct Piece {
    path: PathBuf,
    ids: Vec<u64>,
}

/// Whether `path` is an Arrow IPC file (a chunk) rather than Parquet.
fn is_ipc(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "arrow")
}

/// The file's rows, all columns or the projection `columns`.
fn read_file(path: &Path, columns: Option<&[&str]>) -> PolarsResult<DataFrame> {
    let columns = columns.map(|c| c.iter().map(|c| c.to_string()).collect::<Vec<_>>());
    let read = || -> PolarsResult<DataFrame> {
        if is_ipc(path) {
            IpcReader::new(File::open(path)?)
                .with_columns(columns)
                .finish()
        } else {
            ParquetReader::new(File::open(path)?)
                .with_columns(columns)
                .finish()
        }
    };
    read().map_err(|e| about(path, e))
}

impl Piece {
    /// Index a file by reading its run ids only. A file whose rows are not in
    /// run order (written by an older build) is rewritten sorted first.
    pub fn open(path: &Path) -> PolarsResult<Piece> {
        let ids = read_ids(path)?;
        if ids.is_sorted() {
            return Ok(Piece {
                path: path.to_path_buf(),
                ids,
            });
        }
        let df = read_file(path, None)?;
        let mut sorted = df.sort(["run_id"], SortMultipleOptions::default())?;
        let tmp = temp_path(path);
        if is_ipc(path) {
            IpcWriter::new(File::create(&tmp)?).finish(&mut sorted)?;
        } else {
            ParquetWriter::new(File::create(&tmp)?).finish(&mut sorted)?;
        }
        std::fs::rename(&tmp, path)?;
        Ok(Piece {
            path: path.to_path_buf(),
            ids: read_ids(path)?,
        })
    }

    /// The run ids the file holds, ascending.
    pub fn ids(&self) -> &[u64] {
        &self.ids
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file's rows with run ids in `[from, to)`, if any.
    fn rows_between(&self, from: u64, to: u64) -> PolarsResult<Option<DataFrame>> {
        let lo = self.ids.partition_point(|&id| id < from);
        let hi = self.ids.partition_point(|&id| id < to);
        if hi == lo {
            return Ok(None);
        }
        if is_ipc(&self.path) {
            // A chunk holds a few thousand runs: read whole, then sliced.
            return Ok(Some(read_file(&self.path, None)?.slice(lo as i64, hi - lo)));
        }
        File::open(&self.path)
            .map_err(PolarsError::from)
            .and_then(|file| {
                ParquetReader::new(file)
                    .with_slice(Some((lo, hi - lo)))
                    .finish()
            })
            .map(Some)
            .map_err(|e| about(&self.path, e))
    }
}

fn read_ids(path: &Path) -> PolarsResult<Vec<u64>> {
    // A table of another kind is named with what it lacks, not "run_id".
    summary_projection(path)?;
    let df = read_file(path, Some(&["run_id"]))?;
    Ok(df.column("run_id")?.u64()?.into_no_null_iter().collect())
}

/// Write the runs of `pieces` to `out` (atomically) in run order, one row
/// group per [`WINDOW_RUNS`] run ids up to `total_ids`. A run id held by
/// several pieces is written once, from the first piece that holds it.
/// Returns the number of rows written.
pub fn write_runs(
    pieces: &[Piece],
    total_ids: u64,
    out: &Path,
    provenance: &Provenance,
) -> PolarsResult<u64> {
    let tmp = temp_path(out);
    // The pieces' read errors name their own files; the writer's name `out`.
    let result = write_windows(pieces, total_ids, (&tmp, out), provenance).and_then(|rows| {
        std::fs::rename(&tmp, out)
            .map(|_| rows)
            .map_err(|e| about_writing(out, e.into()))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn write_windows(
    pieces: &[Piece],
    total_ids: u64,
    (tmp, out): (&Path, &Path),
    provenance: &Provenance,
) -> PolarsResult<u64> {
    let writing = |e: PolarsError| about_writing(out, e);
    let mut writer: Option<polars::io::parquet::write::BatchedWriter<File>> = None;
    let mut rows = 0u64;
    let mut from = 0;
    while from < total_ids {
        let to = (from + WINDOW_RUNS).min(total_ids);
        let Some(window) = window_rows(pieces, from, to)? else {
            from = to;
            continue;
        };
        if writer.is_none() {
            writer = Some(
                ParquetWriter::new(File::create(tmp).map_err(|e| writing(e.into()))?)
                    .with_key_value_metadata(Some(KeyValueMetadata::from_static(
                        provenance.pairs(),
                    )))
                    .batched(window.schema())
                    .map_err(writing)?,
            );
        }
        if let Some(w) = writer.as_mut() {
            w.write_batch(&window).map_err(writing)?;
        }
        rows += window.height() as u64;
        from = to;
    }
    match writer {
        Some(w) => {
            w.finish().map_err(writing)?;
        }
        None => {
            return Err(PolarsError::NoData(
                format!("{}: no runs to write", out.display()).into(),
            ));
        }
    }
    Ok(rows)
}

/// Rows of every piece in `[from, to)`, in run order, each run once.
fn window_rows(pieces: &[Piece], from: u64, to: u64) -> PolarsResult<Option<DataFrame>> {
    let mut parts: Vec<DataFrame> = Vec::new();
    for piece in pieces {
        if let Some(df) = piece.rows_between(from, to)? {
            parts.push(df);
        }
    }
    let Some(mut all) = parts.first().cloned() else {
        return Ok(None);
    };
    for part in &parts[1..] {
        all.vstack_mut(part)?;
    }
    // A stable order by run id keeps the first piece's copy of a duplicate.
    let ids: Vec<u64> = all.column("run_id")?.u64()?.into_no_null_iter().collect();
    let mut order: Vec<usize> = (0..ids.len()).collect();
    order.sort_by_key(|&i| ids[i]);
    order.dedup_by_key(|i| ids[*i]);
    let take = IdxCa::from_vec(
        "".into(),
        order.iter().map(|&i| i as IdxSize).collect::<Vec<_>>(),
    );
    let mut window = all.take(&take)?;
    window.rechunk_mut();
    Ok(Some(window))
}

/// Per-plane columns the summary reads when a file has them (rotors with
/// several planes).
pub const PLANE_SUMMARY_COLUMNS: [&str; 3] =
    ["plane_settling_revs", "plane_residual_abs", "plane_a_ref"];

/// Columns the summary reads when a file has them: how contact was
/// modelled and the pack's slip rate (files written before the columns
/// have none), each run's peak whirl (the start-up whirl columns; every
/// file has it, but a table built without it still summarises, with those
/// columns empty), and rolling resistance's drawn keys, which set each
/// run's dead band.
pub const OPTIONAL_SUMMARY_COLUMNS: [&str; 5] = [
    "contact_model",
    "pack_slip_rate",
    "peak_r",
    "scene.effects.rolling_resistance.coefficient",
    "scene.effects.rolling_resistance.static_ratio",
];

/// The summary's projection of the file at `path`: [`SUMMARY_COLUMNS`], and
/// [`PLANE_SUMMARY_COLUMNS`] and [`OPTIONAL_SUMMARY_COLUMNS`] where the file
/// has them.
fn summary_projection(path: &Path) -> PolarsResult<Vec<&'static str>> {
    let read = || -> PolarsResult<_> {
        Ok(if is_ipc(path) {
            IpcReader::new(File::open(path)?).schema()?
        } else {
            ParquetReader::new(File::open(path)?).schema()?
        })
    };
    let schema = read().map_err(|e| about(path, e))?;
    let names: Vec<&str> = schema.iter_names().map(|n| n.as_str()).collect();
    crate::study::results::results_table::check_columns(
        path,
        crate::study::results::results_table::TableKind::Runs,
        names.iter().copied(),
    )?;
    let mut columns = SUMMARY_COLUMNS.to_vec();
    columns.extend(
        PLANE_SUMMARY_COLUMNS
            .iter()
            .chain(&OPTIONAL_SUMMARY_COLUMNS)
            .filter(|c| schema.contains(c)),
    );
    Ok(columns)
}

/// The slim projection of `runs.parquet` the summary needs (about 40 bytes a run).
pub fn read_summary_columns(path: &Path) -> PolarsResult<DataFrame> {
    read_file(path, Some(&summary_projection(path)?))
}

/// The slim projection of several pieces, stacked (for decisions taken
/// while a run is under way, before `runs.parquet` exists).
pub fn read_pieces_summary_columns(pieces: &[Piece]) -> PolarsResult<DataFrame> {
    let mut out: Option<DataFrame> = None;
    for piece in pieces {
        let df = read_file(piece.path(), Some(&summary_projection(piece.path())?))?;
        match out.as_mut() {
            Some(all) => {
                all.vstack_mut(&df)?;
            }
            None => out = Some(df),
        }
    }
    out.ok_or_else(|| PolarsError::NoData("no runs yet".into()))
}
