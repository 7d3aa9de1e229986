//! `study bench`: time the ODE core (RHS cost per cargo count, solves per
//! method and tolerance) and print the figures.

use crate::UserError;
use crate::output::text_table;
use autobal::bench::{self, BenchConfig, BenchReport};
use clap::Args;

/// Examples shown under `study bench --help`.
pub const EXAMPLES: &str = "Examples:
  cargo run --release -- bench
  cargo run --release -- bench --json > bench.json
  study bench --quick
  study bench --revolutions 2000 --repeats 21

Timings are only comparable within one run (cases are interleaved and the
median is reported); build with --release, a debug build says so in the output.";

/// Arguments of `study bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Few repeats and a short horizon: a smoke run of a second or so.
    #[arg(long)]
    quick: bool,
    /// Print the whole report as one JSON object.
    #[arg(long)]
    json: bool,
    /// Horizon of each solve in revolutions (default 500; 20 with --quick).
    #[arg(long)]
    revolutions: Option<f64>,
    /// Timed solves per case and RHS batches per n (default 11 and 21; 3 with --quick).
    #[arg(long)]
    repeats: Option<usize>,
}

/// Run `study bench`.
pub fn run(args: &BenchArgs) -> Result<(), UserError> {
    let mut config = if args.quick {
        BenchConfig::quick()
    } else {
        BenchConfig::full()
    };
    if let Some(revs) = args.revolutions {
        if !(revs.is_finite() && revs > 0.0) {
            return Err(UserError(
                format!("--revolutions {revs}: must be positive and finite"),
                2,
            ));
        }
        config.revolutions = revs;
    }
    if let Some(repeats) = args.repeats {
        if repeats == 0 {
            return Err(UserError("--repeats 0: need at least one".into(), 2));
        }
        config.solve_repeats = repeats;
        config.rhs_samples = repeats;
    }
    let report = bench::run(&config);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", describe(&report));
    }
    Ok(())
}

fn describe(r: &BenchReport) -> String {
    let mut out = String::new();
    if r.debug_build {
        out.push_str("warning: debug build; use `cargo run --release -- bench` for timings\n\n");
    }
    out.push_str("Right-hand side (reference scene, n point cargoes)\n");
    let rows: Vec<Vec<String>> = r
        .rhs
        .points
        .iter()
        .map(|p| {
            vec![
                p.cargoes.to_string(),
                p.dim.to_string(),
                format!("{:.1}", p.ns_per_call),
                format!("{:.1}", p.min_ns_per_call),
                format!("{:.2}", p.ns_per_call_per_cargo),
                r.rhs.fit.as_ref().map_or("–".into(), |f| {
                    format!(
                        "{:.1}",
                        f.intercept_ns + f.slope_ns_per_cargo * p.cargoes as f64
                    )
                }),
            ]
        })
        .collect();
    out.push_str(&text_table(
        &["n", "dim", "ns/call", "min ns", "ns/call/n", "fit ns"],
        &rows,
    ));
    if let Some(f) = &r.rhs.fit {
        out.push_str(&format!(
            "fit: {:.1} ns + {:.2} ns·n  (R² {:.4}, worst residual {:.1} %)\n",
            f.intercept_ns,
            f.slope_ns_per_cargo,
            f.r_squared,
            100.0 * f.max_rel_residual
        ));
    }
    let c = &r.config;
    out.push_str(&format!(
        "\nSolves: {} cargoes, {} revolutions, no observer, median of {}\n",
        c.solve_cargoes, c.revolutions, c.solve_repeats
    ));
    let rows: Vec<Vec<String>> = r
        .solves
        .iter()
        .map(|s| {
            vec![
                s.method.name().to_string(),
                format!("{:.0e}", s.rtol),
                format!("{:.2}", s.median_ms),
                format!("{:.2}", s.us_per_revolution),
                s.stats.steps.to_string(),
                s.stats.rejected.to_string(),
                s.stats.rhs_calls.to_string(),
                format!("{:.1}", s.ns_per_rhs_call),
                s.error_vs_reference
                    .map_or("–".into(), |e| format!("{e:.1e}")),
                s.status.clone(),
            ]
        })
        .collect();
    out.push_str(&text_table(
        &[
            "method", "rtol", "ms", "µs/rev", "steps", "rejected", "RHS", "ns/RHS", "error",
            "status",
        ],
        &rows,
    ));
    out.push_str(
        "error: largest final-state difference to a tight DP5 reference, in units of A_ref, A_ref·ω, rad, rad·ω\n",
    );
    out
}
