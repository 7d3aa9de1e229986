//! The notes under the ranking that read the summary's other columns:
//! merged runs, the dead band of rolling resistance, contact between the
//! weights, and a stall-torque sweep's passage through resonance.

use super::*;

/// Runs that ended `merged`: how many, of which designs, and the way out.
pub(super) fn merged_line(sum: &Summary, order: &[usize]) -> PolarsResult<String> {
    let Ok(column) = sum.0.column("merged") else {
        return Ok(String::new());
    };
    let merged: Vec<u64> = column
        .u64()?
        .iter()
        .map(Option::unwrap_or_default)
        .collect();
    let ids = design_ids(sum)?;
    let parts: Vec<String> = order
        .iter()
        .filter(|&&i| merged[i] > 0)
        .map(|&i| format!("{} in design {}", merged[i], ids[i]))
        .collect();
    if parts.is_empty() {
        return Ok(String::new());
    }
    Ok(format!(
        "merged: {} runs ended when two identical weights coincided ({}), a state the equations never leave and real parts never reach: they count as not settled and their residuals are left out; give the weights their tolerances in [sampling.tolerances] (docs/model.md, \"Identical weights that meet\")\n",
        merged.iter().sum::<u64>(),
        parts.join(", ")
    ))
}

/// Designs whose weights circulated instead of balancing
/// ([`crate::metrics::circulates`]): in how many runs, and how much worse
/// than no balancer those runs ended.
pub(super) fn circulating_line(sum: &Summary, order: &[usize]) -> PolarsResult<String> {
    let Ok(column) = sum.0.column("circulating_runs") else {
        return Ok(String::new());
    };
    let count: Vec<u64> = column
        .u64()?
        .iter()
        .map(Option::unwrap_or_default)
        .collect();
    let runs: Vec<u64> = sum
        .0
        .column("runs")?
        .u64()?
        .iter()
        .map(Option::unwrap_or_default)
        .collect();
    let (lo, hi) = (
        sum.f("circulating_residual_rel_min")?,
        sum.f("circulating_residual_rel_max")?,
    );
    let ids = design_ids(sum)?;
    let parts: Vec<String> = order
        .iter()
        .filter(|&&i| count[i] > 0)
        .map(|&i| {
            let worse = match (lo[i], hi[i]) {
                (Some(a), Some(b)) if a > 1.0 => {
                    format!(
                        ", {}–{}× worse than no balancer",
                        num(Some(a), 1),
                        num(Some(b), 1)
                    )
                }
                (Some(a), Some(b)) => {
                    format!(", residual/A_ref {}–{}", num(Some(a), 2), num(Some(b), 2))
                }
                _ => String::new(),
            };
            format!(
                "design {}: weights circulate in {} of {} runs{worse}",
                ids[i], count[i], runs[i]
            )
        })
        .collect();
    if parts.is_empty() {
        return Ok(String::new());
    }
    Ok(format!(
        "circulating weights (the pack slipped against the rotor by at least {:.0} % of its speed at the end of a run that did not settle): {}; such runs count as not settled, and a design that ends worse than no balancer in significantly more than {:.0} % of its runs does not balance\n",
        100.0 * crate::metrics::CIRCULATING_SLIP_SHARE,
        parts.join("; "),
        100.0 * crate::decide::verdict::WORKS_WORSE_SHARE,
    ))
}

/// With rolling resistance: the dead band μ_s·l beside the band δ·A_ref.
pub(super) fn dead_band_line(sum: &Summary, order: &[usize]) -> PolarsResult<String> {
    let dead = sum.f("dead_band_m")?;
    if dead.iter().all(Option::is_none) {
        return Ok(String::new());
    }
    let ids = design_ids(sum)?;
    let planes = plane_bands(sum)?;
    if !planes.is_empty() {
        // Each plane settles into its own band: compare plane by plane.
        let parts: Vec<String> = order
            .iter()
            .map(|&i| {
                let each: Vec<String> = planes
                    .iter()
                    .enumerate()
                    .map(|(p, (dead, band))| {
                        format!(
                            "plane {p} {} µm vs {} µm",
                            num(dead[i].map(|d| d * 1e6), 2),
                            num(band[i].map(|b| b * 1e6), 2)
                        )
                    })
                    .collect();
                format!("design {} {}", ids[i], each.join(", "))
            })
            .collect();
        return Ok(format!(
            "dead band μ_s·l (l the track radius) against each plane's own settling band δ·A_ref (median A_ref of the plane), in ranking order: {}\n",
            parts.join("; ")
        ));
    }
    let band = sum.f("settling_band_m")?;
    let parts: Vec<String> = order
        .iter()
        .map(|&i| {
            format!(
                "design {} {} µm vs {} µm",
                ids[i],
                num(dead[i].map(|d| d * 1e6), 2),
                num(band[i].map(|b| b * 1e6), 2)
            )
        })
        .collect();
    Ok(format!(
        "dead band μ_s·l (l the track radius) against the settling band δ·A_ref (median A_ref), in ranking order: {}\n",
        parts.join(", ")
    ))
}

