//! The benchmark's options and reports: time the ODE core (RHS cost per cargo count, solves per
//! method and tolerance), the solves `bench/scipy` repeats with SciPy, or a
//! small study at 1 and 2 threads, and print the figures; or write the main
//! job's runs for the lean reference `bench/lean`.

use crate::UserError;
use crate::bench::peer::{PeerConfig, PeerReport};
use crate::bench::threads::{ThreadConfig, ThreadScaling};
use crate::bench::{self, BenchConfig, BenchReport};
use crate::output::text_table;
use clap::Args;

/// Examples shown under `autobal-bench --help`.
pub const EXAMPLES: &str = "Examples:
  cargo run --release --bin autobal-bench
  cargo run --release --bin autobal-bench -- --json > bench.json
  autobal-bench --quick
  autobal-bench --revolutions 2000 --repeats 21
  cargo run --release --bin autobal-bench -- --peer-cases --json > autobal.json   # bench/scipy/run.sh does this
  cargo run --release --bin autobal-bench -- --thread-scaling --repeats 9
  autobal-bench --lean-inputs runs.csv --samples 20   # bench/lean/run.sh does this
  autobal-bench --racing-looks --repeats 5

Timings are only comparable within one run (cases are interleaved and the
median is reported); build with --release, a debug build says so in the output.";

/// Arguments of `autobal-bench`.
#[derive(Args)]
pub struct BenchArgs {
    /// Few repeats and a short horizon: a smoke run of a second or so.
    #[arg(long)]
    quick: bool,
    /// Print the whole report as one JSON object.
    #[arg(long)]
    json: bool,
    /// Horizon of each solve in revolutions (default 500; 20 with --quick).
    #[arg(long, value_parser = crate::bench_limits::bench_revolutions)]
    revolutions: Option<f64>,
    /// Timed solves per case and RHS batches per n (default 11 and 21; 3 with --quick);
    /// studies per thread count with --thread-scaling (default 7; 1 with --quick).
    #[arg(long, value_parser = crate::bench_limits::repeats)]
    repeats: Option<usize>,
    /// Only the solves `bench/scipy` repeats with SciPy (dp5 and dop853 at rtol
    /// 1e-6, 1e-8, 1e-9), with start, tolerances, RHS samples and final states.
    #[arg(long, conflicts_with = "thread_scaling")]
    peer_cases: bool,
    /// Compare the `full` and `rotating` fidelities on the isotropic reference
    /// scene over 10 000 revolutions (RHS calls, steps, time, same answer).
    #[arg(long, conflicts_with_all = ["thread_scaling", "peer_cases"])]
    fidelity: bool,
    /// Run a small fixed study (three_balls, 25 samples per design) with 1 and
    /// with 2 threads, interleaved, and report the speed-up.
    #[arg(long)]
    thread_scaling: bool,
    /// Write every run of the main job (studies/three_balls.toml, --samples
    /// per design) as one CSV row for the lean reference `bench/lean`: the
    /// rotating-frame equations' constants, start state, tolerances, observer
    /// constants and autobal's own answer.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["thread_scaling", "peer_cases", "fidelity"])]
    lean_inputs: Option<std::path::PathBuf>,
    /// With --lean-inputs: export this study's runs instead of the main
    /// job's (one plane rotor in the rotating frame; e.g. bench/lean/peer.toml).
    #[arg(long, value_name = "STUDY", requires = "lean_inputs", conflicts_with_all = ["thread_scaling", "peer_cases", "fidelity"])]
    lean_study: Option<std::path::PathBuf>,
    /// Run the main job on every sample, then replay the race it makes on
    /// those runs and time each look (the paired tests and bounds that
    /// decide which designs leave).
    #[arg(long, conflicts_with_all = ["thread_scaling", "peer_cases", "fidelity", "lean_inputs"])]
    racing_looks: bool,
    /// Samples per design with --thread-scaling (default 25; 1 with --quick),
    /// --lean-inputs (default 20) or --racing-looks (default the main job's 500).
    #[arg(long, value_parser = crate::limits::bench_runs)]
    samples: Option<usize>,
    /// Replace the --lean-inputs file if it exists.
    #[arg(long, requires = "lean_inputs")]
    overwrite: bool,
}

