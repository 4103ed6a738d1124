//! Diagnostics: every error carries a byte span into the DSL text and renders
//! with `line:column` and a caret picture, the way rustc shows its own.

use std::fmt;

/// A byte range in the mechanism text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Span {
    /// First byte.
    pub start: usize,
    /// One past the last byte.
    pub end: usize,
}

impl Span {
    /// A span from `start` to `end` (bytes).
    pub fn new(start: usize, end: usize) -> Self {
        Span { start, end }
    }

    /// The 1-based line and column (in characters) of the span's start.
    pub fn line_col(&self, source: &str) -> (usize, usize) {
        let start = self.start.min(source.len());
        let before = &source[..floor_char_boundary(source, start)];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let col = before[line_start..].chars().count() + 1;
        (line, col)
    }
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// One error found in a mechanism description.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// What is wrong, in one sentence.
    pub message: String,
    /// Where, if the error has a place in the text.
    pub span: Option<Span>,
    /// A short label under the caret.
    pub label: String,
    /// Further explanation lines (`= note: …`).
    pub notes: Vec<String>,
    /// Other places that explain the error (`= note: first declared at m.pkm:3:5`).
    pub related: Vec<(Span, String)>,
}

impl Diagnostic {
    /// An error at `span`.
    pub fn new(span: Span, message: impl Into<String>) -> Self {
        Diagnostic {
            message: message.into(),
            span: Some(span),
            label: String::new(),
            notes: Vec::new(),
            related: Vec::new(),
        }
    }

    /// An error with no place in the text (for example an unreadable file).
    pub fn global(message: impl Into<String>) -> Self {
        Diagnostic {
            message: message.into(),
            span: None,
            label: String::new(),
            notes: Vec::new(),
            related: Vec::new(),
        }
    }

    /// Sets the label shown under the caret.
    pub fn label(mut self, label: impl Into<String>) -> Self {
        self.label = label.into();
        self
    }

    /// Adds a note line.
    pub fn note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    /// Adds another place that explains the error.
    pub fn also(mut self, span: Span, what: impl Into<String>) -> Self {
        self.related.push((span, what.into()));
        self
    }

    /// Renders the diagnostic with `file:line:column` and a caret picture.
    pub fn render(&self, source: &str, file: &str) -> String {
        let mut out = format!("error: {}\n", self.message);
        if let Some(span) = self.span {
            let (line, col) = span.line_col(source);
            let text = source.lines().nth(line - 1).unwrap_or("");
            let gutter = line.to_string().len();
            let pad = " ".repeat(gutter);
            let start_in_line = col - 1;
            let span_chars = source
                .get(
                    floor_char_boundary(source, span.start.min(source.len()))
                        ..floor_char_boundary(source, span.end.min(source.len())),
                )
                .map(|s| s.lines().next().unwrap_or("").chars().count())
                .unwrap_or(0)
                .max(1);
            // Keep the caret inside the line even when the span runs past it.
            let line_len = text.chars().count();
            let width = span_chars.min(line_len.saturating_sub(start_in_line).max(1));
            out.push_str(&format!("{pad}--> {file}:{line}:{col}\n"));
            out.push_str(&format!("{pad} |\n"));
            out.push_str(&format!("{line} | {text}\n"));
            out.push_str(&format!("{pad} | {}{}", " ".repeat(start_in_line), "^".repeat(width)));
            if !self.label.is_empty() {
                out.push(' ');
                out.push_str(&self.label);
            }
            out.push('\n');
        }
        for (span, what) in &self.related {
            let (line, col) = span.line_col(source);
            out.push_str(&format!("  = note: {what} at {file}:{line}:{col}\n"));
        }
        for note in &self.notes {
            out.push_str(&format!("  = note: {note}\n"));
        }
        out
    }
}

/// All the errors found in one mechanism description.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Diagnostics(pub Vec<Diagnostic>);

impl Diagnostics {
    /// Adds one error.
    pub fn push(&mut self, d: Diagnostic) {
        self.0.push(d);
    }

    /// True when no error was collected.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Renders every error, separated by blank lines.
    pub fn render(&self, source: &str, file: &str) -> String {
        self.0
            .iter()
            .map(|d| d.render(source, file))
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// `Ok(value)` when empty, the collected errors otherwise.
    pub fn into_result<T>(self, value: T) -> Result<T, Diagnostics> {
        if self.0.is_empty() {
            Ok(value)
        } else {
            Err(self)
        }
    }
}

impl From<Diagnostic> for Diagnostics {
    fn from(d: Diagnostic) -> Self {
        Diagnostics(vec![d])
    }
}

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.0.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "error: {}", d.message)?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostics {}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(source: &str, span: Span, expected: &str) {
        let d = Diagnostic::new(span, "bad thing").label("here");
        assert_eq!(d.render(source, "m.pkm"), expected);
    }

    #[test]
    fn caret_under_the_span() {
        check(
            "mechanism m {\n  base Q1 base;\n}",
            Span::new(21, 23),
            "error: bad thing\n --> m.pkm:2:8\n  |\n2 |   base Q1 base;\n  |        ^^ here\n",
        );
    }

    #[test]
    fn columns_count_characters_not_bytes() {
        check(
            "a ∥ b",
            Span::new(6, 7),
            "error: bad thing\n --> m.pkm:1:5\n  |\n1 | a ∥ b\n  |     ^ here\n",
        );
    }

    #[test]
    fn span_at_end_of_text() {
        check(
            "ab",
            Span::new(2, 2),
            "error: bad thing\n --> m.pkm:1:3\n  |\n1 | ab\n  |   ^ here\n",
        );
    }
}
