//! `study completions`, `study man` and `study schema`: the tool describing
//! itself to the shell, to `man` and to editors, generated from the same
//! clap definitions as `--help` and the same types as the file parsers so
//! that they cannot drift from them.

use crate::UserError;
use clap::{Args, ValueEnum};
use clap_complete::Shell;
use std::io::Write;

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

/// Examples shown under `study schema --help`.
pub const SCHEMA_EXAMPLES: &str = "Examples:
  study schema study > study.schema.json
  study schema scene > scene.schema.json
The shipped files are schema/study.schema.json and schema/scene.schema.json;
a first line `#:schema ../schema/study.schema.json` in a TOML file points
taplo (Even Better TOML) at one (docs/study-file.md, docs/scene-file.md).";

/// Arguments of `study schema`.
#[derive(Args)]
pub struct SchemaArgs {
    /// Which file: a study (`study run`) or a scene (`study simulate`).
    file: SchemaFile,
}

/// The file kinds that have a schema.
#[derive(Clone, Copy, ValueEnum)]
enum SchemaFile {
    /// A study file.
    Study,
    /// A scene file.
    Scene,
}

/// Print the JSON Schema of `args.file` on stdout.
pub fn schema(args: &SchemaArgs) -> Result<(), UserError> {
    let schema = match args.file {
        SchemaFile::Study => autobal::schema::study_schema(),
        SchemaFile::Scene => autobal::schema::scene_schema(),
    };
    let text = serde_json::to_string_pretty(&schema)
        .map_err(|e| UserError::internal(format!("cannot format the schema: {e}")))?;
    match writeln!(std::io::stdout(), "{text}") {
        // `study schema study | head` closing the pipe early is not a failure.
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(UserError::internal(format!("cannot write the schema: {e}")))
        }
        _ => Ok(()),
    }
}

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
