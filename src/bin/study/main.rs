//! `study`: the command-line face of autobal. Parses arguments, calls the
//! library, prints results on stdout and errors on stderr (exit code 2 for
//! bad input).

mod calibrate_cmd;
mod check_cmd;
mod claims_cmd;
mod compare_cmd;
mod completion_values;
mod criterion_cmd;
mod design_cmd;
mod limits;
mod linear_cmd;
mod map_cmd;
mod meta_cmd;
mod optimize_cmd;
mod output;
mod plot_cmd;
mod progress;
mod report_cmd;
mod robustness_notes;
mod run_cmd;
mod sensitivity_cmd;
mod simulate_cmd;
mod simulate_draws_cmd;
mod stepped_bands_cmd;
mod stepped_cmd;
mod sweep_cmd;
mod tradeoff_cmd;
mod user_error;

use clap::{CommandFactory, Parser, Subcommand};
use std::process::ExitCode;
pub use user_error::UserError;

/// Design passive auto-balancers by virtual experiment.
#[derive(Parser)]
#[command(
    name = "study",
    version = autobal::build_info::VERSION_LINE,
    about,
    long_about = None,
    after_help = "Exit codes: 0 done; 1 a run or a check failed (e.g. a regression, a solver that did not converge); 2 bad input or usage (the message names the key or flag), nothing written; 130 interrupted (finished runs saved; continue with --resume)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Print tables and notes at full width instead of fitting the terminal (80 columns off a terminal).
    #[arg(long, global = true)]
    wide: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Run a Monte Carlo study: every design × sample, statistics, Parquet files.
    #[command(after_help = run_cmd::RUN_EXAMPLES)]
    Run(run_cmd::RunArgs),
    /// Merge the outputs of `study run --shard k/N` into one study's files.
    #[command(after_help = run_cmd::MERGE_EXAMPLES)]
    Merge(run_cmd::MergeArgs),
    /// Simulate one scene and print settling time, residual vibration and more.
    #[command(after_help = simulate_cmd::EXAMPLES)]
    Simulate(simulate_cmd::SimulateArgs),
    /// Analytic design table (Table 1 of seed 000): optimal radius, capacity, p_max, ã.
    #[command(after_help = design_cmd::EXAMPLES)]
    Design(design_cmd::DesignArgs),
    /// Optimise weight count, radius (and drag) for an analytic or simulated objective.
    #[command(after_help = optimize_cmd::EXAMPLES)]
    Optimize(optimize_cmd::OptimizeArgs),
    /// Compare two designs (of one results folder or two): paired when they met the same unbalances.
    #[command(after_help = compare_cmd::EXAMPLES)]
    Compare(compare_cmd::CompareArgs),
    /// Put seed 000's design claims to a virtual experiment and write a report.
    #[command(after_help = claims_cmd::EXAMPLES)]
    Claims(claims_cmd::ClaimsArgs),
    /// Measure speed against accuracy for every fidelity and tolerance on a study's runs.
    #[command(after_help = tradeoff_cmd::EXAMPLES)]
    Tradeoff(tradeoff_cmd::TradeoffArgs),
    /// Which sampled input (unbalance, start, tolerances, uncertain keys) explains each design's spread: Sobol indices.
    #[command(after_help = sensitivity_cmd::EXAMPLES)]
    Sensitivity(sensitivity_cmd::SensitivityArgs),
    /// Fit a rig's unknowns to its measured points: intervals, and predictions of the points held out.
    #[command(after_help = calibrate_cmd::EXAMPLES)]
    Calibrate(calibrate_cmd::CalibrateArgs),
    /// Compare a fresh run of a study with its baseline: KS, Fisher and Mood tests, Holm; exit 1 on a regression.
    #[command(after_help = check_cmd::CHECK_EXAMPLES)]
    Check(check_cmd::CheckArgs),
    /// Run a study and write (or refresh) its baseline for `study check`, with provenance.
    #[command(after_help = check_cmd::BASELINE_EXAMPLES)]
    Baseline(check_cmd::BaselineArgs),
    /// Figures as SVG or PNG: one run, one study, design curves, work–precision.
    #[command(after_help = plot_cmd::EXAMPLES)]
    Plot(plot_cmd::PlotArgs),
    /// Linear stability of a scene's balanced state: eigenvalues, slowest decay rate.
    #[command(after_help = linear_cmd::EXAMPLES)]
    Linear(linear_cmd::LinearArgs),
    /// Seed 003's criterion for a rotor on two supports: resonances, extra speeds, balancing ranges.
    #[command(after_help = criterion_cmd::EXAMPLES)]
    Criterion(criterion_cmd::CriterionArgs),
    /// Simulate one scene over a grid of speeds next to the criterion and linear stability.
    #[command(after_help = sweep_cmd::EXAMPLES)]
    Sweep(sweep_cmd::SweepArgs),
    /// Stepped speed sweep carrying the state, run-up then run-down, as rigs are measured.
    #[command(after_help = stepped_cmd::EXAMPLES)]
    Stepped(stepped_cmd::SteppedArgs),
    /// Stability map of the balanced state over speed and unbalance (Parquet and a character picture).
    #[command(after_help = map_cmd::EXAMPLES)]
    Map(map_cmd::MapArgs),
    /// Write one self-contained HTML report of a finished study: ranking, verdicts, figures, provenance.
    #[command(after_help = report_cmd::EXAMPLES)]
    Report(report_cmd::ReportArgs),
    /// Print a shell completion script (bash, zsh, fish, powershell, elvish).
    #[command(after_help = meta_cmd::COMPLETIONS_EXAMPLES)]
    Completions(meta_cmd::CompletionsArgs),
    /// Print the man page (roff) of `study`.
    #[command(after_help = meta_cmd::MAN_EXAMPLES)]
    Man,
    /// Print the JSON Schema of study or scene files, for editors and validators.
    #[command(after_help = meta_cmd::SCHEMA_EXAMPLES)]
    Schema(meta_cmd::SchemaArgs),
}

fn main() -> ExitCode {
    user_error::end_quietly_on_closed_pipe();
    let cli: Cli = user_error::parse_args();
    output::set_wide(cli.wide);
    let result = match cli.command {
        Command::Design(args) => design_cmd::run(&args),
        Command::Criterion(args) => criterion_cmd::run(&args),
        Command::Simulate(args) => simulate_cmd::run(&args),
        Command::Linear(args) => linear_cmd::run(&args),
        Command::Sweep(args) => sweep_cmd::run(&args),
        Command::Map(args) => map_cmd::run(&args),
        Command::Stepped(args) => stepped_cmd::run(&args),
        Command::Run(args) => run_cmd::run(&args),
        Command::Merge(args) => run_cmd::merge_shards(&args),
        Command::Optimize(args) => optimize_cmd::run(&args),
        Command::Claims(args) => claims_cmd::run(&args),
        Command::Compare(args) => compare_cmd::run(&args),
        Command::Tradeoff(args) => tradeoff_cmd::run(&args),
        Command::Sensitivity(args) => sensitivity_cmd::run(&args),
        Command::Calibrate(args) => calibrate_cmd::run(&args),
        Command::Plot(args) => plot_cmd::run(&args),
        Command::Report(args) => report_cmd::run(&args),
        Command::Check(args) => check_cmd::check(&args),
        Command::Baseline(args) => check_cmd::baseline(&args),
        Command::Completions(args) => meta_cmd::completions(&args, Cli::command()),
        Command::Man => meta_cmd::man(Cli::command()),
        Command::Schema(args) => meta_cmd::schema(&args),
    };
    user_error::exit_code(result)
}
