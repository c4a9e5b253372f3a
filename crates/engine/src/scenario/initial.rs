//! Initial conditions from a file (`run --initial`), in one of two formats told apart by their
//! content:
//!
//! - **export**: what `nbody-bench export --format text` writes: a first line
//!   `# nbody-bench initial state v1`, `#` lines describing the scenario, then a
//!   `# columns: id x y [z] vx vy [vz] mass strength` line and one row per body. Ids are
//!   0..n−1, each once, in any order; the other header lines are notes (the run keeps the
//!   scenario's law, box and field).
//! - **barnes-hut**: the Barnes-Hut report's body file (its `nbody_start.txt`): one body per
//!   line, `m x y z vx vy vz`, with `#` comment lines and blank lines. 3-D only; the mass is
//!   both the inertial and the gravitational mass. It carries no charges, so it is refused
//!   for coulomb (whose export text has a strength column: the charge).
//!
//! Every value must be a finite number and every mass positive; an error names the file and
//! the line.

use super::ScenarioKind;
use crate::physics::LawKind;
use crate::real::Real;
use crate::state::State;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// The first line of an exported state.
pub const EXPORT_HEADER: &str = "# nbody-bench initial state v1";
/// What tells an exported state from a body file, whatever its version.
const EXPORT_PREFIX: &str = "# nbody-bench initial state";
const BARNES_HUT_COLUMNS: [&str; 7] = ["m", "x", "y", "z", "vx", "vy", "vz"];

/// Which of the two initial-state formats a file is in, told apart by its first line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum InitialFormat {
    /// `nbody-bench export --format text`.
    Export,
    /// The Barnes-Hut report's body file.
    BarnesHut,
}

impl InitialFormat {
    /// The format's name in messages: `export` or `barnes-hut`.
    pub fn name(self) -> &'static str {
        match self {
            InitialFormat::Export => "export",
            InitialFormat::BarnesHut => "barnes-hut",
        }
    }
}

/// One body as read, in f64 and up to 3-D (unused components are 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    /// Position; components past the file's dimension are 0.
    pub pos: [f64; 3],
    /// Velocity; components past the file's dimension are 0.
    pub vel: [f64; 3],
    /// Inertial mass, always positive.
    pub mass: f64,
    /// The law's source strength: charge (coulomb), gravitational mass (gravity).
    pub strength: f64,
    /// Its line in the file (from 1), for errors found later.
    pub line: usize,
}

/// The bodies of an initial-state file.
#[derive(Clone, PartialEq)]
pub struct InitialBodies {
    /// The file the bodies were read from, named in errors and in the run's results.
    pub path: PathBuf,
    /// The format the file was read as.
    pub format: InitialFormat,
    /// Spatial dimension of the bodies, 2 or 3 (a Barnes-Hut file is always 3).
    pub dim: usize,
    /// The line that fixes the dimension (the columns line, or the first body).
    dim_line: usize,
    /// The scenario an exported state was made from, as its header names it.
    pub exported_from: Option<String>,
    /// In id order.
    pub bodies: Vec<Body>,
}

// A million bodies are not debug output.
impl std::fmt::Debug for InitialBodies {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InitialBodies")
            .field("path", &self.path)
            .field("format", &self.format)
            .field("dim", &self.dim)
            .field("n", &self.bodies.len())
            .finish_non_exhaustive()
    }
}

/// Why an initial-state file cannot start a run.
#[derive(Debug, Error)]
pub enum InitialError {
    /// The file could not be read (missing, unreadable, a device, or too large).
    #[error("cannot read initial state {}: {source}", path.display())]
    Read {
        /// The initial-state file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file holds comments and blank lines only.
    #[error(
        "initial state {}: no bodies ({lines} lines of comments and blank lines): a body file \
         has one body per line",
        path.display()
    )]
    Empty {
        /// The initial-state file.
        path: PathBuf,
        /// Lines in the file, all comments or blank.
        lines: usize,
    },
    /// One line of the file is wrong; the problem says how.
    #[error("initial state {} line {line}: {problem}", path.display())]
    Line {
        /// The initial-state file.
        path: PathBuf,
        /// The line, counted from 1.
        line: usize,
        /// What is wrong on it.
        problem: LineProblem,
    },
}

