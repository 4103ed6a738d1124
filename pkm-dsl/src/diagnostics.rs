//! Diagnostics: every error carries a byte span into the DSL text and renders
//! with `line:column` and a caret picture, the way rustc shows its own.

use std::fmt;

/// The most errors rendered for one text; the rest are counted in a last line.
/// Every error renders its source line, so an unbounded list of errors on a
/// long line would print (and allocate) without bound.
pub const MAX_RENDERED_DIAGNOSTICS: usize = 50;

/// The most characters of a source line shown above a caret; longer lines are
/// cut to a window around the span, marked with `…`.
pub const MAX_SHOWN_LINE_CHARS: usize = 120;

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

/// The part of a source line to show, and the caret's column (0-based, in
/// characters) within it: the whole line when it is short, otherwise a window
/// of [`MAX_SHOWN_LINE_CHARS`] characters around `caret`, with `…` at cut ends.
fn shown_line(line: &str, caret: usize) -> (String, usize) {
    let total = line.chars().count();
    if total <= MAX_SHOWN_LINE_CHARS {
        return (line.to_string(), caret);
    }
    let first = caret.saturating_sub(MAX_SHOWN_LINE_CHARS / 3).min(total);
    let last = (first + MAX_SHOWN_LINE_CHARS).min(total);
    let mut text: String = line.chars().skip(first).take(last - first).collect();
    let mut caret = caret - first;
    if first > 0 {
        text.insert(0, '…');
        caret += 1;
    }
    if last < total {
        text.push('…');
    }
    (text, caret)
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
            let full_line = source.lines().nth(line - 1).unwrap_or("");
            let gutter = line.to_string().len();
            let pad = " ".repeat(gutter);
            let span_chars = source
                .get(
                    floor_char_boundary(source, span.start.min(source.len()))
                        ..floor_char_boundary(source, span.end.min(source.len())),
                )
                .map(|s| s.lines().next().unwrap_or("").chars().count())
                .unwrap_or(0)
                .max(1);
            let (text, start_in_line) = shown_line(full_line, col - 1);
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

    /// Records `key` as given at `span` in `seen`. Given before, it is an
    /// error at `span`, "`what` is given twice", pointing at the first:
    /// false, and the caller skips it.
    pub fn given_once<K: std::hash::Hash + Eq>(
        &mut self,
        seen: &mut std::collections::HashMap<K, Span>,
        key: K,
        span: Span,
        what: impl FnOnce() -> String,
    ) -> bool {
        match seen.insert(key, span) {
            None => true,
            Some(first) => {
                self.push(
                    Diagnostic::new(span, format!("{} is given twice", what()))
                        .label("again")
                        .also(first, "first here"),
                );
                false
            }
        }
    }

    /// True when no error was collected.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Renders the errors, separated by blank lines: the first
    /// [`MAX_RENDERED_DIAGNOSTICS`], then a line counting the others.
    pub fn render(&self, source: &str, file: &str) -> String {
        let mut out = self
            .0
            .iter()
            .take(MAX_RENDERED_DIAGNOSTICS)
            .map(|d| d.render(source, file))
            .collect::<Vec<_>>()
            .join("\n");
        if let Some(more) = self.hidden() {
            out.push_str(&format!("\n{more}\n"));
        }
        out
    }

    /// The line that counts the errors not rendered, if any are not.
    fn hidden(&self) -> Option<String> {
        let more = self.0.len().checked_sub(MAX_RENDERED_DIAGNOSTICS).filter(|&m| m > 0)?;
        Some(format!(
            "error: {more} more error{} not shown (at most {MAX_RENDERED_DIAGNOSTICS} are shown)",
            if more == 1 { "" } else { "s" }
        ))
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
        for (i, d) in self.0.iter().take(MAX_RENDERED_DIAGNOSTICS).enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "error: {}", d.message)?;
        }
        if let Some(more) = self.hidden() {
            write!(f, "\n{more}")?;
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
    fn long_lines_are_cut_around_the_caret() {
        // 200 `a`s, then the span `bc` at byte 200; the window starts 40 characters
        // before the caret and holds 120 characters.
        let source = format!("{}bc{}", "a".repeat(200), "d".repeat(200));
        let shown = format!("…{}bc{}…", "a".repeat(40), "d".repeat(78));
        check(
            &source,
            Span::new(200, 202),
            &format!(
                "error: bad thing\n --> m.pkm:1:201\n  |\n1 | {shown}\n  | {}^^ here\n",
                " ".repeat(41)
            ),
        );
    }

    #[test]
    fn many_errors_are_counted_not_rendered() {
        let all = Diagnostics(
            (0..MAX_RENDERED_DIAGNOSTICS + 3)
                .map(|_| Diagnostic::global("e"))
                .collect(),
        );
        let text = all.render("", "m.pkm");
        assert_eq!(text.matches("error: e\n").count(), MAX_RENDERED_DIAGNOSTICS);
        assert!(
            text.ends_with("error: 3 more errors not shown (at most 50 are shown)\n"),
            "{text}"
        );
        assert!(all
            .to_string()
            .ends_with("error: 3 more errors not shown (at most 50 are shown)"));
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
