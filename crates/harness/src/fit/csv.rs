//! Tables of measurements from other codes: comma-separated, a header naming the columns,
//! one row per sample, several rows per x. Header names are matched case-insensitively with
//! surrounding spaces (and double quotes) ignored; blank lines and lines starting with `#` are
//! skipped. Every error names the line (1-based) it is about.

use super::{Samples, WeakSamples};
use thiserror::Error;

/// Why a table of measurements was refused; each names the 1-based line it is about.
#[derive(Clone, Debug, PartialEq, Error)]
#[non_exhaustive]
pub enum CsvError {
    /// The text has no header: it is empty or holds only blank and `#` lines.
    #[error(
        "line {line}: the table ends with no header (it is empty); expected a header line `{expected}` followed by data rows"
    )]
    Empty {
        /// The line just past the end of the text.
        line: usize,
        /// The header the table should have started with, e.g. `p,time`.
        expected: String,
    },
    /// The first non-blank line holds only numbers, so it is data, not a header.
    #[error(
        "line {line}: missing header: the first line must name the columns (`{expected}`), not hold numbers"
    )]
    MissingHeader {
        /// The line taken for the header.
        line: usize,
        /// The header expected, e.g. `p,time`.
        expected: String,
    },
    /// The header names columns this kind of table does not have.
    #[error("line {line}: unknown column(s) {names}; expected `{expected}`")]
    UnknownColumns {
        /// The header's line.
        line: usize,
        /// The unknown names, back-quoted and comma-separated.
        names: String,
        /// The header expected, e.g. `p,n,time`.
        expected: String,
    },
    /// The header lacks a required column.
    #[error("line {line}: missing column `{name}`; expected `{expected}`")]
    MissingColumn {
        /// The header's (or the row's) line.
        line: usize,
        /// The missing column: `p`, `n` or `time`.
        name: &'static str,
        /// The header expected, e.g. `p,time`.
        expected: String,
    },
    /// The header names one column twice.
    #[error("line {line}: column `{name}` appears twice")]
    DuplicateColumn {
        /// The header's line.
        line: usize,
        /// The repeated name, lower-cased.
        name: String,
    },
    /// A data row has more or fewer comma-separated fields than the header.
    #[error("line {line}: {got} fields, but the header has {expected}")]
    WrongFieldCount {
        /// The row's line.
        line: usize,
        /// The row's number of fields.
        got: usize,
        /// The header's number of columns.
        expected: usize,
    },
    /// A field does not parse as a number, or is NaN or infinite.
    #[error("line {line}: `{value}` in column `{column}` is not a finite number")]
    NotANumber {
        /// The row's line.
        line: usize,
        /// The field's column: `p`, `n` or `time`.
        column: &'static str,
        /// The field as written, trimmed and unquoted.
        value: String,
    },
    /// A number outside its column's range: p below 1, or n or time not positive.
    #[error("line {line}: {column} = {value}, but {requirement}")]
    OutOfRange {
        /// The row's line.
        line: usize,
        /// The field's column: `p`, `n` or `time`.
        column: &'static str,
        /// The value read.
        value: f64,
        /// The column's rule, as a phrase for the message.
        requirement: &'static str,
    },
    /// A `p,n,time` table gives one worker count two different problem sizes.
    #[error(
        "line {line}: p = {p} has n = {n}, but line {first_line} gave it n = {first_n}; each p needs one problem size"
    )]
    InconsistentN {
        /// The line with the second problem size.
        line: usize,
        /// The worker count.
        p: f64,
        /// The problem size (particles) on `line`.
        n: f64,
        /// The line where `p` first appeared.
        first_line: usize,
        /// The problem size `p` had there.
        first_n: f64,
    },
    /// The header is followed by no data rows.
    #[error("no data rows after the header on line {header_line}")]
    NoRows {
        /// The header's line.
        header_line: usize,
    },
}

/// A column the parser knows: its name and the values it accepts.
#[derive(Clone, Copy, Debug)]
struct Column {
    name: &'static str,
    accepts: fn(f64) -> bool,
    requirement: &'static str,
}

const P: Column = Column {
    name: "p",
    accepts: |v| v >= 1.0,
    requirement: "worker counts must be >= 1",
};
const N: Column = Column {
    name: "n",
    accepts: |v| v > 0.0,
    requirement: "problem sizes must be > 0",
};
const TIME: Column = Column {
    name: "time",
    accepts: |v| v > 0.0,
    requirement: "times must be seconds > 0",
};

/// Parsed rows: for each row its line number and one value per requested column, in the order
/// the columns were requested (absent optional columns are `None`).
struct Table {
    rows: Vec<Row>,
    /// Whether each optional column is in the header (then every row has its value).
    has_optional: Vec<bool>,
}

/// One data row: its line number, the required columns' values in the order asked, and the
/// optional ones (`None` when the header does not have that column).
struct Row {
    line: usize,
    required: Vec<f64>,
    optional: Vec<Option<f64>>,
}

