//! Tidy tables: one row per observation, one column per variable, written as CSV or as JSON
//! lines, the way hyperfine's `--export-csv` serves notebooks (pandas, polars, R) that would
//! otherwise walk the nested results file themselves.
//!
//! A [`TidyTable`] holds plain JSON values, so any record becomes rows the same way (a results
//! file's samples here, [`samples`]; the performance history elsewhere) and is written by the
//! same two writers. Null is "not measured": an empty CSV cell, JSON `null`, never 0. Text
//! that starts like a spreadsheet formula (`=`, `+`, `-`, `@`) is written with a `'` in front,
//! in both formats.

use super::results::ResultsFile;
use nbody_engine::output::neutral::spreadsheet::text_cell;
use serde_json::Value;
use std::borrow::Cow;

/// Named columns and rows of JSON values, every row as long as `columns`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TidyTable {
    /// Column names, in the order written (the CSV header, the JSON keys' order).
    pub columns: Vec<String>,
    /// The observations, each one value per column; `null` where nothing was measured.
    pub rows: Vec<Vec<Value>>,
}

/// The two ways a table is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TidyFormat {
    /// A header row, then one line per row: RFC 4180 quoting, '.' decimals, numbers in the
    /// shortest form that reads back to the same f64, an empty cell where nothing was measured.
    Csv,
    /// One JSON object per line with the same columns in the same order; `null` where nothing
    /// was measured.
    Jsonl,
}

impl TidyFormat {
    /// The text of `table` in this format.
    pub fn write(self, table: &TidyTable) -> String {
        match self {
            TidyFormat::Csv => table.to_csv(),
            TidyFormat::Jsonl => table.to_jsonl(),
        }
    }
}

impl TidyTable {
    /// An empty table with these column names.
    pub fn new<S: Into<String>>(columns: impl IntoIterator<Item = S>) -> TidyTable {
        TidyTable {
            columns: columns.into_iter().map(Into::into).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row: one value per column, in the columns' order.
    pub fn push(&mut self, row: Vec<Value>) {
        assert_eq!(
            row.len(),
            self.columns.len(),
            "a tidy row has one value per column"
        );
        self.rows.push(row);
    }

    /// The header line and one line per row, each ended by `\n`.
    pub fn to_csv(&self) -> String {
        let mut text = String::new();
        let header = self.columns.iter().map(|c| quote(c));
        push_line(&mut text, header);
        for row in &self.rows {
            push_line(&mut text, row.iter().map(csv_cell));
        }
        text
    }

    /// One object per row and line, its keys the columns in their order (a JSON map would sort
    /// them); a text value that a spreadsheet would run as a formula with a `'` in front
    /// ([`text_cell`]), as in the CSV.
    pub fn to_jsonl(&self) -> String {
        let mut text = String::new();
        for row in &self.rows {
            text.push('{');
            for (i, (column, value)) in self.columns.iter().zip(row).enumerate() {
                if i > 0 {
                    text.push(',');
                }
                text.push_str(&Value::String(column.clone()).to_string());
                text.push(':');
                match value {
                    Value::String(s) => {
                        let cell = text_cell(s).into_owned();
                        text.push_str(&Value::String(cell).to_string());
                    }
                    other => text.push_str(&other.to_string()),
                }
            }
            text.push_str("}\n");
        }
        text
    }
}

fn push_line<'a>(text: &mut String, cells: impl Iterator<Item = Cow<'a, str>>) {
    for (i, cell) in cells.enumerate() {
        if i > 0 {
            text.push(',');
        }
        text.push_str(&cell);
    }
    text.push('\n');
}

/// A value as a CSV cell: null empty; numbers as Rust prints them (`{}`: the shortest decimal
/// that reads back to the same f64, never an exponent); an empty string quoted, so that it
/// differs from null; text that a spreadsheet would run as a formula with a `'` in front
/// ([`text_cell`]); an array or object as its compact JSON.
fn csv_cell(value: &Value) -> Cow<'_, str> {
    match value {
        Value::Null => Cow::Borrowed(""),
        Value::Bool(b) => Cow::Owned(b.to_string()),
        Value::Number(n) => Cow::Owned(match (n.as_u64(), n.as_i64(), n.as_f64()) {
            (Some(u), _, _) => u.to_string(),
            (None, Some(i), _) => i.to_string(),
            (None, None, Some(f)) => format!("{f}"),
            (None, None, None) => n.to_string(),
        }),
        Value::String(s) if s.is_empty() => Cow::Borrowed("\"\""),
        Value::String(s) => match text_cell(s) {
            Cow::Borrowed(s) => quote(s),
            Cow::Owned(s) => Cow::Owned(quote(&s).into_owned()),
        },
        Value::Array(_) | Value::Object(_) => Cow::Owned(quote(&value.to_string()).into_owned()),
    }
}

