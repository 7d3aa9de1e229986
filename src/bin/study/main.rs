//! `study`: the command-line face of autobal. Parses arguments, calls the
//! library, prints results on stdout and errors on stderr (exit code 2 for
//! bad input).

mod bench_cmd;
mod design_cmd;
mod output;
mod simulate_cmd;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Design passive auto-balancers by virtual experiment.
#[derive(Parser)]
#[command(name = "study", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Analytic design table (Table 1 of seed 000): optimal radius, capacity, p_max, ã.
    #[command(after_help = design_cmd::EXAMPLES)]
    Design(design_cmd::DesignArgs),
    /// Simulate one scene and print settling time, residual vibration and more.
    #[command(after_help = simulate_cmd::EXAMPLES)]
    Simulate(simulate_cmd::SimulateArgs),
    /// Time the ODE core: RHS cost per cargo count, solves per method and tolerance.
    #[command(after_help = bench_cmd::EXAMPLES)]
    Bench(bench_cmd::BenchArgs),
}

/// An error the user caused (bad input): printed and mapped to exit code 2.
pub struct UserError(pub String);

impl<E: std::fmt::Display> From<E> for UserError {
    fn from(e: E) -> Self {
        UserError(e.to_string())
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Design(args) => design_cmd::run(&args),
        Command::Simulate(args) => simulate_cmd::run(&args),
        Command::Bench(args) => bench_cmd::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(UserError(message)) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}