/// Run the benchmark the arguments name.
pub fn run(args: &BenchArgs) -> Result<(), UserError> {
    if args.samples.is_some()
        && !(args.thread_scaling || args.racing_looks || args.lean_inputs.is_some())
    {
        return Err(UserError(
            "--samples needs --thread-scaling, --racing-looks or --lean-inputs".into(),
            2,
        ));
    }
    if args.fidelity {
        return run_fidelity(args);
    }
    if let Some(path) = &args.lean_inputs {
        autobal::output_file::prepare(
            "--lean-inputs",
            path,
            autobal::output_file::WhenExists::from_overwrite(args.overwrite),
        )?;
        // bench_runs caps the samples at a million, well inside u32.
        let samples = args.samples.map_or(20, |s| s as u32);
        return write_lean_inputs(path, args.lean_study.as_deref(), samples);
    }
    if args.peer_cases {
        return run_peer_cases(args);
    }
    if args.thread_scaling {
        return run_thread_scaling(args);
    }
    if args.racing_looks {
        return run_racing_looks(args);
    }
    let mut config = if args.quick {
        BenchConfig::quick()
    } else {
        BenchConfig::full()
    };
    if let Some(revs) = args.revolutions {
        config.revolutions = revs;
    }
    if let Some(repeats) = args.repeats {
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

/// `autobal-bench --fidelity`: the `full` and `rotating` fidelities side by side.
fn run_fidelity(args: &BenchArgs) -> Result<(), UserError> {
    let revs = args
        .revolutions
        .unwrap_or(if args.quick { 1000.0 } else { 10_000.0 });
    let repeats = args.repeats.unwrap_or(if args.quick { 1 } else { 5 });
    let rows = bench::fidelity::measure_fidelities(revs, 1e-6, repeats);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&rows)?);
        return Ok(());
    }
    let table: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.fidelity.clone(),
                r.method.clone(),
                r.steps.to_string(),
                r.rhs_calls.to_string(),
                format!("{:.3}", 1e3 * r.wall_s),
                r.settling_revs.map_or("–".into(), |t| format!("{t:.3}")),
                format!("{:.1e}", r.residual_rel),
            ]
        })
        .collect();
    print!(
        "{}",
        crate::output::text_table(
            &[
                "fidelity",
                "method",
                "steps",
                "RHS calls",
                "ms",
                "t_s rev",
                "residual/A_ref"
            ],
            &table
        )
    );
    if let [full, rot] = rows.as_slice() {
        println!(
            "{revs} revolutions at rtol 1e-6: rotating uses {:.1}× fewer RHS calls and {:.1}× less time than full",
            full.rhs_calls as f64 / rot.rhs_calls as f64,
            full.wall_s / rot.wall_s
        );
    }
    Ok(())
}

/// Export the main job's runs, or `study`'s, for `bench/lean` (each run is
/// solved once by autobal).
fn write_lean_inputs(
    path: &std::path::Path,
    study: Option<&std::path::Path>,
    samples: u32,
) -> Result<(), UserError> {
    let plan = match study {
        Some(file) => bench::lean_inputs::lean_plan_of(file, samples)
            .map_err(|e| UserError(format!("--lean-study {}: {e}", file.display()), 2))?,
        None => bench::lean_inputs::lean_plan(samples),
    };
    let rows = bench::lean_inputs::lean_rows(&plan).map_err(UserError::internal)?;
    let mut text = Vec::new();
    bench::lean_inputs::write_csv(&rows, &mut text)
        .map_err(|e| UserError::internal(e.to_string()))?;
    let text = String::from_utf8(text).map_err(|e| UserError::internal(e.to_string()))?;
    autobal::study::results::io::write_text(path, &text)
        .map_err(|e| UserError::internal(format!("--lean-inputs {}: {e}", path.display())))?;
    eprintln!(
        "wrote {} runs of {} to {}",
        rows.len(),
        plan.name,
        path.display()
    );
    Ok(())
}

fn run_peer_cases(args: &BenchArgs) -> Result<(), UserError> {
    let mut config = if args.quick {
        PeerConfig::quick()
    } else {
        PeerConfig::full()
    };
    if let Some(revs) = args.revolutions {
        config.revolutions = revs;
    }
    if let Some(repeats) = args.repeats {
        config.repeats = repeats;
    }
    let report = bench::peer::peer_cases(&config);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", describe_peers(&report));
    }
    Ok(())
}

fn describe_peers(r: &PeerReport) -> String {
    let mut out = String::new();
    if r.debug_build {
        out.push_str(
            "warning: debug build; use `cargo run --release --bin autobal-bench` for timings\n\n",
        );
    }
    let c = &r.config;
    out.push_str(&format!(
        "Solves repeated by bench/scipy: {} cargoes, {} revolutions (t_end {:.4}), median of {}\n",
        c.cargoes, c.revolutions, r.t_end, c.repeats
    ));
    let rows: Vec<Vec<String>> = r
        .cases
        .iter()
        .map(|s| {
            vec![
                s.method.name().to_string(),
                format!("{:.0e}", s.rtol),
                format!("{:.3}", s.median_ms),
                format!("{:.3}", s.min_ms),
                s.stats.steps.to_string(),
                s.stats.rejected.to_string(),
                s.stats.rhs_calls.to_string(),
                format!("{:.1e}", s.error_vs_reference),
                s.status.clone(),
            ]
        })
        .collect();
    out.push_str(&text_table(
        &[
            "method", "rtol", "ms", "min ms", "steps", "rejected", "RHS", "error", "status",
        ],
        &rows,
    ));
    out.push_str(&format!(
        "error: largest final-state difference to {} at rtol {:.0e} (which agrees with dp5 at 10× its rtol to {:.1e}),\n       in units of A_ref, A_ref·ω, rad, rad·ω\n",
        r.reference.method.name(),
        r.reference.rtol,
        r.reference.cross_check
    ));
    out
}

