//! The chunked executor: runs in blocks over all cores, designs
//! interleaved, each block written as a chunk file, the table assembled
//! from the chunks in run order.

use super::*;

/// Run ids per block: blocks run one after the other (runs of a block in
/// parallel), so every chunk holds runs of one block and the final table is
/// assembled from a few chunks per window. Large enough that waiting for a
/// block's slowest run costs little.
const BLOCK_RUNS: usize = 8_192;

/// Run `pending` on the pool, writing chunks (each sorted by run id) as
/// results arrive; returns how many runs were saved.
pub(super) fn execute(
    plan: &StudyPlan,
    pending: &[u64],
    options: &RunOptions,
    pool: Option<&rayon::ThreadPool>,
    chunks: &Path,
    progress: &dyn Progress,
) -> Result<u64, RunError> {
    let cancelled = || {
        options
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    };
    let mut next_chunk = next_chunk_index(chunks)?;
    // Bounded, so that runs finishing faster than chunks are written wait
    // instead of piling up in memory.
    let (tx, rx) = mpsc::sync_channel::<RunRecord>(2 * options.chunk_runs.max(1));
    std::thread::scope(|scope| {
        scope.spawn(move || {
            let work = move || {
                for block in pending.chunks(BLOCK_RUNS) {
                    if cancelled() {
                        return;
                    }
                    let order = designs_interleaved(block, plan.file.sampling.samples);
                    // One run per job (and one item per job wherever items
                    // are simulations): rayon otherwise runs a quarter of the
                    // block as one sequential piece per thread, and the
                    // thread that finishes first waits for the other's rest
                    // (1 000 runs at 2 threads: 1.68× → 1.82×). A run costs
                    // far more than a job.
                    order
                        .par_iter()
                        .with_max_len(1)
                        .for_each_with(tx.clone(), |tx, &id| {
                            if cancelled() {
                                return;
                            }
                            // The receiver only disappears if writing failed; the error is reported there.
                            let _ = tx.send(run_one(plan, id));
                        });
                }
            };
            match pool {
                Some(p) => p.install(work),
                None => work(),
            }
        });
        let mut saved = 0u64;
        let mut buffer: Vec<RunRecord> = Vec::new();
        let mut last_flush = Instant::now();
        let mut flush = |buffer: &mut Vec<RunRecord>| -> Result<(), RunError> {
            if buffer.is_empty() {
                return Ok(());
            }
            buffer.sort_by_key(|r| r.run_id);
            let mut df = to_dataframe(buffer)?;
            crate::study::plan::plane_designs::append_columns(&mut df, &plan.designs)?;
            write_chunk(
                &chunks.join(format!("chunk-{next_chunk:06}.arrow")),
                &mut df,
            )?;
            next_chunk += 1;
            saved += buffer.len() as u64;
            buffer.clear();
            Ok(())
        };
        loop {
            match rx.recv_timeout(Duration::from_millis(200)) {
                Ok(record) => {
                    progress.advance(&record);
                    buffer.push(record);
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
            if buffer.len() >= options.chunk_runs || last_flush.elapsed() >= options.chunk_interval
            {
                flush(&mut buffer)?;
                last_flush = Instant::now();
            }
        }
        flush(&mut buffer)?;
        Ok(saved)
    })
}

/// The run ids of a block sample by sample, the designs interleaved. A
/// design's runs cost alike (a slow design's are all slow), so in id order,
/// which is design by design, the slowest design could come last and leave
/// the other threads idle at the block's end: on the main job at 2 threads
/// this order took 0.97× the time (1.69× → 1.74× over one thread). Which
/// thread runs what never changes a result, and chunks are sorted by id.
pub(super) fn designs_interleaved(block: &[u64], samples_per_design: u32) -> Vec<u64> {
    let samples = u64::from(samples_per_design.max(1));
    let mut order = block.to_vec();
    order.sort_by_key(|&id| (id % samples, id));
    order
}

/// The folder's finished table as a piece, if there is one.
pub(super) fn earlier_table_pieces(runs_path: &Path) -> Result<Vec<Piece>, RunError> {
    Ok(if runs_path.exists() {
        vec![Piece::open(runs_path)?]
    } else {
        Vec::new()
    })
}

/// Every complete chunk in `dir`, in the order written (leftover temporary
/// files of an interrupted write are removed).
pub(super) fn chunk_pieces(dir: &Path) -> Result<Vec<Piece>, RunError> {
    let mut out = Vec::new();
    if !dir.exists() {
        return Ok(out);
    }
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    paths.sort();
    for path in paths {
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or_default();
        if name.contains(".tmp-") {
            std::fs::remove_file(&path)?;
        } else if name.ends_with(".arrow") {
            out.push(Piece::open(&path)?);
        }
    }
    Ok(out)
}

pub(super) fn next_chunk_index(dir: &Path) -> Result<u64, RunError> {
    let mut next = 0;
    for entry in std::fs::read_dir(dir)? {
        let name = entry?.file_name().to_string_lossy().to_string();
        if let Some(num) = name
            .strip_prefix("chunk-")
            .and_then(|s| s.strip_suffix(".arrow"))
            && let Ok(i) = num.parse::<u64>()
        {
            next = next.max(i + 1);
        }
    }
    Ok(next)
}

#[cfg(test)]
mod tests {
    use super::designs_interleaved;

    #[test]
    fn interleaving_keeps_every_id_and_alternates_the_designs() {
        // Three designs of four samples: ids 0–3, 4–7, 8–11; a block 2..11.
        let block: Vec<u64> = (2..11).collect();
        let order = designs_interleaved(&block, 4);
        assert_eq!(order, [4, 8, 5, 9, 2, 6, 10, 3, 7]);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, block);
    }
}
