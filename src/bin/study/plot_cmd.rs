//! `study plot`: figures of one run, one study, the design curves and the
//! trade-off study, as SVG or PNG (by the extension of `--out`).

use crate::UserError;
use crate::design_cmd::{Counts, KindArg, parse_counts};
use autobal::design::Shape;
use autobal::plot::design::plot_design;
use autobal::plot::run::{RunFigure, plot_run};
use autobal::plot::study::{StudyData, StudyFigure, plot_study};
use autobal::plot::tradeoff::{plot_work_precision, read_tradeoff};
use autobal::plot::{Format, PlotError};
use autobal::scene_file::SceneFile;
use clap::{Args, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};

/// Examples shown under `study plot --help`.
pub const EXAMPLES: &str = "Examples:
  study plot run scenes/three_balls.toml --out run.svg
  study plot study results/three_balls --out figures/ --format png
  study plot study results/three_balls --out docs/figures/three_balls --only settling-time
  study plot design --kind ball --n 1..8 --out design.svg
  study plot tradeoff results/three_balls/tradeoff.parquet --out wp.png
  study plot map results/flexible_map.parquet --out map.png

The format follows the extension of --out (.svg or .png); `plot study` writes
settling_time, settled_fraction and settling_vs_unbalance into the --out folder.";

/// Arguments of `study plot`.
#[derive(Args)]
pub struct PlotArgs {
    #[command(subcommand)]
    figure: Figure,
}

#[derive(Subcommand)]
enum Figure {
    /// Simulate one scene and plot r(t)/A_ref, the cargo angles and ε(t).
    Run(RunArgs),
    /// Plot a study's settling times, settled fractions and settling vs unbalance.
    Study(StudyArgs),
    /// Plot the capacity s(ρ) per n with the Table-1 optima, and ã(n) (Fig. 7).
    Design(DesignArgs),
    /// Plot the work–precision diagram of a trade-off table (error vs cost per fidelity).
    Tradeoff(TradeoffArgs),
    /// Plot the stability map written by `study map --out` (speed × unbalance).
    Map(MapArgs),
}

#[derive(Args)]
struct MapArgs {
    /// Parquet table written by `study map --out`.
    table: PathBuf,
    /// Output file: .svg or .png.
    #[arg(long)]
    out: PathBuf,
    /// Figure title.
    #[arg(long, default_value = "Stability map of the balanced state")]
    title: String,
}

#[derive(Args)]
struct RunArgs {
    /// Scene file (TOML), as for `study simulate`.
    scene: PathBuf,
    /// Output file: .svg or .png.
    #[arg(long)]
    out: PathBuf,
    /// Figure title (default: the scene file's name).
    #[arg(long)]
    title: Option<String>,
}

#[derive(Args)]
struct StudyArgs {
    /// Output folder of `study run` (holds runs.parquet and summary.parquet).
    dir: PathBuf,
    /// Folder for the three figures (created if missing).
    #[arg(long)]
    out: PathBuf,
    /// Image format of the figures.
    #[arg(long, value_enum, default_value = "svg")]
    format: FormatArg,
    /// Write only this figure (default: all three, `passage` when the study
    /// sweeps the stall torque, `sensitivity` when `study sensitivity` ran).
    #[arg(long, value_enum)]
    only: Option<StudyFigureArg>,
}

#[derive(Clone, Copy, ValueEnum)]
enum StudyFigureArg {
    SettlingTime,
    SettledFraction,
    SettlingVsUnbalance,
    Passage,
    Sensitivity,
}

impl From<StudyFigureArg> for StudyFigure {
    fn from(f: StudyFigureArg) -> Self {
        match f {
            StudyFigureArg::SettlingTime => StudyFigure::SettlingTime,
            StudyFigureArg::SettledFraction => StudyFigure::SettledFraction,
            StudyFigureArg::SettlingVsUnbalance => StudyFigure::SettlingVsUnbalance,
            StudyFigureArg::Passage => StudyFigure::Passage,
            StudyFigureArg::Sensitivity => StudyFigure::Sensitivity,
        }
    }
}

