//! `study completions` and `study man`: the tool describing itself to the
//! shell and to `man`, generated from the same clap definitions as `--help`
//! so that they cannot drift from it.

use crate::UserError;
use clap::Args;
use clap_complete::Shell;

/// Examples shown under `study completions --help`.
pub const COMPLETIONS_EXAMPLES: &str = "Examples:
  study completions bash > ~/.local/share/bash-completion/completions/study
  study completions zsh > ~/.zfunc/_study        (with fpath+=(~/.zfunc) in ~/.zshrc)
  study completions fish > ~/.config/fish/completions/study.fish
  study completions powershell >> $PROFILE";

/// Examples shown under `study man --help`.
pub const MAN_EXAMPLES: &str = "Examples:
  study man > study.1 && man ./study.1
  study man > ~/.local/share/man/man1/study.1";

/// Arguments of `study completions`.
#[derive(Args)]
pub struct CompletionsArgs {
    /// The shell: bash, zsh, fish, powershell or elvish.
    shell: Shell,
}

/// Print the completion script for `args.shell` on stdout.
pub fn completions(args: &CompletionsArgs, mut command: clap::Command) -> Result<(), UserError> {
    clap_complete::generate(args.shell, &mut command, "study", &mut std::io::stdout());
    Ok(())
}

/// Print the man page (roff) on stdout.
pub fn man(command: clap::Command) -> Result<(), UserError> {
    match clap_mangen::Man::new(command).render(&mut std::io::stdout()) {
        // `study man | head` closing the pipe early is not a failure.
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(UserError::internal(format!(
            "cannot write the man page: {e}"
        ))),
        _ => Ok(()),
    }
}
