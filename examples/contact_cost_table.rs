//! The cost and effect of contact on every shipped study, the table of
//! docs/model.md: per study, with contact off and on, 20 samples per design
//! run on one thread, the runs per second, the settled share, the median
//! settling time (a run that did not settle counts as later than any that
//! did), the median residual and the deepest overlap of two weights.
//!
//! cargo run --release --example contact_cost_table

#[path = "../tests/it/contact_gauge.rs"]
mod contact_gauge;

use autobal::stats::quantile::median;
use autobal::study::run::run_one;
use contact_gauge::{STUDIES, plan, worst_overlap};

fn main() {
    println!(
        "| study | runs | contact | runs/s | settled | median t_s (rev) | median residual (A_ref) | worst overlap (2α) |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
    for name in STUDIES {
        for on in [false, true] {
            let p = plan(name, 20, Some(on));
            let clock = std::time::Instant::now();
            let runs: Vec<_> = (0..p.total_runs()).map(|id| run_one(&p, id)).collect();
            let rate = runs.len() as f64 / clock.elapsed().as_secs_f64();
            let times: Vec<f64> = runs
                .iter()
                .map(|r| r.metrics.settling_revs.unwrap_or(f64::INFINITY))
                .collect();
            let settled = times.iter().filter(|t| t.is_finite()).count();
            let residual: Vec<f64> = runs.iter().map(|r| r.metrics.residual_rel).collect();
            let (worst, _, _) = worst_overlap(&p);
            println!(
                "| {name} | {} | {} | {rate:.0} | {:.1} % | {} | {:.4} | {:.1} % |",
                runs.len(),
                if on { "on" } else { "off" },
                100.0 * settled as f64 / runs.len() as f64,
                median(&times)
                    .filter(|m| m.is_finite())
                    .map_or("beyond the run".into(), |m| format!("{m:.1}")),
                median(&residual).unwrap_or(f64::NAN),
                100.0 * worst,
            );
        }
    }
}
