//! What the commands print for people, and the rows their CSV carries: named
//! columns, each with its unit, one row per branch of the plan, numbered as
//! `pkm fk` and `pkm ik` number them (bit k of the number set: choice k is
//! `-`).
//!
//! A command describes its values once, as [`Column`]s, and gives each
//! branch as a [`Branch`]: its number, its signs, and its values in the
//! columns' order or the reason it has none. [`branch_table`] lays the
//! branches out for a terminal (the reasons under the table);
//! [`super::csv::Writer`] writes the same rows as CSV, every digit kept.

use pkm_runtime::primitives::Sign;

/// One named value of a row, with its unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// The name: a joint's, an output's, or the quantity's (`k_z`).
    pub name: String,
    /// Its unit (`mm`, `rad`, `N/mm`); `None` for a count or a flag.
    pub unit: Option<String>,
    /// Written to CSV only; the text table leaves it out (a command prints
    /// such values its own way, as the stiffness prints K as a matrix).
    pub csv_only: bool,
}

impl Column {
    /// A value in `unit`.
    pub fn new(name: impl Into<String>, unit: impl Into<String>) -> Column {
        Column {
            name: name.into(),
            unit: Some(unit.into()),
            csv_only: false,
        }
    }

    /// A value without a unit (a count, a flag, a name).
    pub fn bare(name: impl Into<String>) -> Column {
        Column {
            name: name.into(),
            unit: None,
            csv_only: false,
        }
    }

    /// The same column, left out of the text table.
    pub fn csv_only(self) -> Column {
        Column { csv_only: true, ..self }
    }

    /// The CSV header: `name [unit]`, or the name alone.
    pub fn header(&self) -> String {
        match &self.unit {
            Some(u) => format!("{} [{u}]", self.name),
            None => self.name.clone(),
        }
    }
}

/// One value of a row.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// No value.
    Empty,
    /// A count or a number of a branch.
    Int(i64),
    /// A number in its column's unit.
    Num(f64),
    /// Text.
    Text(String),
    /// Yes or no.
    Flag(bool),
}

impl Cell {
    /// For people: a number to 7 significant digits, a flag as `yes` or
    /// nothing.
    pub fn short(&self) -> String {
        match self {
            Cell::Empty => String::new(),
            Cell::Int(i) => i.to_string(),
            Cell::Num(v) => significant(*v, 7),
            Cell::Text(t) => t.clone(),
            Cell::Flag(f) => if *f { "yes" } else { "" }.to_string(),
        }
    }

    /// For CSV: a number with every digit (the shortest text that reads
    /// back as the same `f64`), a flag as `true` or `false`.
    pub fn exact(&self) -> String {
        match self {
            Cell::Num(v) => format!("{v:?}"),
            Cell::Flag(f) => f.to_string(),
            other => other.short(),
        }
    }

    fn numeric(&self) -> bool {
        matches!(self, Cell::Int(_) | Cell::Num(_))
    }
}

/// `v` to `digits` significant digits, trailing zeros dropped; in
/// scientific notation outside 1e-3 ≤ |v| < 1e7.
fn significant(v: f64, digits: i32) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v == 0.0 { "0".into() } else { v.to_string() };
    }
    let e = v.abs().log10().floor() as i32;
    let trim = |s: String| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if (-3..7).contains(&e) {
        let decimals = (digits - 1 - e).max(0) as usize;
        let s = trim(format!("{v:.decimals$}"));
        if s == "-0" {
            "0".into()
        } else {
            s
        }
    } else {
        let s = format!("{v:.*e}", (digits - 1) as usize);
        match s.split_once('e') {
            Some((mantissa, exponent)) => format!("{}e{exponent}", trim(mantissa.to_string())),
            None => s,
        }
    }
}

/// One branch at one input: its number in the plan, its ± choices, and its
/// values (in the order of the command's columns) or why it has none.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Its number: bit k set when choice k is `-` (the order of `pkm fk`).
    pub number: usize,
    /// Its ± choices.
    pub signs: Vec<Sign>,
    /// Its values, or the reason it has none.
    pub values: Result<Vec<Cell>, String>,
}