/// Per plane, each design's dead band and own settling band.
type PlaneBands = Vec<(Vec<Option<f64>>, Vec<Option<f64>>)>;

/// Per balancer plane with weights (a dead band), its dead band and own
/// settling band per design; empty on a rotor with one plane or a summary
/// written before the columns.
fn plane_bands(sum: &Summary) -> PolarsResult<PlaneBands> {
    let mut out = Vec::new();
    for p in 0.. {
        let [.., band, dead] = crate::decide::plane_summary::column_names(p);
        if sum.0.column(&dead).is_err() {
            break;
        }
        let dead = sum.f(&dead)?;
        if dead.iter().all(Option::is_none) {
            break;
        }
        out.push((dead, sum.f(&band)?));
    }
    Ok(out)
}

/// Whether the weights were solid, said under every ranking: a study that
/// switched contact off prints numbers for weights that pass through each other.
pub(super) fn contact_line(summary: &DataFrame, wide: bool) -> PolarsResult<String> {
    let contact = summary.column("contact")?.bool()?;
    let deepest = summary
        .column("max_overlap_fraction")?
        .f64()?
        .iter()
        .flatten()
        .reduce(f64::max);
    let closest = deepest.map_or(String::new(), |f| {
        format!(
            "; deepest overlap {:.2} % of the angle at which two weights touch{}",
            100.0 * f,
            if wide { " (2α)" } else { "" }
        )
    });
    let off = contact.iter().filter(|c| *c == Some(false)).count();
    // Summaries written before the column name no model.
    let models: std::collections::BTreeSet<String> = summary
        .column("contact_model")
        .ok()
        .and_then(|c| c.str().ok().cloned())
        .map(|c| c.iter().flatten().map(str::to_string).collect())
        .unwrap_or_default();
    let model = if models.is_empty() {
        String::new()
    } else {
        let names: Vec<String> = models.into_iter().collect();
        format!(" ({} contact)", names.join(", "))
    };
    Ok(if off == 0 {
        format!("contact between the weights: on{model}{closest}\n")
    } else {
        format!(
            "contact between the weights: OFF in {} of {} designs (the study switched it off: weights may pass through each other){model}{closest}\n",
            off,
            summary.height()
        )
    })
}

/// For a study that sweeps the motor's stall torque: per design, how many
/// runs reached the operating speed and where the rest were held (the
/// Sommerfeld effect, docs/realism.md); empty otherwise.
pub(super) fn passage_table(summary: &DataFrame) -> PolarsResult<String> {
    let Ok(torque) = summary.column("stall_torque") else {
        return Ok(String::new());
    };
    let torque: Vec<Option<f64>> = torque.f64()?.iter().collect();
    if torque.iter().all(Option::is_none) {
        return Ok(String::new());
    }
    let sum = Summary(summary);
    let kind = sum.s("kind")?;
    let n: Vec<Option<u32>> = summary.column("n")?.u32()?.iter().collect();
    let runs = sum.u("runs")?;
    let reached = sum.u("reached_operating_speed")?;
    let t_op = sum.f("operating_time_s_median")?;
    let spin = sum.f("final_spin_rate_median")?;
    let ids = design_ids(&sum)?;
    let rows: Vec<Vec<String>> = (0..summary.height())
        .map(|i| {
            vec![
                ids[i].to_string(),
                kind[i].clone().unwrap_or_else(|| "–".into()),
                n[i].map_or("–".into(), |v| v.to_string()),
                num(torque[i], 3),
                format!("{}/{}", reached[i], runs[i]),
                num(t_op[i], 2),
                num(spin[i], 1),
            ]
        })
        .collect();
    Ok(text_table(
        &[
            "design",
            "kind",
            "n",
            "M_s (N·m)",
            "reached operating speed",
            "after (s, median)",
            "final φ̇ median (rad/s)",
        ],
        &rows,
    ) + "(passage through resonance: a run that never reached |φ̇ − ω_sync| ≤ δ ω_sync was held below it for the whole run)\n")
}
