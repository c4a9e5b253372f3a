//! `export-results`: the committed quick sweep as a tidy table. The CSV and the JSON lines hold
//! one row per sample with the results file's values to the bit (read back here, and by pandas
//! where it is installed), and bad input is refused with exit 2, naming the path.

use super::{bin, refused, text};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The columns in their order: a change here is a change every notebook reading the tables
/// sees.
const COLUMNS: [&str; 31] = [
    "key",
    "scenario",
    "kernel",
    "n",
    "threads",
    "ranks",
    "theta",
    "multipole",
    "order",
    "skin",
    "seed",
    "precision",
    "decomp",
    "time_factor",
    "round",
    "sample",
    "seconds_per_step",
    "steps_per_sample",
    "reference_s",
    "energy_drift",
    "force_error_median",
    "force_error_max",
    "pairs_interacting",
    "n_simulated",
    "config",
    "tool_version",
    "git_commit",
    "git_dirty",
    "simd",
    "profile",
    "host",
];

/// A copy of the committed quick sweep's results file in a temporary directory.
fn quick_copy() -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("results.json");
    let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("results/quick/results.json");
    std::fs::copy(committed, &path).unwrap();
    (dir, path)
}

/// `nbody-bench export-results ARGS` run in `dir`.
fn export(dir: &Path, args: &[&str]) -> Output {
    bin()
        .arg("export-results")
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn succeeded(o: &Output) {
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// The cells of an RFC 4180 text, row by row: `None` for an empty unquoted cell (null),
/// `Some` for any other, unquoted.
fn parse_csv(text: &str) -> Vec<Vec<Option<String>>> {
    let mut rows = Vec::new();
    let (mut row, mut cell) = (Vec::new(), String::new());
    let (mut quoted, mut in_quotes) = (false, false);
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match (in_quotes, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                cell.push('"');
            }
            (true, '"') => in_quotes = false,
            (true, c) => cell.push(c),
            (false, '"') => (quoted, in_quotes) = (true, true),
            (false, ',' | '\n') => {
                let value = std::mem::take(&mut cell);
                row.push((quoted || !value.is_empty()).then_some(value));
                quoted = false;
                if c == '\n' {
                    rows.push(std::mem::take(&mut row));
                }
            }
            (false, c) => cell.push(c),
        }
    }
    assert!(
        row.is_empty() && cell.is_empty(),
        "the last line ends with a line feed"
    );
    rows
}

/// A value of one sample read from the raw results file: `f(case, round, sample)`.
type Field<T> = fn(&Value, &Value, usize) -> Option<T>;

/// One value per sample of the raw results file, in file order: `f(case, round, sample)`.
fn per_sample<T>(raw: &Value, f: impl Fn(&Value, &Value, usize) -> T) -> Vec<T> {
    let mut out = Vec::new();
    for case in raw["cases"].as_array().unwrap() {
        for round in case["rounds"].as_array().unwrap() {
            for s in 0..round["samples_s"].as_array().unwrap().len() {
                out.push(f(case, round, s));
            }
        }
    }
    out
}

/// The column `name` of parsed CSV rows.
fn column<'a>(rows: &'a [Vec<Option<String>>], name: &str) -> Vec<Option<&'a str>> {
    let i = COLUMNS.iter().position(|c| *c == name).unwrap();
    rows.iter().map(|r| r[i].as_deref()).collect()
}

/// A CSV cell read as an f64's bits (`None` when empty).
fn bits(cell: Option<&str>) -> Option<u64> {
    cell.map(|c| c.parse::<f64>().unwrap().to_bits())
}

/// A JSON whole number as text (`None` for null).
fn whole(v: &Value) -> Option<String> {
    v.as_u64().map(|x| x.to_string())
}

/// A JSON number's bits (`None` for null).
fn json_bits(v: &Value) -> Option<u64> {
    (!v.is_null()).then(|| v.as_f64().unwrap().to_bits())
}

