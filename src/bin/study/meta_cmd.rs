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
    #[arg(hide_possible_values = true)]
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
    #[arg(hide_possible_values = true)]
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
/// an EXAMPLES section from the verbs' `--help` examples, then the exit
/// codes and the full version.
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
    for verb in verbs(&command) {
        verb_section(verb, "study", out)?;
    }
    out.extend_from_slice(b".SH EXAMPLES\n");
    for verb in verbs(&command) {
        examples_section(verb, "study", out)?;
    }
    man.render_extra_section(out)?;
    man.render_version_section(out)?;
    Ok(())
}

/// The verbs of `command` a reader looks up: the visible ones but `help`,
/// whose entries ("study help run", …) would repeat every verb's page.
fn verbs(command: &clap::Command) -> impl Iterator<Item = &clap::Command> {
    command
        .get_subcommands()
        .filter(|c| !c.is_hide_set() && c.get_name() != "help")
}

/// A verb's examples (its `--help` text after the options, from
/// "Examples:" on) as a subsection set line for line; its own verbs follow.
fn examples_section(verb: &clap::Command, parent: &str, out: &mut Vec<u8>) -> std::io::Result<()> {
    let name = format!("{parent} {}", verb.get_name());
    if let Some(help) = verb.get_after_help() {
        let help = help.to_string();
        let body = help.strip_prefix("Examples:").unwrap_or(&help);
        writeln!(out, ".SS \"{name}\"\n.nf")?;
        for line in body.trim_matches('\n').lines() {
            writeln!(out, "{}", roff_text(line))?;
        }
        out.extend_from_slice(b".fi\n");
    }
    for sub in verbs(verb) {
        examples_section(sub, &name, out)?;
    }
    Ok(())
}

/// `line` as roff text: backslashes escaped, a leading control character
/// made literal, hyphens as minus signs (so that flags copy as typed).
fn roff_text(line: &str) -> String {
    let escaped = line.replace('\\', "\\e").replace('-', "\\-");
    if escaped.starts_with(['.', '\'']) {
        format!("\\&{escaped}")
    } else {
        escaped
    }
}

/// One verb as a subsection: `.SS study <verb>`, its synopsis, what it
/// does and its options; its own verbs follow.
fn verb_section(verb: &clap::Command, parent: &str, out: &mut Vec<u8>) -> std::io::Result<()> {
    let name = format!("{parent} {}", verb.get_name());
    // -h and the global flags (--wide) are under the tool's own options
    // once; on every verb they would repeat.
    let repeated: Vec<clap::Id> = verb
        .get_arguments()
        .filter(|a| a.is_global_set() || a.get_id() == "help")
        .map(|a| a.get_id().clone())
        .collect();
    let command = repeated.iter().fold(verb.clone().bin_name(&name), |c, id| {
        c.mut_arg(id.clone(), |a| a.hide(true))
    });
    let man = clap_mangen::Man::new(command);
    writeln!(out, ".SS \"{name}\"")?;
    let mut part = Vec::new();
    man.render_synopsis_section(&mut part)?;
    man.render_description_section(&mut part)?;
    man.render_options_section(&mut part)?;
    // The parts' own .SH headings would end the COMMANDS section; the
    // string each part defines for an apostrophe (Aq) is defined once in
    // the page's head already.
    let text = String::from_utf8_lossy(&part);
    let mut last = "";
    for line in text.lines() {
        let line = if line.starts_with(".SH ") {
            ".PP"
        } else {
            line
        };
        let defines_aq = line.starts_with(".ie \\n(.g .ds Aq") || line.starts_with(".el .ds Aq");
        let repeated_paragraph = line == ".PP" && last == ".PP";
        if !(defines_aq || repeated_paragraph) {
            writeln!(out, "{line}")?;
            last = line;
        }
    }
    for sub in verbs(verb) {
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