fn run_thread_scaling(args: &BenchArgs) -> Result<(), UserError> {
    let mut config = if args.quick {
        ThreadConfig::quick()
    } else {
        ThreadConfig::full()
    };
    if let Some(repeats) = args.repeats {
        config.repeats = repeats;
    }
    if let Some(samples) = args.samples {
        config.samples = samples as u32;
    }
    let dir = std::env::temp_dir().join(format!("autobal-bench-threads-{}", std::process::id()));
    let result = bench::threads::measure_threads(&config, &dir);
    // The study's files are scratch: remove them whatever happened.
    let _ = std::fs::remove_dir_all(&dir);
    let report = result.map_err(|e| UserError::internal(e.to_string()))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", describe_threads(&report));
    }
    Ok(())
}

/// `autobal-bench --racing-looks`: the main job's race replayed, each look timed.
fn run_racing_looks(args: &BenchArgs) -> Result<(), UserError> {
    let samples = args.samples.map_or(500, |s| s as u32);
    let repeats = args.repeats.unwrap_or(if args.quick { 1 } else { 5 });
    let dir = std::env::temp_dir().join(format!("autobal-bench-looks-{}", std::process::id()));
    let result = bench::looks::measure_looks(samples, repeats, &dir);
    // The study's files are scratch: remove them whatever happened.
    let _ = std::fs::remove_dir_all(&dir);
    let report = result.map_err(|e| UserError::internal(e.to_string()))?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    if report.debug_build {
        println!(
            "warning: debug build; use `cargo run --release --bin autobal-bench` for timings\n"
        );
    }
    let rows: Vec<Vec<String>> = report
        .looks
        .iter()
        .map(|l| {
            vec![
                l.look.to_string(),
                l.samples.to_string(),
                l.running.to_string(),
                l.left.to_string(),
                format!("{:.2}", l.ms),
            ]
        })
        .collect();
    print!(
        "{}",
        text_table(&["look", "samples", "running", "left", "ms"], &rows)
    );
    println!(
        "looks: median {:.2} ms, largest {:.2} ms (median of {repeats} replays); runs {} raced of {} on every sample",
        report.median_ms, report.max_ms, report.runs_raced, report.runs_every_sample
    );
    Ok(())
}

fn describe_threads(r: &ThreadScaling) -> String {
    let mut out = String::new();
    if r.debug_build {
        out.push_str(
            "warning: debug build; use `cargo run --release --bin autobal-bench` for timings\n\n",
        );
    }
    out.push_str(&format!(
        "Study {}: {} designs × {} samples = {} runs, {} RHS calls; {} repeats per thread count (ABBA)\n",
        r.study, r.designs, r.config.samples, r.runs, r.rhs_calls, r.config.repeats
    ));
    let rows: Vec<Vec<String>> = r
        .timings
        .iter()
        .map(|t| {
            vec![
                t.threads.to_string(),
                format!("{:.3}", t.median_s),
                format!("{:.3}", t.min_s),
                format!("{:.2}", t.speedup),
                format!("{:.2}", t.paired_speedup),
                format!("{:.2}", t.speedup_min),
                t.cores_used.map_or("–".into(), |c| format!("{c:.2}")),
                if t.cpu_s.is_empty() {
                    "–".into()
                } else {
                    format!("{:.3}", bench::median(&t.cpu_s))
                },
            ]
        })
        .collect();
    out.push_str(&text_table(
        &[
            "threads",
            "median s",
            "min s",
            "speed-up",
            "paired",
            "of fastest",
            "cores used",
            "CPU s",
        ],
        &rows,
    ));
    let load = |l: Option<[f64; 3]>| {
        l.map_or("unknown".into(), |[a, b, c]| {
            format!("{a:.2} {b:.2} {c:.2}")
        })
    };
    out.push_str(&format!(
        "speed-up: ratio of medians; paired: median of per-round ratios; of fastest: ratio of minima;\n\
         cores used: CPU time / wall time (below the thread count when other processes hold cores);\n\
         CPU s: median CPU time per study, all threads (equal across thread counts when threading adds no work)\n\
         results identical across thread counts: {}\n\
         cores available: {}; load average before {}, after {}\n",
        if r.identical_results { "yes" } else { "NO" },
        r.available_parallelism,
        load(r.load_before),
        load(r.load_after)
    ));
    out
}

fn describe(r: &BenchReport) -> String {
    let mut out = String::new();
    if r.debug_build {
        out.push_str(
            "warning: debug build; use `cargo run --release --bin autobal-bench` for timings\n\n",
        );
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
