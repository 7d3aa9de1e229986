//! How a verb starts and ends: its arguments parsed with help wrapped to the
//! terminal, an error printed on stderr with its exit code (2 for bad input,
//! 1 for internal failures), and a closed pipe ending the verb quietly.
//! Shared with the benchmark binary, so both start and end alike.

use std::process::ExitCode;

/// An error: printed on stderr; exit code 2 for bad input, 1 for internal failures.
pub struct UserError(pub String, pub u8);

impl UserError {
    /// A failure that is not the user's fault (exit code 1).
    pub fn internal(message: String) -> Self {
        UserError(message, 1)
    }
}

impl<E: std::fmt::Display> From<E> for UserError {
    fn from(e: E) -> Self {
        UserError(e.to_string(), 2)
    }
}

/// The command line parsed, help text wrapped at words to the terminal (80
/// columns off a terminal); a usage error exits as clap decides.
pub fn parse_args<C: clap::CommandFactory + clap::FromArgMatches>() -> C {
    let matches = C::command()
        .term_width(crate::output::terminal_columns())
        .get_matches();
    match C::from_arg_matches(&matches) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    }
}

/// Printing to a closed pipe ends the process instead of panicking.
pub fn end_quietly_on_closed_pipe() {
    // Rust ignores SIGPIPE, so printing to a closed pipe would panic; a
    // filter such as `| head` should end the verb quietly instead. Every
    // verb writes its files before it prints, so nothing is left half-written.
    // SAFETY: setting a signal's disposition to its default before any
    // thread starts has no other effect.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// The process's exit code for a verb's result, its error printed on stderr.
pub fn exit_code(result: Result<(), UserError>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(UserError(message, code)) => {
            // Wrapped on a terminal; whole on one line in a log or a pipe,
            // where scripts and tests search it.
            let line = format!("error: {message}");
            if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
                eprint!(
                    "{}",
                    crate::output::wrap(&line, crate::output::text_width())
                );
            } else {
                eprintln!("{line}");
            }
            ExitCode::from(code)
        }
    }
}