#[test]
fn csv_rows_read_back_to_the_results_values_bit_for_bit() {
    let (dir, path) = quick_copy();
    let o = export(dir.path(), &["results.json", "--out", "samples.csv"]);
    succeeded(&o);
    let csv = std::fs::read_to_string(dir.path().join("samples.csv")).unwrap();
    let raw: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let rows = parse_csv(&csv);
    let header: Vec<&str> = rows[0].iter().map(|c| c.as_deref().unwrap()).collect();
    assert_eq!(header, COLUMNS);
    let rows = &rows[1..];
    let total = per_sample(&raw, |_, _, _| ()).len();
    assert!(total > 100, "{total}");
    assert_eq!(rows.len(), total);
    assert!(rows.iter().all(|r| r.len() == COLUMNS.len()));
    // Every number reads back to the bits of the file; null is an empty cell, never 0.
    let checks: [(&str, Field<u64>); 5] = [
        ("seconds_per_step", |_, r, s| json_bits(&r["samples_s"][s])),
        ("reference_s", |_, r, s| json_bits(&r["reference_s"][s])),
        ("energy_drift", |_, r, _| json_bits(&r["energy_drift"])),
        ("force_error_median", |_, r, _| {
            json_bits(&r["force_error"][0])
        }),
        ("theta", |c, _, _| json_bits(&c["case"]["theta"])),
    ];
    for (name, want) in checks {
        let got: Vec<Option<u64>> = column(rows, name).into_iter().map(bits).collect();
        assert_eq!(got, per_sample(&raw, want), "{name}");
    }
    let strings: [(&str, Field<String>); 6] = [
        ("key", |c, _, _| c["key"].as_str().map(String::from)),
        ("n", |c, _, _| whole(&c["case"]["n"])),
        ("threads", |c, _, _| whole(&c["case"]["threads"])),
        ("steps_per_sample", |_, r, _| whole(&r["steps_per_sample"])),
        ("pairs_interacting", |_, r, _| {
            whole(&r["pairs_interacting"])
        }),
        ("sample", |_, _, s| Some(s.to_string())),
    ];
    for (name, want) in strings {
        let got: Vec<Option<String>> = column(rows, name)
            .into_iter()
            .map(|c| c.map(String::from))
            .collect();
        assert_eq!(got, per_sample(&raw, want), "{name}");
    }
    // The build's fields repeat on every row.
    let commit = raw["metadata"]["git_commit"].as_str().unwrap();
    assert!(
        column(rows, "git_commit")
            .iter()
            .all(|c| *c == Some(commit))
    );
    assert!(column(rows, "config").iter().all(|c| *c == Some("quick")));
    // The samples of each case sum to the file's (same values, same order).
    for case in raw["cases"].as_array().unwrap() {
        let key = case["key"].as_str().unwrap();
        let want: f64 = case["rounds"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|r| r["samples_s"].as_array().unwrap())
            .map(|s| s.as_f64().unwrap())
            .sum();
        let got: f64 = column(rows, "key")
            .iter()
            .zip(column(rows, "seconds_per_step"))
            .filter(|(k, _)| **k == Some(key))
            .map(|(_, s)| s.unwrap().parse::<f64>().unwrap())
            .sum();
        assert_eq!(got.to_bits(), want.to_bits(), "{key}");
    }
    // Standard output carries the same bytes.
    let o = export(dir.path(), &["results.json"]);
    succeeded(&o);
    assert_eq!(text(&o.stdout), csv);
}

#[test]
fn json_lines_hold_the_same_rows_in_the_column_order() {
    let (dir, _) = quick_copy();
    let o = export(dir.path(), &["results.json", "--format", "csv"]);
    succeeded(&o);
    let csv = parse_csv(&text(&o.stdout));
    let o = export(dir.path(), &["results.json", "--format", "jsonl"]);
    succeeded(&o);
    let lines = text(&o.stdout);
    assert_eq!(lines.lines().count(), csv.len() - 1);
    for (line, row) in lines.lines().zip(&csv[1..]) {
        let positions: Vec<usize> = COLUMNS
            .iter()
            .map(|c| line.find(&format!("\"{c}\":")).unwrap())
            .collect();
        assert!(positions.is_sorted(), "{line}");
        let object: Value = serde_json::from_str(line).unwrap();
        assert_eq!(object.as_object().unwrap().len(), COLUMNS.len());
        for (name, cell) in COLUMNS.iter().zip(row) {
            let v = &object[*name];
            match (v, cell) {
                (Value::Null, None) => {}
                (Value::String(s), Some(c)) => assert_eq!(s, c),
                (Value::Bool(b), Some(c)) => assert_eq!(&b.to_string(), c),
                (Value::Number(n), Some(c)) => assert_eq!(
                    n.as_f64().unwrap().to_bits(),
                    c.parse::<f64>().unwrap().to_bits(),
                    "{name}"
                ),
                _ => panic!("{name}: {v} in the JSON, {cell:?} in the CSV"),
            }
        }
    }
}

/// Reads both tables back with pandas and checks them against the results file read by
/// Python's json module.
const PANDAS_CHECK: &str = r#"
import json, sys
import pandas as pd
csv_path, jsonl_path, results_path = sys.argv[1:4]
columns = json.loads(sys.argv[4])
text = {"key": str, "git_commit": str}
tables = {
    "csv": pd.read_csv(csv_path, float_precision="round_trip", dtype=text),
    "jsonl": pd.read_json(jsonl_path, lines=True, precise_float=True, dtype=text,
                          convert_dates=False),
}
with open(results_path) as f:
    results = json.load(f)
