//! Many inputs at once: `--csv FILE` reads one input a row and writes every
//! branch of every row as CSV, streaming (one row in, its branches out and
//! flushed, then the next: constant memory for any number of rows, and a
//! program can feed `--csv -` a row and read its answer before the next).
//!
//! The format, for every command that takes it (README, "Many inputs"):
//!
//! - in: a header row naming the given values (fk: the actuated joints; ik
//!   and stiffness: the declared outputs), each once, in any order, each
//!   name optionally followed by its unit in brackets (`R1 [deg]`), which
//!   must then be the unit the command takes; then one input a row, values
//!   only. Blank lines and lines starting with `#` are skipped.
//! - out: a header row, `row, branch, signs, ok, reason`, then the
//!   command's columns as `name [unit]`; then for every input row, every
//!   branch of the plan in the order of `pkm fk` (`row` counts the input's
//!   data rows from 0, `branch` is the branch's number, `signs` its ±
//!   choices as one word, `ok` true or false, `reason` why not, and the
//!   values empty when not ok). A row whose values are not numbers, or that
//!   the command refuses, lists every branch with that reason.

use super::failure::{Failure, Kind};
use super::table::{signs_word, Branch, Column};
use std::io::{Read, Write};
use std::path::Path;

/// The longest line an input file may have: a row of numbers is far
/// shorter; a longer line is refused before it is held in memory.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// A reader that fails on a line longer than [`MAX_LINE_BYTES`].
struct LineLimit<R> {
    inner: R,
    /// Bytes since the last newline.
    run: usize,
}

impl<R: Read> Read for LineLimit<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        for &b in &buf[..n] {
            self.run = if b == b'\n' { 0 } else { self.run + 1 };
            if self.run > MAX_LINE_BYTES {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    format!("a line is longer than {MAX_LINE_BYTES} bytes (cli::csv::MAX_LINE_BYTES)"),
                ));
            }
        }
        Ok(n)
    }
}

/// What `--csv` needs of a command.
pub trait Solver {
    /// The values an input row gives, in the order [`Solver::branches`]
    /// takes them, with the units they are given in.
    fn given(&self) -> Vec<Column>;
    /// The values of a branch, as its rows carry them.
    fn columns(&self) -> Vec<Column>;
    /// The plan's ± choices: a row the command refuses lists 2^choices branches.
    fn choices(&self) -> usize;
    /// Every branch at one input row (values in [`Solver::given`]'s order
    /// and units), or why the input is refused.
    fn branches(&self, given: &[f64]) -> Result<Vec<Branch>, Failure>;
}

/// The input rows of a CSV file, one at a time.
pub struct Reader {
    rows: ::csv::Reader<LineLimit<Box<dyn Read>>>,
    /// For each given value, its column in the file.
    at: Vec<usize>,
    names: Vec<String>,
    shown: String,
    record: ::csv::StringRecord,
}

impl Reader {
    /// Opens `path` (`-`: standard input) and matches its header to `given`.
    pub fn open(path: &Path, given: &[Column]) -> Result<Reader, Failure> {
        let stdin = path.as_os_str() == "-";
        let shown = if stdin {
            "standard input".to_string()
        } else {
            format!("`{}`", path.display())
        };
        let source: Box<dyn Read> = if stdin {
            Box::new(std::io::stdin())
        } else {
            let file =
                std::fs::File::open(path).map_err(|e| Failure::new(Kind::Io, format!("cannot read {shown}: {e}")))?;
            Box::new(file)
        };
        let mut rows = ::csv::ReaderBuilder::new()
            .trim(::csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(LineLimit { inner: source, run: 0 });
        let header = rows.headers().map_err(|e| csv_failure(&shown, &e))?.clone();
        let expected = given.iter().map(Column::header).collect::<Vec<_>>().join(", ");
        let mut at = vec![None; given.len()];
        for (k, cell) in header.iter().enumerate() {
            let (name, unit) = match cell.strip_suffix(']').and_then(|c| c.split_once('[')) {
                Some((name, unit)) => (name.trim(), Some(unit.trim())),
                None => (cell, None),
            };
            let Some(i) = given.iter().position(|c| c.name == name) else {
                return Err(Failure::input(format!(
                    "{shown}: column `{cell}` is not a value this command takes; the header must name {expected}"
                )));
            };
            if let (Some(unit), Some(want)) = (unit, given[i].unit.as_deref()) {
                if unit != want {
                    return Err(Failure::input(format!(
                        "{shown}: column `{cell}` is in {unit}; {name} is taken in {want}"
                    )));
                }
            }
            if at[i].replace(k).is_some() {
                return Err(Failure::input(format!("{shown}: column {name} is named twice")));
            }
        }
        let missing: Vec<&str> = given
            .iter()
            .zip(&at)
            .filter(|(_, a)| a.is_none())
            .map(|(c, _)| c.name.as_str())
            .collect();
        if !missing.is_empty() {
            return Err(Failure::input(format!(
                "{shown}: no column for {}; the header must name {expected}",
                missing.join(", ")
            )));
        }
        Ok(Reader {
            rows,
            at: at.into_iter().flatten().collect(),
            names: given.iter().map(|c| c.name.clone()).collect(),
            shown,
            record: ::csv::StringRecord::new(),
        })
    }

    /// The next row's values in the order given to [`Reader::open`], or why
    /// they are not numbers; `None` at the end. A file that is not CSV of
    /// the header's width fails.
    pub fn next_row(&mut self) -> Result<Option<Result<Vec<f64>, String>>, Failure> {
        if !self
            .rows
            .read_record(&mut self.record)
            .map_err(|e| csv_failure(&self.shown, &e))?
        {
            return Ok(None);
        }
        let values = self
            .at
            .iter()
            .zip(&self.names)
            .map(|(&k, name)| {
                let text = &self.record[k];
                match text.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    Ok(v) => Err(format!("{name} = {v} is not finite")),
                    Err(_) => Err(format!("{name} = `{text}` is not a number")),
                }
            })
            .collect();
        Ok(Some(values))
    }
}

