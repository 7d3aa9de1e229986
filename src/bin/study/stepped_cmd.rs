//! `study stepped`: one scene stepped up (and back down) through a speed
//! range with a dwell at each step, carrying the state, as rigs are measured.

use crate::UserError;
use autobal::output_file::{WhenExists, prepare};
use autobal::scene_file::SceneFile;
use autobal::simulation::stepped::{
    StepPoint, SteppedError, SweepSeries, check_dwell, stepped_speeds, to_dataframe,
};
use autobal::study::results::io::{Provenance, write_parquet};
use clap::Args;
use std::f64::consts::PI;
use std::path::PathBuf;

/// Examples shown under `study stepped --help`.
pub const EXAMPLES: &str = "Examples:
  study stepped scenes/bristol_rig.toml --rpm 1000..5000 --step-rpm 100 --dwell 0.25
  study stepped scenes/two_support_long.toml --rpm 10..60 --step-rpm 2.5 --dwell 60 --up-only
  study stepped scenes/bristol_rig.toml --rpm 1000..3000 --step-rpm 50 --dwell 0.5 --out steps.parquet";

/// Arguments of `study stepped`.
#[derive(Args)]
pub struct SteppedArgs {
    /// Scene file (TOML); its speed law is replaced by each step's constant
    /// speed, and its start is where the run-up begins.
    scene: PathBuf,
    /// Speed range `lo..hi` (rpm): the run-up goes from lo to hi.
    #[arg(long)]
    rpm: String,
    /// Speed step between dwells (rpm); the last step up ends at hi.
    #[arg(long, value_parser = crate::limits::step_rpm)]
    step_rpm: f64,
    /// Time held at each speed (s), at least one revolution: the last
    /// revolution of each dwell is the one measured.
    #[arg(long, value_parser = crate::limits::dwell_seconds)]
    dwell: f64,
    /// Seconds at the end of each dwell over which the vibration is read
    /// (whole revolutions; default the last revolution), as a rig reads it.
    #[arg(long, value_parser = crate::limits::dwell_seconds)]
    window: Option<f64>,
    /// Run up only (by default the run-down from hi back to lo follows).
    #[arg(long)]
    up_only: bool,
    /// Write every sample read (each dwell's window) to this Parquet file: a rig's recording.
    #[arg(long)]
    series: Option<PathBuf>,
    /// Worker threads for --draws (the results do not depend on it).
    #[arg(long, value_parser = crate::limits::threads)]
    threads: Option<usize>,
    /// Write one row per step to this Parquet file.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace the --out (and --draws-out) file if it exists.
    #[arg(long)]
    overwrite: bool,
    /// Print the steps as JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Sweep this many draws of the scene's `[uncertain]` keys and print the
    /// median and the 5–95 % band of each step (default 32 when the scene
    /// has uncertain keys); `--draws 0` sweeps the nominal scene only.
    #[arg(long, value_parser = crate::limits::draws)]
    draws: Option<u32>,
    /// Seed of the draws.
    #[arg(long, default_value_t = autobal::study::plan::config::DEFAULT_SEED)]
    seed: u64,
    /// Write every draw's steps (mean bearing peak, ratio, onset, key values) to this Parquet file.
    #[arg(long)]
    draws_out: Option<PathBuf>,
}

/// Draws of the uncertain keys when a scene has them and --draws is not given.
const DEFAULT_DRAWS: u32 = 32;

/// Most steps one sweep may take (each a whole dwell's integration).
const MAX_STEPS: f64 = 100_000.0;

fn parse_rpm(text: &str) -> Result<(f64, f64), UserError> {
    crate::limits::speed_range(
        "rpm",
        text,
        false,
        Some("1000..5000"),
        30.0 / std::f64::consts::PI,
    )
    .map_err(|e| UserError(e, 2))
}