fn parse_table(text: &str, required: &[Column], optional: &[Column]) -> Result<Table, CsvError> {
    let expected = required
        .iter()
        .chain(optional)
        .map(|c| c.name)
        .collect::<Vec<_>>()
        .join(",");
    // A byte-order mark, as spreadsheet exports write, is not part of the first column's name.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((header_line, header)) = lines.next() else {
        return Err(CsvError::Empty {
            line: text.lines().count() + 1,
            expected,
        });
    };
    let names: Vec<String> = fields(header).map(|f| f.to_ascii_lowercase()).collect();
    if names.iter().all(|f| f.parse::<f64>().is_ok()) {
        return Err(CsvError::MissingHeader {
            line: header_line,
            expected,
        });
    }
    let known: Vec<&Column> = required.iter().chain(optional).collect();
    let unknown: Vec<String> = names
        .iter()
        .filter(|n| !known.iter().any(|c| c.name == n.as_str()))
        .map(|n| {
            if n.is_empty() {
                "(an empty name)".to_string()
            } else {
                format!("`{n}`")
            }
        })
        .collect();
    if !unknown.is_empty() {
        return Err(CsvError::UnknownColumns {
            line: header_line,
            names: unknown.join(", "),
            expected,
        });
    }
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) {
            return Err(CsvError::DuplicateColumn {
                line: header_line,
                name: n.clone(),
            });
        }
    }
    if let Some(missing) = required.iter().find(|c| !names.iter().any(|n| n == c.name)) {
        return Err(CsvError::MissingColumn {
            line: header_line,
            name: missing.name,
            expected,
        });
    }
    let position: Vec<Option<usize>> = known
        .iter()
        .map(|c| names.iter().position(|n| n == c.name))
        .collect();
    let mut rows = Vec::new();
    for (line, text) in lines {
        let raw: Vec<&str> = fields(text).collect();
        if raw.len() != names.len() {
            return Err(CsvError::WrongFieldCount {
                line,
                got: raw.len(),
                expected: names.len(),
            });
        }
        let mut row = Row {
            line,
            required: Vec::with_capacity(required.len()),
            optional: Vec::with_capacity(optional.len()),
        };
        for (i, (column, pos)) in known.iter().zip(&position).enumerate() {
            let Some(pos) = *pos else {
                // Only optional columns can be absent: required ones were checked above.
                row.optional.push(None);
                continue;
            };
            let v = raw[pos]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| CsvError::NotANumber {
                    line,
                    column: column.name,
                    value: raw[pos].to_string(),
                })?;
            if !(column.accepts)(v) {
                return Err(CsvError::OutOfRange {
                    line,
                    column: column.name,
                    value: v,
                    requirement: column.requirement,
                });
            }
            if i < required.len() {
                row.required.push(v);
            } else {
                row.optional.push(Some(v));
            }
        }
        rows.push(row);
    }
    if rows.is_empty() {
        return Err(CsvError::NoRows { header_line });
    }
    let has_optional = position[required.len()..]
        .iter()
        .map(Option::is_some)
        .collect();
    Ok(Table { rows, has_optional })
}

/// The fields of a line, trimmed and without surrounding double quotes.
fn fields(line: &str) -> impl Iterator<Item = &str> {
    line.split(',').map(|f| {
        let f = f.trim();
        f.strip_prefix('"')
            .and_then(|g| g.strip_suffix('"'))
            .unwrap_or(f)
            .trim()
    })
}

/// Groups `(x, time)` rows by x, in order of first appearance.
fn group(rows: impl Iterator<Item = (f64, f64)>) -> Vec<Samples> {
    let mut out: Vec<Samples> = Vec::new();
    for (x, t) in rows {
        match out.iter_mut().find(|s| s.x == x) {
            Some(s) => s.values.push(t),
            None => out.push(Samples::new(x, vec![t])),
        }
    }
    out
}

/// A `p,time` table (strong scaling) as samples at x = p.
pub fn parse_threads(text: &str) -> Result<Vec<Samples>, CsvError> {
    let table = parse_table(text, &[P, TIME], &[])?;
    Ok(group(
        table.rows.iter().map(|r| (r.required[0], r.required[1])),
    ))
}

/// An `n,time` table (complexity in n) as samples at x = n.
pub fn parse_sizes(text: &str) -> Result<Vec<Samples>, CsvError> {
    let table = parse_table(text, &[N, TIME], &[])?;
    Ok(group(
        table.rows.iter().map(|r| (r.required[0], r.required[1])),
    ))
}

/// A weak-scaling table: `p,time`, or `p,n,time` when the problem sizes are known.
#[derive(Clone, Debug, PartialEq)]
pub enum WeakTable {
    /// A `p,time` table: samples at x = p, problem sizes unknown (for [`super::fit_weak`]).
    Times(Vec<Samples>),
    /// A `p,n,time` table: samples at each p with its problem size (for
    /// [`super::fit_weak_with_n`]), in order of first appearance.
    WithN(Vec<WeakSamples>),
}

/// A weak-scaling table, with or without its `n` column; a p given two different n is refused.
pub fn parse_weak(text: &str) -> Result<WeakTable, CsvError> {
    let table = parse_table(text, &[P, TIME], &[N])?;
    let pairs = table.rows.iter().map(|r| (r.required[0], r.required[1]));
    if !table.has_optional[0] {
        return Ok(WeakTable::Times(group(pairs)));
    }
    let mut out: Vec<(usize, WeakSamples)> = Vec::new();
    for row in &table.rows {
        let line = &row.line;
        let (p, time) = (row.required[0], row.required[1]);
        let Some(n) = row.optional[0] else {
            return Err(CsvError::MissingColumn {
                line: row.line,
                name: N.name,
                expected: "p,n,time".into(),
            });
        };
        match out.iter_mut().find(|(_, s)| s.p == p) {
            Some((first_line, s)) if s.n != n => {
                return Err(CsvError::InconsistentN {
                    line: *line,
                    p,
                    n,
                    first_line: *first_line,
                    first_n: s.n,
                });
            }
            Some((_, s)) => s.values.push(time),
            None => out.push((
                *line,
                WeakSamples {
                    p,
                    n,
                    values: vec![time],
                },
            )),
        }
    }
    Ok(WeakTable::WithN(out.into_iter().map(|(_, s)| s).collect()))
}

#[cfg(test)]
#[path = "csv_tests.rs"]
mod tests;