/// What is wrong on one line of an initial-state file.
#[derive(Debug, Error, PartialEq)]
pub enum LineProblem {
    /// The header names a version of the export format this tool does not read; holds the header.
    #[error(
        "`{0}` is not a version this tool reads (it reads `{EXPORT_HEADER}`, as \
         `nbody-bench export --format text` writes)"
    )]
    Version(String),
    /// The `# columns:` line is neither the 2-D nor the 3-D export columns; holds the columns
    /// given.
    #[error(
        "columns `{0}` are not those of an exported state (`id x y vx vy mass strength` in 2-D, \
         `id x y z vx vy vz mass strength` in 3-D)"
    )]
    Columns(String),
    /// An exported state has a body before its `# columns:` line.
    #[error("a body before the `# columns:` line: an exported state names its columns first")]
    NoColumns,
    /// An exported state has a second `# columns:` line.
    #[error(
        "a second `# columns:` line (the first is line {first}): one file holds bodies of one \
         dimension; remove one of them"
    )]
    ColumnsTwice {
        /// The line of the first `# columns:` line.
        first: usize,
    },
    /// A body line has the wrong number of values.
    #[error("{found} values where {} were expected ({})", .want.len(), .want.join(" "))]
    Count {
        /// Values on the line.
        found: usize,
        /// The column names expected, in order.
        want: Vec<&'static str>,
    },
    /// A value does not parse as a number.
    #[error("`{text}` (column {column}, {name}) is not a number")]
    NotANumber {
        /// The text found.
        text: String,
        /// Its column, counted from 1.
        column: usize,
        /// The column's name (`x`, `mass`, ...).
        name: &'static str,
    },
    /// A value is NaN or infinite.
    #[error("{name} (column {column}) is {value}: every value must be finite")]
    NotFinite {
        /// The value read.
        value: f64,
        /// Its column, counted from 1.
        column: usize,
        /// The column's name (`x`, `mass`, ...).
        name: &'static str,
    },
    /// A body's mass is 0 or negative; holds the mass.
    #[error("mass {0} is not positive: every body needs a mass greater than 0")]
    Mass(f64),
    /// An exported body's id is not a number below the body count.
    #[error("id `{text}` is not one of 0..{n} (ids count the bodies from 0)")]
    Id {
        /// The id as written.
        text: String,
        /// Bodies in the file: ids run over 0..n.
        n: usize,
    },
    /// Two exported bodies have the same id.
    #[error("id {id} is given twice (again on line {again})")]
    DuplicateId {
        /// The repeated id.
        id: usize,
        /// The line where it appears again (the error is reported at the first).
        again: usize,
    },
    /// The bodies' dimension is not the scenario's.
    #[error("the bodies are {file}-D ({format} format) but scenario `{scenario}` is {want}-D")]
    Dimension {
        /// Dimension of the bodies in the file.
        file: usize,
        /// Name of the file's format.
        format: &'static str,
        /// The scenario asked for, by its command-line name.
        scenario: &'static str,
        /// The scenario's dimension.
        want: usize,
    },
    /// A Barnes-Hut file (masses only) was given to coulomb, which needs charges.
    #[error(
        "a Barnes-Hut body file gives masses, not charges, so it cannot start coulomb: write \
         the bodies as an exported state (`nbody-bench export --format text` shows the columns), \
         whose strength column is the charge"
    )]
    NoCharges,
    /// A body's gravitational mass is negative in a gravity scenario; holds the strength.
    #[error("gravitational mass (strength) {0} is negative; gravity needs strengths of 0 or more")]
    NegativeStrength(f64),
    /// A body lies outside the scenario's reflecting box.
    #[error(
        "the body at {pos:?} is outside the reflecting box [0, {side}]^{dim} (scenario \
         `{scenario}`, side sqrt(n / density)): move it inside, or change --density"
    )]
    OutsideBox {
        /// Its position, in the file's dimension.
        pos: Vec<f64>,
        /// Side of the box, √(n/ρ).
        side: f64,
        /// Dimension of the box.
        dim: usize,
        /// The scenario asked for, by its command-line name.
        scenario: &'static str,
    },
}