#[derive(Args)]
struct DesignArgs {
    /// Weight shape; both (one row each) when omitted.
    #[arg(long, value_enum)]
    kind: Option<KindArg>,
    /// Weight counts: a single value (3), an inclusive range (1..8) or a list (2,3,5).
    #[arg(long, default_value = "1..8", value_parser = parse_counts)]
    n: Counts,
    /// Output file: .svg or .png.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args)]
struct TradeoffArgs {
    /// Parquet table with columns fidelity, rtol, settling_error_revs, rhs_calls, wall_time_s.
    table: PathBuf,
    /// Output file: .svg or .png.
    #[arg(long)]
    out: PathBuf,
    /// Figure title.
    #[arg(long, default_value = "Work–precision: settling-time error vs cost")]
    title: String,
}

#[derive(Clone, Copy, ValueEnum)]
enum FormatArg {
    Svg,
    Png,
}

/// Run `study plot`.
pub fn run(args: &PlotArgs) -> Result<(), UserError> {
    let written = match &args.figure {
        Figure::Run(a) => plot_one_run(a)?,
        Figure::Study(a) => plot_one_study(a)?,
        Figure::Design(a) => {
            check_out(&a.out)?;
            let shapes: Vec<Shape> = match a.kind {
                Some(k) => vec![k.into()],
                None => Shape::ALL.to_vec(),
            };
            plot_design(&shapes, &a.n.0, &a.out).map_err(write_error("--out", &a.out))?;
            vec![a.out.clone()]
        }
        Figure::Map(a) => {
            check_out(&a.out)?;
            let points = autobal::plot::map::read_map(&a.table).map_err(plot_error)?;
            autobal::plot::map::plot_stability_map(&points, &a.title, &a.out)
                .map_err(write_error("--out", &a.out))?;
            vec![a.out.clone()]
        }
        Figure::Tradeoff(a) => {
            check_out(&a.out)?;
            let points = read_tradeoff(&a.table).map_err(plot_error)?;
            plot_work_precision(&points, &a.title, &a.out).map_err(write_error("--out", &a.out))?;
            vec![a.out.clone()]
        }
    };
    for path in written {
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn plot_one_run(a: &RunArgs) -> Result<Vec<PathBuf>, UserError> {
    check_out(&a.out)?;
    let shown = a.scene.display().to_string();
    let simulation = SceneFile::read(&a.scene)?.simulation(&shown)?;
    let result = simulation.run(true)?;
    let title = a.title.clone().unwrap_or_else(|| {
        let name = a
            .scene
            .file_stem()
            .map_or(shown.clone(), |s| s.to_string_lossy().into_owned());
        format!("{name}: one run ({})", result.metrics.outcome.name())
    });
    let figure = RunFigure::new(&simulation, &result, &title).map_err(plot_error)?;
    plot_run(&figure, &a.out).map_err(write_error("--out", &a.out))?;
    Ok(vec![a.out.clone()])
}

fn plot_one_study(a: &StudyArgs) -> Result<Vec<PathBuf>, UserError> {
    if !a.dir.is_dir() {
        return Err(UserError(
            format!(
                "{}: not a folder (give the output folder of `study run`)",
                a.dir.display()
            ),
            2,
        ));
    }
    autobal::output_file::prepare_folder("--out", &a.out)?;
    let data = StudyData::read(&a.dir).map_err(plot_error)?;
    let format = match a.format {
        FormatArg::Svg => Format::Svg,
        FormatArg::Png => Format::Png,
    };
    let figures: Vec<StudyFigure> = match a.only {
        Some(f) => vec![f.into()],
        None => {
            let mut all = StudyFigure::ALL.to_vec();
            // The passage figure only where the study sweeps the stall
            // torque, the indices only where `study sensitivity` ran.
            if data.runs.iter().any(|r| r.stall_torque.is_some()) {
                all.push(StudyFigure::Passage);
            }
            if !data.sensitivity.is_empty() {
                all.push(StudyFigure::Sensitivity);
            }
            all
        }
    };
    plot_study(&data, &a.out, format, &figures).map_err(write_error("--out", &a.out))
}

/// Reject a bad --out before any work: wrong extension or missing folder.
fn check_out(out: &Path) -> Result<(), UserError> {
    check_figure_path("--out", out)
}

/// Reject a bad figure path given with `flag` before any work: wrong
/// extension, a folder, a missing or unwritable folder. An existing figure
/// is redrawn (docs/limits.md, "Output policy").
pub(crate) fn check_figure_path(flag: &str, out: &Path) -> Result<(), UserError> {
    Format::from_path(out).map_err(|e| UserError(format!("{flag} {e}"), 2))?;
    autobal::output_file::prepare(flag, out, autobal::output_file::WhenExists::Replace)?;
    Ok(())
}

/// [`plot_error`] for drawing into `out`: a failure to write the file
/// names the flag and the path (the folder went away, a disk filled up).
pub(crate) fn write_error(flag: &'static str, out: &Path) -> impl Fn(PlotError) -> UserError {
    let shown = out.display().to_string();
    move |e| match e {
        PlotError::Io(_) | PlotError::NoFolder(_) => {
            UserError(format!("{flag} {shown}: cannot write the figure: {e}"), 2)
        }
        other => plot_error(other),
    }
}

/// Drawing and font failures are ours (exit 1); everything else is the input's (exit 2).
pub(crate) fn plot_error(e: PlotError) -> UserError {
    match e {
        PlotError::Draw(_) | PlotError::Font => UserError::internal(e.to_string()),
        other => UserError(other.to_string(), 2),
    }
}
