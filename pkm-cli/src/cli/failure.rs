//! How the command line ends: an answer on stdout, or a failure as one
//! `error: …` line on stderr (text) or an `{"error": {…}}` object on stdout
//! (`--json`), with a non-zero exit code either way.

use serde_json::{json, Map, Value};
use std::io::{ErrorKind, Write};
use std::process::ExitCode;

/// What kind of failure ended the command; the `kind` field of the JSON error.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// The command line itself is wrong (clap's usage errors; exit code 2).
    Usage,
    /// The file could not be read or the output could not be written.
    Io,
    /// The mechanism file has errors (diagnostics with line and column).
    Parse,
    /// A value given on the command line is wrong (count, name, NaN, a length through zero).
    Input,
    /// No branch reaches the given inputs or pose.
    Unreachable,
    /// The given outputs contradict each other: no configuration has them all.
    Inconsistent,
    /// `pkm report` failed; its message says why.
    Report,
}

impl Kind {
    /// The name scripts match on.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Usage => "usage",
            Kind::Io => "io",
            Kind::Parse => "parse",
            Kind::Input => "input",
            Kind::Unreachable => "unreachable",
            Kind::Inconsistent => "inconsistent",
            Kind::Report => "report",
        }
    }

    /// The exit code: 2 for usage errors as clap has it, 1 for the rest.
    pub fn exit_code(self) -> u8 {
        match self {
            Kind::Usage => 2,
            _ => 1,
        }
    }
}

/// Why a command failed.
#[derive(Debug, Clone)]
pub struct Failure {
    /// Its kind.
    pub kind: Kind,
    /// One line naming the cause.
    pub message: String,
    /// The text form when it is more than one line (diagnostics with their carets).
    pub rendered: Option<String>,
    /// Further fields of the JSON error (`file`, `line`, `column`, `diagnostics`).
    pub fields: Map<String, Value>,
}

impl Failure {
    /// A failure of `kind` with a one-line message.
    pub fn new(kind: Kind, message: impl Into<String>) -> Failure {
        Failure {
            kind,
            message: message.into(),
            rendered: None,
            fields: Map::new(),
        }
    }

    /// A wrong value on the command line.
    pub fn input(message: impl Into<String>) -> Failure {
        Failure::new(Kind::Input, message)
    }

    /// The diagnostics of mechanism file `file` (text `source`): the message
    /// is the first one's (and how many more there are), the JSON carries
    /// every one with its line and column.
    pub fn parse(d: &pkm_dsl::Diagnostics, source: &str, file: &str) -> Failure {
        let place = |span: Option<pkm_dsl::diagnostics::Span>| match span {
            Some(s) => {
                let (line, column) = s.line_col(source);
                (json!(line), json!(column))
            }
            None => (Value::Null, Value::Null),
        };
        let all: Vec<Value> =
            d.0.iter()
                .map(|e| {
                    let (line, column) = place(e.span);
                    json!({ "message": e.message, "line": line, "column": column, "label": e.label, "notes": e.notes })
                })
                .collect();
        let first = d.0.first();
        let mut message = first.map_or_else(|| "the mechanism file has errors".to_string(), |e| e.message.clone());
        if d.0.len() > 1 {
            message.push_str(&format!(" (and {} more)", d.0.len() - 1));
        }
        let (line, column) = place(first.and_then(|e| e.span));
        let mut fields = Map::new();
        fields.insert("file".into(), json!(file));
        fields.insert("line".into(), line);
        fields.insert("column".into(), column);
        fields.insert("diagnostics".into(), Value::Array(all));
        Failure {
            kind: Kind::Parse,
            message,
            rendered: Some(d.render(source, file)),
            fields,
        }
    }

    /// `{"error": {"kind": …, "message": …, …}}`.
    pub fn to_json(&self) -> Value {
        let mut error = Map::new();
        error.insert("kind".into(), json!(self.kind.name()));
        error.insert("message".into(), json!(self.message));
        error.extend(self.fields.clone());
        json!({ "error": error })
    }
}

/// Writes `text` to stdout. A reader that has gone (`pkm fk … | head -1`)
/// is not a failure of ours: the program then ends quietly with code 0.
/// Any other write error is an `io` failure, reported on stderr.
pub fn write_out(text: &str) -> ExitCode {
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.kind() == ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            write_err(&format!("error: cannot write the output: {e}\n"));
            ExitCode::FAILURE
        }
    }
}

/// Writes `text` to stderr; if even that fails there is no one left to tell.
pub fn write_err(text: &str) {
    let _ = std::io::stderr().lock().write_all(text.as_bytes());
}

/// An answer: pretty JSON, or one line of JSON with `--json`.
pub fn answer(json: bool, value: &Value) -> ExitCode {
    let text = if json {
        value.to_string()
    } else {
        serde_json::to_string_pretty(value).unwrap_or_else(|_| value.to_string())
    };
    write_out(&format!("{text}\n"))
}

/// Reports a failure: with `--json` the error object on stdout, otherwise
/// the diagnostics or one `error: …` line on stderr; the kind's exit code.
pub fn fail(json: bool, f: &Failure) -> ExitCode {
    if json {
        // The exit code says it failed even if no one reads the object.
        let _ = write_out(&format!("{}\n", f.to_json()));
    } else {
        match &f.rendered {
            Some(text) => write_err(text),
            None => write_err(&format!("error: {}\n", f.message)),
        }
    }
    ExitCode::from(f.kind.exit_code())
}