/// Reads the bodies of `path` (with the bounded reader: a device or an endless pipe is refused).
pub fn read(path: &Path) -> Result<InitialBodies, InitialError> {
    let text = crate::input::read_text(path).map_err(|source| InitialError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse(path, &text)
}

/// The bodies of `text`, read from `path` (named in errors).
pub fn parse(path: &Path, text: &str) -> Result<InitialBodies, InitialError> {
    let err = |line: usize, problem| InitialError::Line {
        path: path.to_path_buf(),
        line,
        problem,
    };
    let first = text
        .lines()
        .map(str::trim)
        .enumerate()
        .find(|(_, l)| !l.is_empty());
    let format = match first {
        Some((i, l)) if l.starts_with(EXPORT_PREFIX) => {
            if l != EXPORT_HEADER {
                return Err(err(i + 1, LineProblem::Version(l.to_string())));
            }
            InitialFormat::Export
        }
        _ => InitialFormat::BarnesHut,
    };
    let mut reader = Reader {
        format,
        dim: (format == InitialFormat::BarnesHut).then_some(3),
        dim_line: 0,
        exported_from: None,
        rows: Vec::new(),
    };
    let mut lines = 0;
    for (i, line) in text.lines().enumerate() {
        lines = i + 1;
        reader.line(i + 1, line.trim()).map_err(|p| err(i + 1, p))?;
    }
    if reader.rows.is_empty() {
        return Err(InitialError::Empty {
            path: path.to_path_buf(),
            lines,
        });
    }
    let dim = reader.dim.unwrap_or(3);
    let dim_line = reader.dim_line;
    let exported_from = reader.exported_from.take();
    let bodies = reader.into_bodies().map_err(|(line, p)| err(line, p))?;
    Ok(InitialBodies {
        path: path.to_path_buf(),
        format,
        dim,
        dim_line,
        exported_from,
        bodies,
    })
}

/// The state of a file being read.
struct Reader {
    format: InitialFormat,
    /// Known from the columns line (export) or fixed (barnes-hut).
    dim: Option<usize>,
    dim_line: usize,
    exported_from: Option<String>,
    /// Each body with its id text (export) or none.
    rows: Vec<(Body, Option<String>)>,
}

impl Reader {
    fn line(&mut self, number: usize, line: &str) -> Result<(), LineProblem> {
        if line.is_empty() {
            return Ok(());
        }
        if let Some(comment) = line.strip_prefix('#') {
            if self.format == InitialFormat::Export {
                self.header(number, comment.trim())?;
            }
            return Ok(());
        }
        let fields: Vec<&str> = line.split_whitespace().collect();
        let (names, id) = match self.format {
            InitialFormat::BarnesHut => (BARNES_HUT_COLUMNS.to_vec(), None),
            InitialFormat::Export => {
                let dim = self.dim.ok_or(LineProblem::NoColumns)?;
                (export_columns(dim), fields.first().map(|s| s.to_string()))
            }
        };
        if fields.len() != names.len() {
            return Err(LineProblem::Count {
                found: fields.len(),
                want: names,
            });
        }
        if self.rows.is_empty() && self.format == InitialFormat::BarnesHut {
            self.dim_line = number;
        }
        let skip = id.is_some() as usize;
        let mut values = Vec::with_capacity(names.len());
        for (k, (&text, &name)) in fields.iter().zip(&names).enumerate().skip(skip) {
            let column = k + 1;
            let value: f64 = text.parse().map_err(|_| LineProblem::NotANumber {
                text: text.to_string(),
                column,
                name,
            })?;
            if !value.is_finite() {
                return Err(LineProblem::NotFinite {
                    value,
                    column,
                    name,
                });
            }
            values.push(value);
        }
        let body = match self.format {
            InitialFormat::BarnesHut => Body {
                mass: values[0],
                strength: values[0],
                pos: [values[1], values[2], values[3]],
                vel: [values[4], values[5], values[6]],
                line: number,
            },
            InitialFormat::Export => {
                let d = self.dim.expect("checked above");
                let mut body = Body {
                    pos: [0.0; 3],
                    vel: [0.0; 3],
                    mass: values[2 * d],
                    strength: values[2 * d + 1],
                    line: number,
                };
                body.pos[..d].copy_from_slice(&values[..d]);
                body.vel[..d].copy_from_slice(&values[d..2 * d]);
                body
            }
        };
        if body.mass <= 0.0 {
            return Err(LineProblem::Mass(body.mass));
        }
        self.rows.push((body, id));
        Ok(())
    }

    /// A `#` line of an exported state: the columns, and the scenario it came from.
    fn header(&mut self, number: usize, comment: &str) -> Result<(), LineProblem> {
        if let Some(columns) = comment.strip_prefix("columns:") {
            // A second line would switch the dimension of the bodies after it, silently.
            if self.dim.is_some() {
                return Err(LineProblem::ColumnsTwice {
                    first: self.dim_line,
                });
            }
            let columns = columns.split_whitespace().collect::<Vec<_>>().join(" ");
            let dim = [2, 3]
                .into_iter()
                .find(|&d| export_columns(d).join(" ") == columns)
                .ok_or(LineProblem::Columns(columns))?;
            self.dim = Some(dim);
            self.dim_line = number;
        } else if let Some(rest) = comment.strip_prefix("scenario ") {
            self.exported_from = rest.split_whitespace().next().map(str::to_string);
        }
        Ok(())
    }

    /// The bodies in id order (export) or file order (barnes-hut).
    fn into_bodies(self) -> Result<Vec<Body>, (usize, LineProblem)> {
        if self.format == InitialFormat::BarnesHut {
            return Ok(self.rows.into_iter().map(|(b, _)| b).collect());
        }
        let n = self.rows.len();
        let mut slots: Vec<Option<Body>> = vec![None; n];
        for (body, id) in self.rows {
            let text = id.unwrap_or_default();
            let id = text
                .parse::<usize>()
                .ok()
                .filter(|&i| i < n)
                .ok_or((body.line, LineProblem::Id { text, n }))?;
            if let Some(first) = &slots[id] {
                return Err((
                    first.line,
                    LineProblem::DuplicateId {
                        id,
                        again: body.line,
                    },
                ));
            }
            slots[id] = Some(body);
        }
        // n rows, n distinct ids below n: every slot is filled.
        Ok(slots.into_iter().flatten().collect())
    }
}

/// The column names of an exported state in `dim` dimensions (those `export` writes).
fn export_columns(dim: usize) -> Vec<&'static str> {
    let mut c = vec!["id"];
    c.extend(&["x", "y", "z"][..dim]);
    c.extend(&["vx", "vy", "vz"][..dim]);
    c.extend(["mass", "strength"]);
    c
}

