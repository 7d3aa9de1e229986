//! `study linear`: linear stability of a scene's balanced state.

use crate::UserError;
use autobal::model::linear::{LinearError, LinearReport, analyse};
use autobal::scene_file::SceneFile;
use clap::Args;
use std::path::PathBuf;

/// Examples shown under `study linear --help`.
pub const EXAMPLES: &str = "Examples:
  study linear scenes/three_balls.toml
  study linear scenes/two_support_long.toml --json";

/// Arguments of `study linear`.
#[derive(Args)]
pub struct LinearArgs {
    /// Scene file (TOML) with a constant speed law and isotropic supports.
    scene: PathBuf,
    /// Print the report (every eigenvalue included) as one JSON object.
    #[arg(long)]
    json: bool,
}

/// Run `study linear`.
pub fn run(args: &LinearArgs) -> Result<(), UserError> {
    let shown = args.scene.display().to_string();
    let file = SceneFile::read(&args.scene)?;
    let simulation = file.simulation(&shown)?;
    let system = simulation.scene.build()?;
    // A solver that could not converge is a failed run (exit 1), not bad
    // input; either way the message names the scene.
    let report = analyse(&system, None).map_err(|e| match e {
        LinearError::EigenvaluesDidNotConverge { .. } | LinearError::NoSteadyState(_) => {
            UserError::internal(format!("{shown}: {e}"))
        }
        _ => UserError(format!("{shown}: {e}"), 2),
    })?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        let critical = autobal::model::critical_speeds::critical_speeds_in_range(&system);
        let text = format!(
            "{}{}",
            describe(&report, simulation.metrics.delta),
            crate::simulate_cmd::critical_speeds_line(critical.as_deref())
        );
        print!(
            "{}",
            crate::output::wrap(&text, crate::output::text_width())
        );
    }
    Ok(())
}

fn describe(r: &LinearReport, delta: f64) -> String {
    let predicted = if r.stable {
        format!("{:.4} s", r.settling_time(1.0, delta))
    } else {
        "–".into()
    };
    format!(
        "speed ω            {:.4} rad/s\nstable             {}\nslowest decay σ    {:.4e} 1/s (λ = {:.4e} {:+.4e}i)\nln(1/δ)/σ          {predicted} (δ = {delta})\nneutral directions {}\nbalancing error ε  {:.3e}\neigenvalue count   {} (--json lists them)\n",
        r.omega,
        r.stable,
        r.slowest_decay,
        r.slowest.0,
        r.slowest.1,
        r.neutral,
        r.balancing_error,
        r.eigenvalues.len()
    )
}