/// RFC 4180: a field holding a comma, a double quote or a line break is enclosed in double
/// quotes, each double quote inside doubled.
fn quote(field: &str) -> Cow<'_, str> {
    if field.contains([',', '"', '\n', '\r']) {
        Cow::Owned(format!("\"{}\"", field.replace('"', "\"\"")))
    } else {
        Cow::Borrowed(field)
    }
}

/// The columns of [`samples`] and what each holds; `export-results --help` and
/// docs/reference/outputs.md list them from here.
pub const SAMPLE_COLUMNS: [(&str, &str); 31] = [
    ("key", "the case key, unique in the file"),
    ("scenario", "the scenario simulated"),
    (
        "kernel",
        "the built-in kernel, or the external program's name",
    ),
    ("n", "particles the case asked for"),
    ("threads", "threads per rank"),
    ("ranks", "MPI ranks (1 without MPI)"),
    ("theta", "opening angle (octree and fmm; else empty)"),
    (
        "multipole",
        "the octree's expansion order, monopole or quadrupole (else empty)",
    ),
    ("order", "the fmm's expansion order p (else empty)"),
    (
        "skin",
        "the neighbour-list skin when the config set one (else empty: the kernel's default)",
    ),
    ("seed", "seed of the initial state"),
    (
        "precision",
        "f32 or f64: the config's, else the scenario's default",
    ),
    ("decomp", "the MPI decomposition (empty without MPI)"),
    (
        "time_factor",
        "simulated-time factor of a weak-by-time study (else 1)",
    ),
    ("round", "the round's index in the case, from 0"),
    ("sample", "the sample's index in its round, from 0"),
    (
        "seconds_per_step",
        "the sample: mean wall time of its steps, seconds",
    ),
    (
        "steps_per_sample",
        "steps timed in each sample of the round",
    ),
    (
        "reference_s",
        "the reference workload timed right before this sample, seconds (empty when not asked)",
    ),
    (
        "energy_drift",
        "the round's relative energy drift (empty when not measured: an external program, a \
         system of zero initial energy under MPI)",
    ),
    (
        "force_error_median",
        "the round's median relative force error (empty when not checked)",
    ),
    (
        "force_error_max",
        "the round's largest relative force error (empty when not checked)",
    ),
    (
        "pairs_interacting",
        "interacting pairs in the round's final state (empty for an external program)",
    ),
    (
        "n_simulated",
        "particles the round simulated (below n only with allow_fewer)",
    ),
    ("config", "the sweep config's name"),
    ("tool_version", "the nbody-bench version that measured"),
    ("git_commit", "the commit it was built from"),
    ("git_dirty", "whether the work tree had uncommitted changes"),
    ("simd", "the instruction set the pair loops ran with"),
    ("profile", "the cargo profile (release or debug)"),
    ("host", "the machine's host name"),
];