/// Run `study stepped`.
pub fn run(args: &SteppedArgs) -> Result<(), UserError> {
    let (lo, hi) = parse_rpm(&args.rpm)?;
    if (hi - lo) / args.step_rpm > MAX_STEPS {
        return Err(UserError(
            format!(
                "--step-rpm {}: {:.0} steps from {lo} to {hi} rpm, more than {MAX_STEPS}; take larger steps",
                args.step_rpm,
                (hi - lo) / args.step_rpm
            ),
            2,
        ));
    }
    if args.overwrite && args.out.is_none() && args.draws_out.is_none() {
        return Err(UserError(
            "--overwrite: replaces an output file; give --out (or --draws-out)".into(),
            2,
        ));
    }
    let shown = args.scene.display().to_string();
    let file = SceneFile::read(&args.scene)?;
    let draws = match (args.draws, file.uncertain.is_empty()) {
        (Some(n), true) if n > 0 => {
            return Err(UserError(
                format!("--draws {n}: {shown} has no [uncertain] keys to draw"),
                2,
            ));
        }
        (Some(n), _) => n,
        (None, true) => 0,
        (None, false) => DEFAULT_DRAWS,
    };
    check_draw_flags(args, draws)?;
    for (flag, path) in [
        ("--out", &args.out),
        ("--draws-out", &args.draws_out),
        ("--series", &args.series),
    ] {
        if let Some(path) = path {
            // Steps hold a list per bearing, which CSV cannot: any other
            // name would hold Parquet under the wrong name.
            if path.extension().is_none_or(|e| e != "parquet") {
                return Err(UserError(
                    format!(
                        "{flag} {}: study stepped writes Parquet files only; name it .parquet",
                        path.display()
                    ),
                    2,
                ));
            }
            prepare(flag, path, WhenExists::from_overwrite(args.overwrite))?;
        }
    }
    let simulation = file.simulation(&shown)?;
    for line in protocol_warnings(&file) {
        eprintln!("warning: {line}");
    }
    let to_rad = PI / 30.0;
    let speeds = stepped_speeds(
        lo * to_rad,
        hi * to_rad,
        args.step_rpm * to_rad,
        !args.up_only,
    );
    // Before the first dwell (or draw): an endless sweep is refused whole.
    check_dwell(&speeds, args.dwell)
        .map_err(|e| UserError(format!("--dwell {}: {}", args.dwell, reason(&e)), 2))?;
    if draws > 0 {
        let outputs = crate::stepped_bands_cmd::Outputs {
            bands: args.out.as_deref(),
            draws: args.draws_out.as_deref(),
            scene: &args.scene,
            json: args.json,
        };
        let sweep = (speeds.as_slice(), args.dwell, args.window);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(crate::limits::capped_threads(args.threads).unwrap_or(0))
            .build()
            .map_err(|e| UserError::internal(e.to_string()))?;
        return pool.install(|| {
            crate::stepped_bands_cmd::run(&file, &simulation, sweep, (draws, args.seed), outputs)
        });
    }
    let mut series = args.series.as_ref().map(|_| SweepSeries::default());
    let swept =
        simulation.stepped_sweep_windowed(&speeds, args.dwell, args.window, series.as_mut());
    let (points, failure) = match swept {
        Ok(points) => (points, None),
        Err(SteppedError::Scene(e)) if matches!(&e, autobal::model::scene::SceneError::Invalid { field, .. } if field == "dwell") =>
        {
            return Err(UserError(
                format!("--dwell {}: {}", args.dwell, reason(&e)),
                2,
            ));
        }
        Err(SteppedError::Scene(e)) => return Err(e.into()),
        Err(SteppedError::Failed { done, omega, why }) => (
            done,
            Some(format!(
                "the solver stopped in the dwell at {:.1} rpm: {why}",
                omega / to_rad
            )),
        ),
    };
    write_nominal(args, &points, series.as_ref())?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&points)?);
    } else {
        print!("{}", describe(&points));
    }
    match failure {
        // The steps before the failure are kept and shown; the run says why it stopped.
        Some(why) => Err(UserError(why, 1)),
        None => Ok(()),
    }
}

/// The flags that depend on whether the scene's draws are swept: each one
/// that cannot take effect is refused, naming it.
fn check_draw_flags(args: &SteppedArgs, draws: u32) -> Result<(), UserError> {
    if args.draws_out.is_some() && draws == 0 {
        return Err(UserError(
            "--draws-out: needs draws of the scene's [uncertain] keys (--draws N)".into(),
            2,
        ));
    }
    if let Some(w) = args.window
        && w > args.dwell
    {
        return Err(UserError(
            format!(
                "--window {w}: longer than the dwell ({} s) it is read from",
                args.dwell
            ),
            2,
        ));
    }
    if args.series.is_some() && draws > 0 {
        return Err(UserError(
            "--series: records one sweep; give --draws 0 to sweep the nominal scene".into(),
            2,
        ));
    }
    if args.threads.is_some() && draws == 0 {
        return Err(UserError(
            "--threads: runs the draws in parallel; one sweep is one thread (give --draws N)"
                .into(),
            2,
        ));
    }
    Ok(())
}

