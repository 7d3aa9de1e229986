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

/// Print the man page (roff) on stdout: one page for the tool and every
/// verb (clap_mangen's own page points to study-run(1) and others that do
/// not exist), ASCII-only roff, the short version in the footer.
pub fn man(command: clap::Command) -> Result<(), UserError> {
    let mut page = Vec::new();
    man_page(command, &mut page)
        .map_err(|e| UserError::internal(format!("cannot render the man page: {e}")))?;
    let text = ascii_roff(&String::from_utf8_lossy(&page));
    match std::io::stdout().write_all(text.as_bytes()) {
        // `study man | head` closing the pipe early is not a failure.
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(UserError::internal(format!(
            "cannot write the man page: {e}"
        ))),
        _ => Ok(()),
    }
}

/// The roff of the whole page: title, name, synopsis, description and
/// options of `study`, then a COMMANDS section with each verb's synopsis,
/// description and options (a verb's own verbs, as `plot run`, below it),
/// then the exit codes and the full version.
fn man_page(mut command: clap::Command, out: &mut Vec<u8>) -> std::io::Result<()> {
    command.build();
    // The footer's fields hold a short version (clap_mangen's default put the
    // whole version line, commit and all, over the date field); the full
    // line goes to the VERSION section, where there is room. The date field
    // must not be empty: roff would shift the fields after it.
    let man = clap_mangen::Man::new(command.clone())
        .date(format!("autobal {}", env!("CARGO_PKG_VERSION")))
        .source("autobal")
        .manual("autobal manual");
    man.render_title(out)?;
    man.render_name_section(out)?;
    man.render_synopsis_section(out)?;
    man.render_description_section(out)?;
    man.render_options_section(out)?;
    out.extend_from_slice(b".SH COMMANDS\n");
    for verb in command.get_subcommands().filter(|c| !c.is_hide_set()) {
        verb_section(verb, "study", out)?;
    }
    man.render_extra_section(out)?;
    man.render_version_section(out)?;
    Ok(())
}

/// One verb as a subsection: `.SS study <verb>`, its synopsis, what it
/// does and its options; its own verbs follow.
fn verb_section(verb: &clap::Command, parent: &str, out: &mut Vec<u8>) -> std::io::Result<()> {
    let name = format!("{parent} {}", verb.get_name());
    let command = verb.clone().bin_name(&name);
    let man = clap_mangen::Man::new(command);
    writeln!(out, ".SS \"{name}\"")?;
    let mut part = Vec::new();
    man.render_synopsis_section(&mut part)?;
    man.render_description_section(&mut part)?;
    man.render_options_section(&mut part)?;
    // The parts' own .SH headings would end the COMMANDS section.
    let text = String::from_utf8_lossy(&part);
    for line in text.lines() {
        if line.starts_with(".SH ") {
            out.extend_from_slice(b".PP\n");
        } else {
            writeln!(out, "{line}")?;
        }
    }
    for sub in verb.get_subcommands().filter(|c| !c.is_hide_set()) {
        verb_section(sub, &name, out)?;
    }
    Ok(())
}

/// Roff that plain `groff -man` renders right: every non-ASCII character
/// as a groff Unicode escape (`ρ` as `\[u03C1]`).
fn ascii_roff(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_ascii() {
            out.push(c);
        } else {
            out.push_str(&format!("\\[u{:04X}]", c as u32));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::ascii_roff;

    #[test]
    fn non_ascii_becomes_groff_escapes() {
        assert_eq!(
            ascii_roff("ρ = 0.3, 2 × 3"),
            "\\[u03C1] = 0.3, 2 \\[u00D7] 3"
        );
    }
}
