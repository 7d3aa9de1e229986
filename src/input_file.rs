//! Reading a user's input file (a study or scene) as text without blocking:
//! a FIFO, a device or a folder given as the file is refused at once, where
//! reading it would wait for a writer that never comes.

use std::io::{Error, ErrorKind};
use std::path::Path;

/// The text of the regular file at `path`; anything else is an
/// `InvalidInput` error saying what the path is.
pub fn read_text(path: &Path) -> std::io::Result<String> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "a folder"
        } else {
            "not a regular file (a FIFO, socket or device)"
        };
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("{what}, not a text file"),
        ));
    }
    std::fs::read_to_string(path)
}

/// A TOML parse error of `text` in a user's words, led by the dotted key
/// of the line it points at (`optimize.rho_bounds: …`) when the parser's
/// own message does not name it: the parser shows the line, not the
/// table the line sits in.
pub fn toml_message(text: &str, error: &toml::de::Error) -> String {
    let words = in_user_words(&error.to_string());
    match error
        .span()
        .and_then(|span| dotted_key_at(text, span.start))
    {
        Some(key) if !error.message().contains(&key) => format!("{key}: {words}"),
        _ => words,
    }
}

/// The dotted key a TOML parse error of `text` read as `T` points at
/// (`balancer.dragg` for an unknown key on that line); `None` when `text`
/// parses or the error has no place. For callers that report the key apart
/// from the message (the Python package's `InputError.key`).
pub fn toml_error_key<T: serde::de::DeserializeOwned>(text: &str) -> Option<String> {
    let error = toml::from_str::<T>(text).err()?;
    let at = error.span()?.start;
    dotted_key_at(text, at).or_else(|| missing_key_at(text, at, error.message()))
}

/// The dotted key a "missing field `x`" error means when it points at its
/// table's header line (`[rotor]` and `kx` → `rotor.kx`).
fn missing_key_at(text: &str, offset: usize, message: &str) -> Option<String> {
    let field = message.split_once("missing field `")?.1.split('`').next()?;
    let start = text
        .get(..offset.min(text.len()))?
        .rfind('\n')
        .map_or(0, |i| i + 1);
    let header = text[start..].lines().next()?.trim();
    let table = header
        .strip_prefix('[')?
        .trim_start_matches('[')
        .split(']')
        .next()?
        .trim();
    Some(format!("{}.{field}", table.trim_matches('"')))
}

/// `T` read from a TOML table by way of its text: serde reads an internally
/// tagged or flattened table from a buffer that has lost each value's
/// place, so its errors name no key ("invalid type: sequence, expected a
/// number"); read again as text, the error points at the key's line, and
/// the message is led by that key (`max: invalid type: …`).
pub fn from_table<T: serde::de::DeserializeOwned>(table: &toml::Table) -> Result<T, String> {
    let text = table.to_string();
    toml::from_str(&text).map_err(|e| {
        let message = in_user_words(e.message());
        // A tagged or flattened table's error has no place: find the key by
        // the value it describes, when one key alone holds such a value.
        let by_value = || {
            let (_, what) = e.message().split_once("invalid type: ")?;
            let mut keys = table.iter().filter(|(_, v)| {
                let said = match v {
                    toml::Value::Array(_) => "sequence".to_string(),
                    toml::Value::Table(_) => "map".to_string(),
                    toml::Value::Boolean(b) => format!("boolean `{b}`"),
                    toml::Value::String(s) => format!("string {s:?}"),
                    toml::Value::Integer(i) => format!("integer `{i}`"),
                    toml::Value::Float(f) => format!("floating point `{f}`"),
                    toml::Value::Datetime(d) => format!("{d}"),
                };
                what.starts_with(&said)
            });
            match (keys.next(), keys.next()) {
                (Some((k, _)), None) => Some(k.clone()),
                _ => None,
            }
        };
        match by_value().or_else(|| e.span().and_then(|span| dotted_key_at(&text, span.start))) {
            Some(key) if !message.contains(&format!("`{key}`")) => format!("{key}: {message}"),
            _ => message,
        }
    })
}

/// The dotted key of the `key = value` line holding byte `offset` of a
/// TOML text: the last table header above it, then the line's key.
/// `None` on a header line or a line without `=` (a continued array).
fn dotted_key_at(text: &str, offset: usize) -> Option<String> {
    let offset = offset.min(text.len());
    let start = text.get(..offset)?.rfind('\n').map_or(0, |i| i + 1);
    let line = text[start..].lines().next()?.trim_start();
    if line.starts_with('[') || line.starts_with('#') {
        return None;
    }
    let key = line.split_once('=')?.0.trim().trim_matches('"');
    if key.is_empty() {
        return None;
    }
    let table = text[..start]
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|h| {
            h.trim_start_matches('[')
                .split(']')
                .next()
                .unwrap_or("")
                .trim()
                .to_string()
        });
    Some(match table {
        Some(t) if !t.is_empty() => format!("{t}.{key}"),
        _ => key.to_string(),
    })
}