/// A CSV file's failure (the parser's message names the line).
fn csv_failure(shown: &str, e: &::csv::Error) -> Failure {
    match e.kind() {
        ::csv::ErrorKind::Io(io) => Failure::new(Kind::Io, format!("cannot read {shown}: {io}")),
        _ => Failure::input(format!("{shown}: {e}")),
    }
}

/// Branches as CSV rows: `row, branch, signs, ok, reason`, then the columns.
pub struct Writer<W: Write> {
    out: ::csv::Writer<W>,
    width: usize,
}

impl<W: Write> Writer<W> {
    /// A writer of branches with `columns`; writes the header.
    pub fn new(out: W, columns: &[Column]) -> std::io::Result<Writer<W>> {
        let mut out = ::csv::WriterBuilder::new().from_writer(out);
        let fixed = ["row", "branch", "signs", "ok", "reason"].map(String::from);
        let header = fixed.into_iter().chain(columns.iter().map(Column::header));
        out.write_record(header).map_err(std::io::Error::from)?;
        Ok(Writer {
            out,
            width: columns.len(),
        })
    }

    /// Branch `b` of input row `row`.
    pub fn branch(&mut self, row: usize, b: &Branch) -> std::io::Result<()> {
        let (ok, reason) = match &b.values {
            Ok(_) => ("true", ""),
            Err(why) => ("false", why.as_str()),
        };
        let fixed = [
            row.to_string(),
            b.number.to_string(),
            signs_word(&b.signs),
            ok.into(),
            reason.into(),
        ];
        let values: Vec<String> = match &b.values {
            Ok(values) => values.iter().map(|v| v.exact()).collect(),
            Err(_) => vec![String::new(); self.width],
        };
        self.out
            .write_record(fixed.into_iter().chain(values))
            .map_err(std::io::Error::from)
    }

    /// Writes out what is buffered.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// `--csv inputs`: every branch of every input row of `inputs`, to `out` or
/// standard output. Fails (after writing every row) when no row has a
/// branch that solves, or the file has no row. Nothing is written (nor
/// `out` created) before the first row is read.
pub fn run(s: &impl Solver, inputs: &Path, out: Option<&Path>) -> Result<(), Failure> {
    let mut reader = Reader::open(inputs, &s.given())?;
    let shown_out = out.map_or_else(|| "standard output".to_string(), |p| format!("`{}`", p.display()));
    let write_failure = |e: std::io::Error| Failure::new(Kind::Io, format!("cannot write {shown_out}: {e}"));
    let open = || -> std::io::Result<Writer<Box<dyn Write>>> {
        let sink: Box<dyn Write> = match out {
            Some(path) => Box::new(std::fs::File::create(path)?),
            None => Box::new(std::io::stdout().lock()),
        };
        Writer::new(sink, &s.columns())
    };
    let mut writer = None;
    let (mut rows, mut solved) = (0usize, 0usize);
    while let Some(values) = reader.next_row()? {
        let branches = values
            .map_err(Failure::input)
            .and_then(|v| s.branches(&v))
            .unwrap_or_else(|f| {
                (0..1usize << s.choices())
                    .map(|n| Branch::failed(n, s.choices(), &f.message))
                    .collect()
            });
        if branches.iter().any(|b| b.values.is_ok()) {
            solved += 1;
        }
        let written = match &mut writer {
            Some(w) => Ok(w),
            None => open().map(|w| writer.insert(w)),
        }
        .and_then(|w| {
            branches.iter().try_for_each(|b| w.branch(rows, b))?;
            w.flush()
        });
        match written {
            Ok(()) => {}
            // The reader has gone (`| head`): nothing more to do.
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => return Ok(()),
            Err(e) => return Err(write_failure(e)),
        }
        rows += 1;
    }
    if rows == 0 {
        return Err(Failure::input(format!(
            "{} has a header and no input row",
            reader.shown
        )));
    }
    if solved == 0 {
        return Err(Failure::new(
            Kind::Unreachable,
            format!("no branch solves at any of the {rows} input rows (each branch's reason is in its row)"),
        ));
    }
    Ok(())
}