/// One row per sample of `results`: the case's fields, the round's index and values, the
/// sample's, and the sweep's build, repeated on every row so that files of several sweeps can
/// be concatenated. Cases, rounds and samples in file order.
pub fn samples(results: &ResultsFile) -> TidyTable {
    let mut table = TidyTable::new(SAMPLE_COLUMNS.map(|(name, _)| name));
    let meta = &results.metadata;
    let build = [
        Value::from(results.config.name.as_str()),
        Value::from(meta.tool_version.as_str()),
        Value::from(meta.git_commit.as_str()),
        Value::from(meta.git_dirty),
        Value::from(meta.simd.as_str()),
        Value::from(meta.profile.as_str()),
        Value::from(meta.host.as_str()),
    ];
    for record in &results.cases {
        let case = &record.case;
        let multipole = (case.kernel == nbody_engine::kernels::KernelKind::Octree)
            .then(|| case.multipole.name());
        let precision = case.precision.unwrap_or(case.scenario.defaults().precision);
        let fields = [
            Value::from(record.key.as_str()),
            Value::from(case.scenario.name()),
            Value::from(case.kernel.name()),
            Value::from(case.n),
            Value::from(case.threads),
            Value::from(case.ranks),
            Value::from(case.theta),
            Value::from(multipole),
            Value::from(case.order),
            Value::from(case.skin),
            Value::from(case.seed),
            Value::from(precision.name()),
            Value::from(case.decomp.map(|d| d.name())),
            Value::from(case.time_factor),
        ];
        for (r, round) in record.rounds.iter().enumerate() {
            // Reference timings pair with samples only when there is one per sample.
            let paired = round.reference_s.len() == round.samples_s.len();
            let [error_median, error_max] = round.force_error.map_or([None, None], |e| e.map(Some));
            // An external program counts no pairs and measures no drift (files of earlier
            // versions hold 0 for its drift): not measured.
            let ours = round.external.is_none();
            for (s, &seconds) in round.samples_s.iter().enumerate() {
                let mut row = fields.to_vec();
                row.extend([
                    Value::from(r),
                    Value::from(s),
                    Value::from(seconds),
                    Value::from(round.steps_per_sample),
                    Value::from(paired.then(|| round.reference_s[s])),
                    Value::from(round.energy_drift),
                    Value::from(error_median),
                    Value::from(error_max),
                    Value::from(round.pairs_interacting.filter(|_| ours)),
                    Value::from(round.n),
                ]);
                row.extend(build.iter().cloned());
                table.push(row);
            }
        }
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn table() -> TidyTable {
        let mut t = TidyTable::new(["name", "x", "note"]);
        t.push(vec![json!("a,b"), json!(0.1), Value::Null]);
        t.push(vec![json!("say \"hi\"\nbye"), json!(-3), json!("")]);
        t.push(vec![json!(true), json!(1e-300), json!([1, "x"])]);
        t
    }

    #[test]
    fn csv_quotes_as_rfc_4180_and_leaves_null_empty() {
        let tiny = format!("{}", 1e-300);
        assert_eq!(
            table().to_csv(),
            format!(
                "name,x,note\n\"a,b\",0.1,\n\"say \"\"hi\"\"\nbye\",-3,\"\"\ntrue,{tiny},\
                 \"[1,\"\"x\"\"]\"\n"
            )
        );
        assert_eq!(tiny.parse::<f64>().unwrap(), 1e-300);
    }

    #[test]
    fn text_that_starts_like_a_formula_is_written_as_text_and_numbers_as_numbers() {
        let mut t = TidyTable::new(["key", "x"]);
        t.push(vec![json!("=HYPERLINK(\"http://x\",\"y\")"), json!(-1.5)]);
        t.push(vec![json!("@SUM(A1)"), json!("-1.5")]);
        assert_eq!(
            t.to_csv(),
            "key,x\n\"'=HYPERLINK(\"\"http://x\"\",\"\"y\"\")\",-1.5\n'@SUM(A1),-1.5\n"
        );
        assert_eq!(
            t.to_jsonl(),
            "{\"key\":\"'=HYPERLINK(\\\"http://x\\\",\\\"y\\\")\",\"x\":-1.5}\n\
             {\"key\":\"'@SUM(A1)\",\"x\":\"-1.5\"}\n"
        );
    }

    #[test]
    fn jsonl_keeps_the_column_order_and_null() {
        let text = table().to_jsonl();
        let first = text.lines().next().unwrap();
        assert_eq!(first, r#"{"name":"a,b","x":0.1,"note":null}"#);
        for (line, row) in text.lines().zip(&table().rows) {
            let v: Value = serde_json::from_str(line).unwrap();
            for (column, value) in table().columns.iter().zip(row) {
                assert_eq!(&v[column], value);
            }
        }
    }

    #[test]
    fn numbers_read_back_to_the_same_bits() {
        for x in [0.1, 1.0 / 3.0, 8.791470338983051e-5, f64::MAX, 5e-324, -0.0] {
            let mut t = TidyTable::new(["x"]);
            t.push(vec![json!(x)]);
            let csv = t.to_csv();
            let cell = csv.lines().nth(1).unwrap();
            assert_eq!(
                cell.parse::<f64>().unwrap().to_bits(),
                x.to_bits(),
                "{cell}"
            );
            let line: Value = serde_json::from_str(t.to_jsonl().trim()).unwrap();
            assert_eq!(line["x"].as_f64().unwrap().to_bits(), x.to_bits());
        }
    }

    #[test]
    #[should_panic(expected = "one value per column")]
    fn a_short_row_is_a_bug() {
        TidyTable::new(["a", "b"]).push(vec![Value::Null]);
    }

    #[test]
    fn the_quick_sweep_gives_a_row_per_sample() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../results/quick/results.json"
        );
        let file = ResultsFile::load(std::path::Path::new(path)).unwrap();
        let t = samples(&file);
        let total: usize = file
            .cases
            .iter()
            .flat_map(|c| &c.rounds)
            .map(|r| r.samples_s.len())
            .sum();
        assert_eq!(t.rows.len(), total);
        let col = |name: &str| t.columns.iter().position(|c| c == name).unwrap();
        let first = &t.rows[0];
        assert_eq!(first[col("key")], json!(file.cases[0].key));
        assert_eq!(
            first[col("seconds_per_step")],
            json!(file.cases[0].rounds[0].samples_s[0])
        );
        assert_eq!(first[col("force_error_median")], Value::Null);
        assert_eq!(first[col("git_commit")], json!(file.metadata.git_commit));
    }

    #[test]
    fn an_external_programs_drift_and_pairs_are_not_measured() {
        // Written when an external round's drift was stored as 0.
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../results/vs-lammps/results.json"
        );
        let t = samples(&ResultsFile::load(std::path::Path::new(path)).unwrap());
        let col = |name: &str| t.columns.iter().position(|c| c == name).unwrap();
        let external: Vec<_> = t
            .rows
            .iter()
            .filter(|r| r[col("kernel")] == json!("lammps"))
            .collect();
        assert!(!external.is_empty());
        for row in external {
            assert_eq!(row[col("energy_drift")], Value::Null);
            assert_eq!(row[col("pairs_interacting")], Value::Null);
            assert!(row[col("seconds_per_step")].as_f64().unwrap() > 0.0);
        }
    }
}