impl Branch {
    /// Branch `number` of a plan with `choices` ± choices, failing for
    /// `reason` (every branch of an input that could not be solved).
    pub fn failed(number: usize, choices: usize, reason: &str) -> Branch {
        Branch {
            number,
            signs: signs_of(number, choices),
            values: Err(reason.to_string()),
        }
    }
}

/// The number of the branch with `signs`: bit k set when choice k is `-`
/// (`pkm_runtime::solution::every_branch`'s order).
pub fn number_of(signs: &[Sign]) -> usize {
    signs.iter().enumerate().map(|(k, s)| s.index() << k).sum()
}

/// The signs of branch `number` of a plan with `choices` ± choices.
pub fn signs_of(number: usize, choices: usize) -> Vec<Sign> {
    (0..choices)
        .map(|k| if number >> k & 1 == 0 { Sign::Plus } else { Sign::Minus })
        .collect()
}

/// A branch's signs as one word, `+-+`.
pub fn signs_word(signs: &[Sign]) -> String {
    signs.iter().map(|s| if s.index() == 0 { '+' } else { '-' }).collect()
}

/// Rows of named columns, laid out for a terminal.
#[derive(Debug, Clone)]
pub struct Table {
    /// The columns.
    pub columns: Vec<Column>,
    /// The rows, a cell per column.
    pub rows: Vec<Vec<Cell>>,
    /// How many leading columns name a row: repeated in each block when the
    /// columns do not fit in the width.
    pub key: usize,
}

impl Table {
    /// The table in lines at most `width` characters wide where the columns
    /// allow: the names, then the units (when a column has one), then the
    /// rows; numbers to the right, text to the left. Columns past the key
    /// that are empty in every row, or CSV-only, are left out; columns that
    /// do not fit go to a further block below, with the key columns again.
    pub fn render(&self, width: usize) -> String {
        let cells: Vec<Vec<String>> = self
            .rows
            .iter()
            .map(|row| row.iter().map(Cell::short).collect())
            .collect();
        let len = |s: &str| s.chars().count();
        let shown: Vec<usize> = (0..self.columns.len())
            .filter(|&c| c < self.key || (!self.columns[c].csv_only && cells.iter().any(|row| !row[c].is_empty())))
            .collect();
        let widths: Vec<usize> = (0..self.columns.len())
            .map(|c| {
                let column = &self.columns[c];
                let unit = column.unit.as_deref().map_or(0, len);
                cells
                    .iter()
                    .map(|row| len(&row[c]))
                    .fold(len(&column.name).max(unit), usize::max)
            })
            .collect();
        let right: Vec<bool> = (0..self.columns.len())
            .map(|c| self.rows.iter().any(|row| row[c].numeric()))
            .collect();
        let (key, values): (Vec<usize>, Vec<usize>) = shown.iter().partition(|&&c| c < self.key);
        let key_width: usize = key.iter().map(|&c| widths[c] + 2).sum();
        let mut blocks: Vec<Vec<usize>> = vec![Vec::new()];
        let mut used = key_width;
        for c in values {
            let last = blocks.last_mut().expect("a block");
            if !last.is_empty() && used + widths[c] > width {
                blocks.push(Vec::new());
                used = key_width;
            }
            blocks.last_mut().expect("a block").push(c);
            used += widths[c] + 2;
        }
        let pad = |text: &str, c: usize| {
            let fill = " ".repeat(widths[c] - len(text));
            if right[c] {
                format!("{fill}{text}")
            } else {
                format!("{text}{fill}")
            }
        };
        let line = |parts: Vec<String>| parts.join("  ").trim_end().to_string() + "\n";
        let mut out = String::new();
        for (b, block) in blocks.iter().enumerate() {
            if b > 0 {
                out.push('\n');
            }
            let columns: Vec<usize> = key.iter().chain(block).copied().collect();
            out += &line(columns.iter().map(|&c| pad(&self.columns[c].name, c)).collect());
            if columns.iter().any(|&c| self.columns[c].unit.is_some()) {
                let unit = |c: usize| pad(self.columns[c].unit.as_deref().unwrap_or(""), c);
                out += &line(columns.iter().map(|&c| unit(c)).collect());
            }
            for row in &cells {
                out += &line(columns.iter().map(|&c| pad(&row[c], c)).collect());
            }
        }
        out
    }
}

