//! `study sweep`: one scene over a grid of constant speeds, simulated and
//! compared with the criterion's prediction and linear stability.

use crate::UserError;
use autobal::output_file::{WhenExists, prepare};
use autobal::scene_file::SceneFile;
use autobal::study::results::io::{Provenance, write_parquet};
use autobal::study::sweep::{SweepPoint, ranges, run_sweep, speed_grid, to_dataframe};
use clap::Args;
use std::path::PathBuf;

/// Examples shown under `study sweep --help`.
pub const EXAMPLES: &str = "Examples:
  study sweep scenes/two_support_single.toml --omega 0.5..8 --points 61
  study sweep scenes/two_support_long.toml --omega 1..8 --points 29 --out sweep.parquet";

/// Arguments of `study sweep`.
#[derive(Args)]
pub struct SweepArgs {
    /// Scene file (TOML); its speed law is replaced by each constant speed.
    scene: PathBuf,
    /// Speed range `lo..hi` (rad/s).
    #[arg(long)]
    omega: String,
    /// Number of speeds, evenly spaced, ends included.
    #[arg(long, default_value_t = 41, value_parser = crate::limits::sweep_points)]
    points: usize,
    /// Write one row per speed to this Parquet file.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace the --out file if it exists.
    #[arg(long, requires = "out")]
    overwrite: bool,
    /// Print the points as JSON instead of a table.
    #[arg(long)]
    json: bool,
}

fn parse_range(text: &str) -> Result<(f64, f64), UserError> {
    crate::limits::speed_range("omega", text, false, Some("0.5..8"), 1.0)
        .map_err(|e| UserError(e, 2))
}

/// Run `study sweep`.
pub fn run(args: &SweepArgs) -> Result<(), UserError> {
    let (lo, hi) = parse_range(&args.omega)?;
    if let Some(path) = &args.out {
        prepare("--out", path, WhenExists::from_overwrite(args.overwrite))?;
    }
    let shown = args.scene.display().to_string();
    let file = SceneFile::read(&args.scene)?;
    let simulation = file.simulation(&shown)?;
    let points = run_sweep(&simulation, &speed_grid(lo, hi, args.points))?;
    if let Some(path) = &args.out {
        let text = autobal::input_file::read_text(&args.scene)?;
        let provenance = Provenance::new(&text, 0, "sweep");
        let mut df = to_dataframe(&points).map_err(|e| UserError::internal(e.to_string()))?;
        write_parquet(path, &mut df, &provenance)
            .map_err(|e| UserError::internal(format!("--out {e}")))?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&points)?);
    } else {
        print!("{}", describe(&points));
    }
    Ok(())
}

fn describe(points: &[SweepPoint]) -> String {
    let yn = |b: Option<bool>| match b {
        Some(true) => "yes",
        Some(false) => "no",
        None => "–",
    };
    let rows: Vec<Vec<String>> = points
        .iter()
        .map(|p| {
            vec![
                format!("{:.4}", p.omega),
                yn(Some(p.criterion)).to_string(),
                yn(p.closed_form).to_string(),
                yn(p.linear_stable).to_string(),
                p.slowest_decay.map_or("–".into(), |v| format!("{v:.3e}")),
                p.outcome.name().to_string(),
                p.settling_time.map_or("–".into(), |v| format!("{v:.2}")),
                format!("{:.2e}", p.balancing_error),
            ]
        })
        .collect();
    let mut s = crate::output::text_table(
        &[
            "ω\nrad/s",
            "criterion",
            "closed\nform",
            "linear\nstable",
            "slowest\ndecay σ",
            "outcome",
            "t_s\ns",
            "ε",
        ],
        &rows,
    );
    let show = |r: Vec<(f64, f64)>| {
        if r.is_empty() {
            "none".to_string()
        } else {
            r.iter()
                .map(|(a, b)| format!("[{a:.3}, {b:.3}]"))
                .collect::<Vec<_>>()
                .join(" ∪ ")
        }
    };
    s += &format!(
        "\nbalancing predicted by the criterion   {}\n",
        show(ranges(points, |p| p.criterion))
    );
    if points.iter().any(|p| p.closed_form.is_some()) {
        s += &format!(
            "closed form of seed 003                {}\n",
            show(ranges(points, |p| p.closed_form == Some(true)))
        );
        // The closed form is undamped, the criterion uses the damped
        // response: where they part, say why rather than leave a puzzle.
        if points
            .iter()
            .any(|p| p.closed_form.is_some_and(|c| c != p.criterion))
        {
            s += "  (they differ where the supports' damping moves an edge: the closed form is the undamped limit)\n";
        }
    }
    // "none" would claim an analysis that never ran: say so instead.
    let linear = if points.iter().any(|p| p.linear_stable.is_some()) {
        show(ranges(points, |p| p.linear_stable == Some(true)))
    } else {
        "– (not analysed at any speed: the rotating frame does not hold for this scene; `study linear` says why)".to_string()
    };
    s += &format!(
        "balanced state linearly stable         {linear}\nbalancing simulated (settled)          {}\n",
        show(ranges(points, |p| p.settled))
    );
    s
}
