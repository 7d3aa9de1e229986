//! `study map`: linear stability of a scene's balanced state over a grid of
//! speeds and unbalances, as a Parquet table and a character picture.

use crate::UserError;
use autobal::output_file::{WhenExists, prepare};
use autobal::scene_file::SceneFile;
use autobal::study::results::io::{Provenance, write_parquet};
use autobal::study::stability_map::{ascii, stability_map, to_dataframe};
use autobal::study::sweep::speed_grid;
use clap::Args;
use std::path::PathBuf;

/// Examples shown under `study map --help`.
pub const EXAMPLES: &str = "Examples:
  study map scenes/flexible_meraz.toml --omega 0.1..3 --unbalance 0.0005..0.0195 --points 59x39
  study map scenes/flexible_meraz.toml --omega 0.1..3 --unbalance 0.0005..0.0195 --out map.parquet";

/// Arguments of `study map`.
#[derive(Args)]
pub struct MapArgs {
    /// Scene file (TOML); speed and rotor unbalance are replaced at each grid point.
    scene: PathBuf,
    /// Speed range `lo..hi` (rad/s).
    #[arg(long)]
    omega: String,
    /// Unbalance range `lo..hi` (kg·m): the plane and flexible rotors' M e.
    #[arg(long)]
    unbalance: String,
    /// Grid size `speeds x unbalances`.
    #[arg(long, default_value = "59x39")]
    points: String,
    /// Write one row per grid point to this Parquet file.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace the --out file if it exists.
    #[arg(long, requires = "out")]
    overwrite: bool,
}

fn parse_range(name: &str, text: &str) -> Result<(f64, f64), UserError> {
    crate::limits::range(name, text, true, None).map_err(|e| UserError(e, 2))
}

/// Run `study map`.
pub fn run(args: &MapArgs) -> Result<(), UserError> {
    let (w_lo, w_hi) = crate::limits::speed_range("omega", &args.omega, true, None, 1.0)
        .map_err(|e| UserError(e, 2))?;
    let (u_lo, u_hi) = parse_range("unbalance", &args.unbalance)?;
    let bad = || {
        UserError(
            format!("--points {}: expected e.g. 59x39 (each ≥ 2)", args.points),
            2,
        )
    };
    let (a, b) = args.points.split_once('x').ok_or_else(bad)?;
    let (nw, nu): (usize, usize) = (a.parse().map_err(|_| bad())?, b.parse().map_err(|_| bad())?);
    if nw < 2 || nu < 2 {
        return Err(bad());
    }
    if nw.saturating_mul(nu) > crate::limits::MAX_MAP_POINTS {
        return Err(UserError(
            format!(
                "--points {}: {} points, more than the {} a map may hold (each point is a whole run)",
                args.points,
                nw.saturating_mul(nu),
                crate::limits::MAX_MAP_POINTS
            ),
            2,
        ));
    }
    if let Some(path) = &args.out {
        prepare("--out", path, WhenExists::from_overwrite(args.overwrite))?;
    }
    let shown = args.scene.display().to_string();
    let file = SceneFile::read(&args.scene)?;
    let scene = file.simulation(&shown)?.scene;
    let points = stability_map(
        &scene,
        &speed_grid(w_lo, w_hi, nw),
        &speed_grid(u_lo, u_hi, nu),
    )?;
    if let Some(path) = &args.out {
        let text = autobal::input_file::read_text(&args.scene)?;
        let mut df = to_dataframe(&points).map_err(|e| UserError::internal(e.to_string()))?;
        write_parquet(path, &mut df, &Provenance::new(&text, 0, "stability map"))
            .map_err(|e| UserError::internal(format!("--out {e}")))?;
    }
    crate::output::say(&format!(
        "unbalance {u_hi} (top) to {u_lo} (bottom), speed {w_lo} (left) to {w_hi} (right)\n'#' stable balanced state, '.' unstable, ' ' unbalance beyond the balancer's capacity\n"
    ));
    print!("{}", ascii(&points, nw));
    Ok(())
}