/// The width tables are laid out to: the terminal's `COLUMNS` if the shell
/// exports it, else 100.
pub fn width() -> usize {
    std::env::var("COLUMNS")
        .ok()
        .and_then(|c| c.parse().ok())
        .filter(|&w: &usize| w >= 40)
        .unwrap_or(100)
}

/// Every branch as a table (`branch`, `signs`, `ok`, then `columns`), and
/// under it the reason of each branch that has no values.
pub fn branch_table(columns: &[Column], branches: &[Branch]) -> String {
    let mut all = vec![Column::bare("branch"), Column::bare("signs"), Column::bare("ok")];
    all.extend(columns.iter().cloned());
    let rows = branches
        .iter()
        .map(|b| {
            let mut row = vec![
                Cell::Int(b.number as i64),
                Cell::Text(signs_word(&b.signs)),
                Cell::Text(if b.values.is_ok() { "ok" } else { "no" }.into()),
            ];
            match &b.values {
                Ok(values) => row.extend(values.iter().cloned()),
                Err(_) => row.extend(std::iter::repeat_n(Cell::Empty, columns.len())),
            }
            row
        })
        .collect();
    let table = Table {
        columns: all,
        rows,
        key: 3,
    };
    let mut out = table.render(width());
    for b in branches {
        if let Err(reason) = &b.values {
            out += &format!("branch {} ({}): {reason}\n", b.number, signs_word(&b.signs));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seven_significant_digits() {
        for (v, want) in [
            (0.0, "0"),
            (1.0, "1"),
            (-0.5, "-0.5"),
            (202.0288760504288, "202.0289"),
            (1234567.89, "1234568"),
            (12345678.9, "1.234568e7"),
            (0.00123456789, "0.001234568"),
            (1.4210854715202004e-14, "1.421085e-14"),
            (-1e-20, "-1e-20"),
        ] {
            assert_eq!(significant(v, 7), want, "{v}");
        }
    }

    #[test]
    fn every_digit_for_csv() {
        for v in [0.1, 1.0 / 3.0, 1e300, -2.5e-20, 202.0288760504288] {
            assert_eq!(Cell::Num(v).exact().parse::<f64>().unwrap(), v);
        }
    }

    #[test]
    fn numbers_and_signs() {
        use Sign::{Minus, Plus};
        assert_eq!(number_of(&[Minus, Plus, Minus]), 5);
        assert_eq!(signs_of(5, 3), vec![Minus, Plus, Minus]);
        assert_eq!(signs_word(&signs_of(6, 4)), "+--+");
    }

    /// Names over units over values, numbers to the right; columns beyond the
    /// width go to a second block that repeats the key.
    #[test]
    fn layout() {
        let t = Table {
            columns: vec![Column::bare("n"), Column::new("x", "mm"), Column::new("angle", "rad")],
            rows: vec![
                vec![Cell::Int(0), Cell::Num(1.5), Cell::Num(-2.0)],
                vec![Cell::Int(1), Cell::Num(10.0), Cell::Empty],
            ],
            key: 1,
        };
        assert_eq!(t.render(80), "n    x  angle\n    mm    rad\n0  1.5     -2\n1   10\n");
        assert_eq!(
            t.render(8),
            "n    x\n    mm\n0  1.5\n1   10\n\nn  angle\n     rad\n0     -2\n1\n"
        );
    }
}
