//! `study simulate`: run one scene and print its metrics.

use crate::UserError;
use autobal::metrics::RunMetrics;
use autobal::model::critical_speeds::critical_speeds_in_range;
use autobal::model::speed::{RAD_PER_RPM, SpeedLaw};
use autobal::output_file::{WhenExists, prepare};
use autobal::scene_file::SceneFile;
use autobal::study::results::io::{Provenance, write_series};
use clap::Args;
use std::path::PathBuf;

/// Examples shown under `study simulate --help`.
pub const EXAMPLES: &str = "Examples:
  study simulate scenes/three_balls.toml
  study simulate scenes/three_balls.toml --json
  study simulate scenes/three_balls.toml --series run.csv
  study simulate scenes/three_balls.toml --series run.parquet";

/// Arguments of `study simulate`.
#[derive(Args)]
pub struct SimulateArgs {
    /// Scene file (TOML): rotor, balancer, speed, effects, start, solver, metrics.
    scene: PathBuf,
    /// Print the metrics as one JSON object.
    #[arg(long)]
    json: bool,
    /// Write the sampled time history (t, x, y, r, ε, ψ_j, each bearing's x and y) to this file:
    /// Parquet when it ends in .parquet, CSV otherwise.
    #[arg(long)]
    series: Option<PathBuf>,
    /// Replace the --series file if it exists.
    #[arg(long, requires = "series")]
    overwrite: bool,
    /// Run the scene once per draw of its `[uncertain]` keys and print the
    /// spread of settling and residual (--json: every draw).
    #[arg(long, value_parser = crate::limits::draws, conflicts_with = "series")]
    draws: Option<u32>,
    /// Seed of the draws.
    #[arg(long, default_value_t = autobal::study::plan::config::DEFAULT_SEED)]
    seed: u64,
}

/// Run `study simulate`.
pub fn run(args: &SimulateArgs) -> Result<(), UserError> {
    let shown = args.scene.display().to_string();
    let file = SceneFile::read(&args.scene)?;
    let simulation = file.simulation(&shown)?;
    match args.draws {
        Some(n) if n > 0 && file.uncertain.is_empty() => {
            return Err(UserError(
                format!("--draws {n}: {shown} has no [uncertain] keys to draw"),
                2,
            ));
        }
        Some(n) if n > 0 => {
            return crate::simulate_draws_cmd::run(&file, &simulation, (n, args.seed), args.json);
        }
        _ => {}
    }
    if !file.uncertain.is_empty() && !args.json {
        crate::output::say_err(&format!(
            "(the nominal values of the scene's {} uncertain key(s); --draws N runs their spread)",
            file.uncertain.len()
        ));
    }
    if let Some(path) = &args.series {
        prepare("--series", path, WhenExists::from_overwrite(args.overwrite))?;
    }
    let critical = simulation
        .scene
        .build()
        .ok()
        .and_then(|system| critical_speeds_in_range(&system));
    let result = simulation.run(args.series.is_some())?;
    if let (Some(path), Some(series)) = (&args.series, &result.series) {
        let text = autobal::input_file::read_text(&args.scene)?;
        let provenance = Provenance::new(&text, 0, "single run");
        write_series(path, series, &provenance).map_err(|e| UserError::internal(e.to_string()))?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&result.metrics)?);
    } else {
        print!(
            "{}",
            crate::output::wrap(
                &format!(
                    "{}{}{}{}",
                    speed_line(&simulation.scene.speed),
                    describe(&result.metrics),
                    bearing_orbits_line(&result.metrics),
                    critical_speeds_line(critical.as_deref())
                ),
                crate::output::text_width()
            )
        );
    }
    Ok(())
}

