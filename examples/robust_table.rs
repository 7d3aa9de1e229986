//! The robust-design table of docs/realism.md: per design, the residual
//! objectives of `study optimize` (`p_residual_below`, `residual_p95`,
//! computed by the same functions) on the runs of one or more study folders,
//! side by side, and which design each column ranks first.
//!
//! cargo run --example robust_table -- --spec 5e-6 /tmp/tol0/tolerances results/tolerances
//!
//! `--runs` lists every run of the first folder instead (design, unbalance,
//! outcome, residual, weights), for looking at individual runs.

use autobal::optimize::evaluate::measured_residual;
use autobal::stats::quantile::{Interpolation, quantile};
use autobal::study::results::io::read_parquet;
use autobal::study::results::record::{RunRecord, from_dataframe};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// One design in one folder: P(residual < spec), residual p95 (µm), settled share.
type Figures = (f64, f64, f64);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut spec = 5e-6;
    let mut list = false;
    let mut folders = Vec::new();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--spec" => spec = args.next().ok_or("--spec METRES")?.parse()?,
            "--runs" => list = true,
            _ => folders.push(PathBuf::from(a)),
        }
    }
    let tables: Vec<Vec<RunRecord>> = folders
        .iter()
        .map(|f| from_dataframe(&read_parquet(&f.join("runs.parquet"))?))
        .collect::<Result<_, _>>()?;
    if list {
        for r in tables.first().ok_or("give a folder")? {
            println!(
                "{} {} n={} rho={:.3} drag={} U={:.3e} {} res={:.3e} rel={:.3e} masses={:?}",
                r.run_id,
                r.design_id,
                r.n,
                r.rho,
                r.drag,
                r.unbalance,
                r.metrics.outcome.name(),
                r.metrics.residual_abs,
                r.metrics.residual_rel,
                r.weights.as_ref().map(|w| w.masses.clone())
            );
        }
        return Ok(());
    }
    // Per folder: design → (label, P(res < spec), p95 in µm, settled share).
    let mut rows: BTreeMap<u32, (String, Vec<Figures>)> = BTreeMap::new();
    for runs in &tables {
        let mut by_design: BTreeMap<u32, Vec<&RunRecord>> = BTreeMap::new();
        for r in runs {
            by_design.entry(r.design_id).or_default().push(r);
        }
        for (id, rs) in by_design {
            let residuals: Vec<f64> = rs.iter().map(|r| measured_residual(&r.metrics)).collect();
            let n = residuals.len() as f64;
            let below = residuals.iter().filter(|&&v| v < spec).count() as f64 / n;
            let p95 = quantile(&residuals, 0.95, Interpolation::Linear).unwrap_or(f64::NAN);
            let settled = rs.iter().filter(|r| r.metrics.settled).count() as f64 / n;
            let r0 = rs[0];
            let entry = rows.entry(id).or_insert_with(|| {
                (
                    format!("| {} | {:.3} | {} |", r0.n, r0.rho, r0.drag),
                    Vec::new(),
                )
            });
            entry.1.push((below, p95 * 1e6, settled));
        }
    }
    let best = |k: usize, col: fn(&Figures) -> f64, max: bool| {
        rows.iter()
            .filter_map(|(id, (_, v))| v.get(k).map(|x| (*id, col(x))))
            .fold(None, |acc: Option<(u32, f64)>, (id, v)| match acc {
                Some((_, b)) if (max && v <= b) || (!max && v >= b) => acc,
                _ => Some((id, v)),
            })
            .map(|(id, _)| id)
    };
    let header: Vec<String> = (0..tables.len())
        .map(|k| format!("folder {}", k + 1))
        .collect();
    println!(
        "| n | ρ | β (N·s/m) | P(residual < {:.1} µm) | residual p95 (µm) | settled | ({}) |",
        spec * 1e6,
        header.join(" → ")
    );
    println!("| --- | --- | --- | --- | --- | --- | --- |");
    for (id, (label, v)) in &rows {
        let join = |f: &dyn Fn(&Figures) -> String| v.iter().map(f).collect::<Vec<_>>().join(" → ");
        println!(
            "{label} {} | {} | {} | design {id} |",
            join(&|x| format!("{:.2}", x.0)),
            join(&|x| format!("{:.2}", x.1)),
            join(&|x| format!("{:.2}", x.2)),
        );
    }
    for k in 0..tables.len() {
        println!(
            "folder {}: best P(residual < spec): design {:?}; best residual p95: design {:?}",
            k + 1,
            best(k, |x| x.0, true),
            best(k, |x| x.1, false)
        );
    }
    Ok(())
}