cases = results["cases"]
samples = {c["key"]: [s for r in c["rounds"] for s in r["samples_s"]] for c in cases}
rows = [(c, r, i) for c in cases for r in c["rounds"] for i in range(len(r["samples_s"]))]
nullable = {
    "energy_drift": lambda c, r, i: r["energy_drift"],
    "force_error_median": lambda c, r, i: (r["force_error"] or [None])[0],
    "reference_s": lambda c, r, i: r["reference_s"][i] if r["reference_s"] else None,
    "theta": lambda c, r, i: c["case"]["theta"],
}
for name, df in tables.items():
    assert list(df.columns) == columns, (name, list(df.columns))
    assert len(df) == sum(map(len, samples.values())), (name, len(df))
    for key, want in samples.items():
        got = df.loc[df["key"] == key, "seconds_per_step"].tolist()
        assert got == want, (name, key, got, want)
        assert sum(got) == sum(want), (name, key)
    for column, value in nullable.items():
        got = [None if pd.isna(x) else x for x in df[column]]
        assert got == [value(*row) for row in rows], (name, column)
    assert df["n"].tolist() == [c["case"]["n"] for c, _, _ in rows], name
    assert df["git_dirty"].dtype == bool, (name, df["git_dirty"].dtype)
    assert (df["git_commit"] == results["metadata"]["git_commit"]).all(), name
print(f"pandas {pd.__version__}: {len(tables['csv'])} rows read back")
"#;

/// A Python that imports pandas: the peers' venv (scripts/install-fmm3d.sh), else `python3`.
pub fn python_with_pandas() -> Result<PathBuf, String> {
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join(".peers/venv/bin/python");
    for python in [venv, PathBuf::from("python3")] {
        let imports = Command::new(&python)
            .args(["-c", "import pandas"])
            .output()
            .is_ok_and(|o| o.status.success());
        if imports {
            return Ok(python);
        }
    }
    Err(
        "neither .peers/venv/bin/python nor python3 imports pandas (scripts/install-fmm3d.sh \
         installs it in .peers/venv)"
            .into(),
    )
}

#[test]
fn pandas_reads_both_tables_back_exactly() {
    let python = match python_with_pandas() {
        Ok(p) => p,
        // scripts/test.sh installs pandas before the suite: in CI a missing one is a failure,
        // not a check quietly skipped.
        Err(why) if std::env::var_os("CI").is_some() => panic!("{why}"),
        Err(why) => return eprintln!("skipped: {why}"),
    };
    let (dir, path) = quick_copy();
    for (format, out) in [("csv", "s.csv"), ("jsonl", "s.jsonl")] {
        succeeded(&export(
            dir.path(),
            &["results.json", "--format", format, "--out", out],
        ));
    }
    let o = Command::new(&python)
        .args(["-c", PANDAS_CHECK])
        .arg(dir.path().join("s.csv"))
        .arg(dir.path().join("s.jsonl"))
        .arg(&path)
        .arg(serde_json::to_string(&COLUMNS).unwrap())
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{}: {}{}",
        python.display(),
        text(&o.stdout),
        text(&o.stderr)
    );
    eprintln!("{}", text(&o.stdout).trim());
}

#[test]
fn bad_input_and_outputs_are_refused_with_exit_2() {
    let (dir, path) = quick_copy();
    let before = std::fs::read(&path).unwrap();
    // The input as the output, by its name and through a link.
    let o = export(dir.path(), &["results.json", "--out", "results.json"]);
    refused(&o, "--out results.json: is also an input");
    std::os::unix::fs::symlink(&path, dir.path().join("link.csv")).unwrap();
    let o = export(dir.path(), &["results.json", "--out", "link.csv"]);
    refused(&o, "--out link.csv: is also an input");
    assert_eq!(std::fs::read(&path).unwrap(), before);
    // A missing input, an output in a missing directory, a bad format.
    refused(&export(dir.path(), &["missing.json"]), "missing.json");
    let o = export(dir.path(), &["results.json", "--out", "no/such/dir.csv"]);
    refused(&o, "no/such/dir.csv");
    let o = export(dir.path(), &["results.json", "--format", "xlsx"]);
    refused(&o, "invalid value 'xlsx' for '--format <FORMAT>'");
    // A file that is not a results file.
    let truncated = dir.path().join("truncated.json");
    std::fs::write(&truncated, &before[..before.len() / 2]).unwrap();
    let o = export(dir.path(), &["truncated.json", "--out", "t.csv"]);
    refused(&o, "truncated.json is not a valid results file");
    assert!(!dir.path().join("t.csv").exists());
}

#[test]
fn the_help_and_the_outputs_page_name_every_column() {
    let o = bin().args(["export-results", "--help"]).output().unwrap();
    succeeded(&o);
    let help = text(&o.stdout);
    let page = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/reference/outputs.md"),
    )
    .unwrap();
    let section = page
        .split("## `export-results`")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .expect("docs/reference/outputs.md has a section on export-results");
    for c in COLUMNS {
        assert!(help.contains(&format!("  {c} ")), "--help: {c}");
        assert!(
            section.contains(&format!("`{c}`")),
            "docs/reference/outputs.md's export-results section does not name `{c}`"
        );
    }
}