/// A TOML parser's message with serde's words for types put in a user's:
/// "expected struct UnbalanceSpec" names a Rust type the user never wrote.
pub fn in_user_words(message: &str) -> String {
    let mut out = message
        .replace("expected f64", "expected a number")
        .replace("expected f32", "expected a number")
        .replace("expected variant identifier", "expected a name in quotes")
        .replace(
            "expected a map",
            "expected a table of keys (`{ key = value }` or a [section])",
        );
    for integer in ["u8", "u16", "u32", "u64", "usize", "i32", "i64"] {
        out = out.replace(
            &format!("expected {integer}"),
            "expected a whole number in range",
        );
    }
    for (phrase, words) in [
        (
            "expected struct ",
            "expected a table of keys (`{ key = value }` or a [section])",
        ),
        (
            "data did not match any variant of untagged enum ",
            "expected one of the value's documented forms",
        ),
        (
            "expected internally tagged enum ",
            "expected a table with its kind key",
        ),
        ("expected enum ", "expected one of the documented names"),
    ] {
        while let Some(at) = out.find(phrase) {
            let rest = &out[at + phrase.len()..];
            let name_len = rest
                .find(|c: char| !c.is_alphanumeric() && c != '_')
                .unwrap_or(rest.len());
            out = format!("{}{words}{}", &out[..at], &rest[name_len..]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_parse_errors_key_is_the_dotted_key_of_its_line() {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        #[allow(dead_code)]
        struct Balancer {
            drag: f64,
        }
        #[derive(serde::Deserialize)]
        #[allow(dead_code)]
        struct File {
            balancer: Balancer,
        }
        let key = toml_error_key::<File>("[balancer]\ndrag = 1.0\ndragg = 2.0\n");
        assert_eq!(key.as_deref(), Some("balancer.dragg"));
        // A missing key is pointed at by its table's header.
        let key = toml_error_key::<File>("[balancer]\n");
        assert_eq!(key.as_deref(), Some("balancer.drag"));
        assert_eq!(toml_error_key::<File>("[balancer]\ndrag = 1.0\n"), None);
    }

    #[test]
    fn rust_type_names_never_reach_the_user() {
        let cases = [
            "invalid type: integer `5`, expected struct UnbalanceSpec",
            "data did not match any variant of untagged enum Foo",
            "invalid type: string \"x\", expected internally tagged enum SpeedLaw",
            "invalid type: string \"fast\", expected f64",
            "invalid value: integer `-3`, expected u32",
        ];
        for case in cases {
            let words = in_user_words(case);
            for rust in ["struct", "enum", "f64", "u32", "Unbalance", "SpeedLaw"] {
                assert!(!words.contains(rust), "{case} -> {words}");
            }
        }
        assert_eq!(
            in_user_words("invalid type: integer `5`, expected struct UnbalanceSpec"),
            "invalid type: integer `5`, expected a table of keys (`{ key = value }` or a [section])"
        );
    }

    #[test]
    fn a_fifo_or_folder_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let err = read_text(dir.path()).unwrap_err();
        assert!(err.to_string().contains("a folder"), "{err}");
        let fifo = dir.path().join("study.toml");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let err = read_text(&fifo).unwrap_err();
            assert!(err.to_string().contains("FIFO"), "{err}");
        }
        let file = dir.path().join("ok.toml");
        std::fs::write(&file, "a = 1").unwrap();
        assert_eq!(read_text(&file).unwrap(), "a = 1");
    }

    #[test]
    fn a_parse_error_is_led_by_the_dotted_key_of_its_line() {
        let text = "name = \"x\"\n[optimize]\nrho_bounds = \"wide\"\n";
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct O {
            rho_bounds: [f64; 2],
        }
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct F {
            name: String,
            optimize: O,
        }
        let e = toml::from_str::<F>(text).unwrap_err();
        assert!(
            toml_message(text, &e).starts_with("optimize.rho_bounds: "),
            "{}",
            toml_message(text, &e)
        );
        assert_eq!(dotted_key_at(text, 3), Some("name".into()));
        assert_eq!(dotted_key_at(text, 15), None);
    }
}
