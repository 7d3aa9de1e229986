//! `autobal-bench`: the benchmark harness of the ODE core and the runner
//! (RHS cost per cargo count, solves per method and tolerance, rotating
//! against full, the SciPy peer's cases, thread scaling, the runs of the
//! lean reference), kept out of the `study` binary a designer runs.
//! docs/benchmarks.md says what each measures and how to run it.

mod bench;
mod bench_cmd;
mod bench_limits;
// The study binary's flag limits, table layout and ending, shared as files so
// both binaries refuse, print and exit alike; this one uses a part of them.
#[allow(dead_code)]
#[path = "../study/limits.rs"]
mod limits;
#[allow(dead_code, unused_imports)]
#[path = "../study/output.rs"]
mod output;
#[allow(dead_code)]
#[path = "../study/user_error.rs"]
mod user_error;

use clap::Parser;
use std::process::ExitCode;
pub use user_error::UserError;

/// Time autobal's ODE core and runner.
#[derive(Parser)]
#[command(
    name = "autobal-bench",
    version = autobal::build_info::VERSION_LINE,
    about = "Time autobal's ODE core and runner: RHS cost per weight count, solves per method and tolerance, rotating against full, the SciPy peer's cases, thread scaling, the lean reference's runs.",
    long_about = None,
    after_help = bench_cmd::EXAMPLES
)]
struct Cli {
    #[command(flatten)]
    args: bench_cmd::BenchArgs,
}

fn main() -> ExitCode {
    user_error::end_quietly_on_closed_pipe();
    let cli: Cli = user_error::parse_args();
    user_error::exit_code(bench_cmd::run(&cli.args))
}