/// The nominal sweep's files: its steps (--out) and its samples (--series).
fn write_nominal(
    args: &SteppedArgs,
    points: &[StepPoint],
    series: Option<&SweepSeries>,
) -> Result<(), UserError> {
    if args.out.is_none() && args.series.is_none() {
        return Ok(());
    }
    let text = autobal::input_file::read_text(&args.scene)?;
    if let Some(path) = &args.out {
        let provenance = Provenance::new(&text, 0, "stepped sweep");
        let mut df = to_dataframe(points).map_err(|e| UserError::internal(e.to_string()))?;
        write_parquet(path, &mut df, &provenance)
            .map_err(|e| UserError::internal(format!("--out {e}")))?;
    }
    if let (Some(path), Some(series)) = (&args.series, series) {
        let provenance = Provenance::new(&text, 0, "stepped sweep series");
        let mut df = series
            .to_dataframe()
            .map_err(|e| UserError::internal(e.to_string()))?;
        write_parquet(path, &mut df, &provenance)
            .map_err(|e| UserError::internal(format!("--series {e}")))?;
    }
    Ok(())
}

/// The reason part of a scene error.
fn reason(e: &autobal::model::scene::SceneError) -> String {
    match e {
        autobal::model::scene::SceneError::Invalid { reason, .. } => reason.clone(),
        other => other.to_string(),
    }
}

/// The steps as a text table.
fn describe(points: &[StepPoint]) -> String {
    let bearings = points.iter().any(|p| p.bearing_peak.is_some());
    let rows: Vec<Vec<String>> = points
        .iter()
        .map(|p| {
            let mut row = vec![
                p.direction.name().to_string(),
                format!("{:.1}", p.omega * 30.0 / PI),
                format!("{:.3}", p.omega),
                format!("{:.3e}", p.whirl_peak),
            ];
            if bearings {
                let peaks = p.bearing_peak.clone().unwrap_or_default();
                let mean = peaks.iter().sum::<f64>() / peaks.len().max(1) as f64;
                row.push(
                    peaks
                        .iter()
                        .map(|x| format!("{x:.3e}"))
                        .collect::<Vec<_>>()
                        .join(" "),
                );
                row.push(format!("{mean:.3e}"));
                let without = p.bearing_peak_without.clone().unwrap_or_default();
                let mean_without = without.iter().sum::<f64>() / without.len().max(1) as f64;
                row.push(format!("{:.3}", mean / mean_without));
            }
            row.push(format!("{:.2e}", p.balancing_error));
            row
        })
        .collect();
    let mut header = vec!["run", "speed\nrpm", "ω\nrad/s", "whirl peak\nm"];
    if bearings {
        header.push("bearing peaks\nm");
        header.push("mean of peaks\nm");
        header.push("over\nwithout");
    }
    header.push("ε");
    let mut s = crate::output::text_table(&header, &rows);
    s += "\nEach row: the dwell at that speed read over its last revolution (or --window), the state carried from the step before. Whirl: the largest balancer (or load) plane's radial displacement; bearing peaks: each support's; over without: the mean of the peaks over the same mean without the balancer's unbalance (the rotor's own unbalance, weights' mass carried); ε: the unbalance left over U.\n";
    s
}

/// What the scene makes of a rig's protocol that a user would not guess.
fn protocol_warnings(file: &SceneFile) -> Vec<String> {
    let mut out = Vec::new();
    if file.effects.rolling_resistance.is_some() {
        out.push(
            "with rolling resistance the balls stop where the last step left them: the answer depends on --step-rpm, --dwell and --window (up to 2x on the Bristol rig, docs/validation.md); use the rig's own protocol".into(),
        );
    }
    if file.cargo.len() >= 2 {
        out.push(format!(
            "the {} [[cargo]] weights are point masses with no contact: two can sit at the same angle and act as one, which solid balls cannot; give [balancer] (kind, n, rho, race_radius) for solid weights that touch",
            file.cargo.len()
        ));
    }
    out
}