/// The speed law in both units, so that an `omega` typed in rpm shows at
/// once: "ω = 314.2 rad/s (3000 rpm)".
fn speed_line(law: &SpeedLaw) -> String {
    let sig4 = |v: f64| autobal::number_text::significant(v, 4);
    let both = |w: f64| format!("{} rad/s ({} rpm)", sig4(w), sig4(w / RAD_PER_RPM));
    let text = match *law {
        SpeedLaw::Constant { omega } => format!("ω = {}, constant", both(omega)),
        SpeedLaw::Ramp {
            omega_start,
            omega_end,
            duration,
        } => format!(
            "ω from {} to {} over {} s",
            both(omega_start),
            both(omega_end),
            sig4(duration)
        ),
        SpeedLaw::Motor {
            omega_sync,
            omega_start,
            ..
        } => format!(
            "motor: ω_sync = {}, from ω = {}",
            both(omega_sync),
            both(omega_start)
        ),
        SpeedLaw::Free { omega_start } => format!("free: from ω = {}", both(omega_start)),
    };
    format!("speed              {text}\n")
}

/// Each bearing's orbit over the revolution after the run (rotors with
/// bearings of their own), as a rig measures vibration; empty otherwise.
fn bearing_orbits_line(m: &autobal::metrics::RunMetrics) -> String {
    let (Some(peak), Some(rms)) = (&m.bearing_orbit_peak, &m.bearing_orbit_rms) else {
        return String::new();
    };
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.4e}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    format!(
        "bearing orbits     peak [{}] m, RMS [{}] m\n  (each support, over the revolution after the run)\n",
        list(peak),
        list(rms)
    )
}

/// The model's undamped critical speeds, to compare with a rig's measured
/// resonances before trusting the rest.
pub fn critical_speeds_line(speeds: Option<&[f64]>) -> String {
    let text = match speeds {
        Some([]) => "none (no spin equals a natural frequency)".to_string(),
        Some(speeds) => {
            let list = |scale: f64| {
                let each: Vec<String> =
                    speeds.iter().map(|s| format!("{:.4}", s * scale)).collect();
                each.join(", ")
            };
            format!(
                "{} rad/s = {} rpm",
                list(1.0),
                list(60.0 / std::f64::consts::TAU)
            )
        }
        None => "– (not computed: singular mass matrix)".to_string(),
    };
    format!("critical speeds    {text} (undamped, weights locked)\n")
}

fn describe(m: &RunMetrics) -> String {
    let opt = |v: Option<f64>| v.map_or("–".to_string(), |x| format!("{x:.4}"));
    let angles: Vec<String> = m
        .final_rel_angles_deg
        .iter()
        .map(|a| format!("{a:.1}"))
        .collect();
    format!(
        "outcome            {}\nreason             {}\nsettled            {}\nsettling time      {} s ({} rev, ± {:.4} s)\nsettling time (ε)  {} s\nresidual           {:.4e} ({:.4} A_ref)\nA_ref              {:.4e}\nbalancing error ε  {:.4e}\npeak r             {:.4e}\nfinal angles       [{}] deg\np final            {:.4}\nsteps, RHS calls   {}, {}\nclosest weights    {}\npack slip rate     {}\n",
        m.outcome.name(),
        m.reason,
        m.settled,
        opt(m.settling_time),
        opt(m.settling_revs),
        m.settling_time_err,
        opt(m.settling_time_eps),
        m.residual_abs,
        m.residual_rel,
        m.a_ref,
        m.balancing_error,
        m.peak_r,
        angles.join(", "),
        m.p_final,
        m.steps,
        m.rhs_calls,
        match (m.min_gap_rad, m.final_min_gap_rad) {
            (Some(low), Some(end)) => format!(
                "{:.3}° beyond touching at the closest, {:.3}° at the end (negative: overlap)",
                low.to_degrees(),
                end.to_degrees()
            ),
            _ => "– (point masses)".to_string(),
        },
        match (m.pack_slip_rate, m.final_spin_rate) {
            (Some(slip), Some(spin)) => format!(
                "{slip:.4} rad/s relative to the rotor at the end ({:.1} % of its speed{})",
                100.0 * slip / spin.abs().max(f64::MIN_POSITIVE),
                if autobal::metrics::circulates(m) {
                    ": the weights circulate"
                } else {
                    ""
                }
            ),
            _ => "–".to_string(),
        }
    )
}