impl InitialBodies {
    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.bodies.len()
    }

    /// Whether the file held no bodies (never true for a file that parsed).
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }

    /// Whether these bodies can start `scenario`, whose reflecting box (if any) has side
    /// `box_side`: the same dimension, charges for coulomb, non-negative gravitational masses
    /// for gravity, every body inside the walls.
    pub fn check(&self, scenario: ScenarioKind, box_side: Option<f64>) -> Result<(), InitialError> {
        let err = |line: usize, problem| InitialError::Line {
            path: self.path.clone(),
            line,
            problem,
        };
        if self.dim != scenario.dim() {
            return Err(err(
                self.dim_line,
                LineProblem::Dimension {
                    file: self.dim,
                    format: self.format.name(),
                    scenario: scenario.name(),
                    want: scenario.dim(),
                },
            ));
        }
        if self.format == InitialFormat::BarnesHut && scenario.law() == LawKind::Coulomb {
            return Err(err(self.dim_line, LineProblem::NoCharges));
        }
        for b in &self.bodies {
            if scenario.law() == LawKind::Gravity && b.strength < 0.0 {
                return Err(err(b.line, LineProblem::NegativeStrength(b.strength)));
            }
            if let Some(side) = box_side
                && b.pos[..self.dim]
                    .iter()
                    .any(|&x| !(0.0..=side).contains(&x))
            {
                let problem = LineProblem::OutsideBox {
                    pos: b.pos[..self.dim].to_vec(),
                    side,
                    dim: self.dim,
                    scenario: scenario.name(),
                };
                return Err(err(b.line, problem));
            }
        }
        Ok(())
    }

    /// The bodies as a state in precision `T`, ids in file order (export: the file's ids).
    pub(crate) fn state<T: Real, const D: usize>(&self) -> State<T, D> {
        let mut s = State::new(self.len());
        for (i, b) in self.bodies.iter().enumerate() {
            for d in 0..D {
                s.pos[d][i] = T::of(b.pos[d]);
                s.vel[d][i] = T::of(b.vel[d]);
            }
            s.mass[i] = T::of(b.mass);
            s.source[i] = T::of(b.strength);
        }
        s
    }
}

#[cfg(test)]
mod tests;
