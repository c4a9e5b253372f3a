//! `export-results` of a performance history: one row per record, the case key taken apart
//! into its fields, read back by pandas (CSV and JSON lines) to the records' values exactly —
//! floats to the bit, nulls as nulls — with a damaged line named and left out.

use super::export_results::python_with_pandas;
use super::{bin, refused, text};
use serde_json::{Value, json};
use std::path::Path;
use std::process::{Command, Output};

/// The committed history's machine class; a history file holds the records of the class it is
/// named after.
const CLASS: &str = "AuthenticAMD-26-2-1-2cpu";

/// The committed history, with records that exercise every optional field appended, and one
/// damaged line between them, as `dir/<CLASS>.jsonl`.
fn history_copy(dir: &Path) -> std::path::PathBuf {
    let committed =
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("results/history/{CLASS}.jsonl"));
    let mut text = std::fs::read_to_string(committed).unwrap();
    let first: Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
    let mut bare = first.clone();
    bare["case"] =
        json!("galaxy/octree/n=4000/p=2/r=3/seed=7/theta=0.5/quadrupole/f32/time-x2/octants");
    bare["n"] = json!(4000);
    bare["commit"] = json!("");
    bare["parent"] = Value::Null;
    bare["commit_date"] = Value::Null;
    bare["dirty"] = json!(true);
    bare["normalized"] = Value::Null;
    bare["work"] = Value::Null;
    bare["median_s"] = json!(1.0000000000000002e-7);
    bare["build"]["features"] = json!(["mpi", "test-slowdown"]);
    let mut fmm = first.clone();
    fmm["case"] = json!("coulomb/fmm/n=2000/p=1/r=1/seed=1/theta=0.25/order=6");
    fmm["n"] = json!(2000);
    text.push_str("{\"schema\": \"nbody-bench-history/1\", \"commit\": \n");
    for record in [bare, fmm] {
        text.push_str(&format!("{record}\n"));
    }
    let path = dir.join(format!("{CLASS}.jsonl"));
    std::fs::write(&path, text).unwrap();
    path
}

fn export(dir: &Path, args: &[&str]) -> Output {
    bin()
        .arg("export-results")
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

/// Checks both tables against the history file read by Python's json module.
const PANDAS_CHECK: &str = r#"
import json, math, sys
import pandas as pd
csv_path, jsonl_path, history_path = sys.argv[1:4]
text = {c: str for c in ["case", "commit", "parent", "features", "measured", "commit_date"]}
tables = {
    "csv": pd.read_csv(csv_path, float_precision="round_trip", dtype=text),
    "jsonl": pd.read_json(jsonl_path, lines=True, precise_float=True, dtype=text,
                          convert_dates=False),
}
records = []
with open(history_path) as f:
    for line in f:
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            pass
def null(x):
    return x is None or (isinstance(x, float) and math.isnan(x))
def same(got, want):
    if null(want) or want == "":
        return null(got) or got == ""
    return got == want
norm = lambda r, i: (r["normalized"] or {}).get("median") if i is None else ((r["normalized"] or {}).get("ci95") or [None, None])[i]
expect = {
    "case": lambda r: r["case"],
    "commit": lambda r: r["commit"],
    "parent": lambda r: r["parent"],
    "commit_date": lambda r: r["commit_date"],
    "dirty": lambda r: r["dirty"],
    "measured": lambda r: r["measured"],
    "class": lambda r: r["class"],
    "simd": lambda r: r["build"]["simd"],
    "features": lambda r: "+".join(r["build"]["features"]),
    "source": lambda r: r["source"],
    "median_s": lambda r: r["median_s"],
    "ci95_lo_s": lambda r: r["ci95_s"][0],
    "ci95_hi_s": lambda r: r["ci95_s"][1],
    "normalized_median": lambda r: norm(r, None),
    "normalized_ci95_lo": lambda r: norm(r, 0),
    "normalized_ci95_hi": lambda r: norm(r, 1),
    "samples": lambda r: r["samples"],
    "n": lambda r: r["n"],
}
for name in ["pair_checks", "pairs_interacting", "cells_visited", "nodes_opened",
             "nodes_accepted", "rebuilds", "list_entries"]:
    expect["work_" + name] = lambda r, name=name: (r["work"] or {}).get(name)
for name, df in tables.items():
    assert len(df) == len(records), (name, len(df), len(records))
    for column, want in expect.items():
        got = df[column].tolist()
        bad = [(i, g, want(r)) for i, (g, r) in enumerate(zip(got, records)) if not same(g, want(r))]
        assert not bad, (name, column, bad[:3])
    last = df.iloc[-2]
    assert (last["scenario"], last["kernel"], last["threads"], last["ranks"], last["seed"]) == ("galaxy", "octree", 2, 3, 7), (name, last)
    assert (last["theta"], last["multipole"], last["precision"], last["time_factor"], last["decomp"]) == (0.5, "quadrupole", "f32", 2, "octants"), (name, last)
    assert df.iloc[-1]["order"] == 6 and null(df.iloc[-1]["multipole"]), name
print(f"pandas {pd.__version__}: {len(records)} history records read back")
"#;

#[test]
fn a_history_round_trips_through_csv_and_json_lines_read_by_pandas() {
    let python = match python_with_pandas() {
        Ok(p) => p,
        Err(why) if std::env::var_os("CI").is_some() => panic!("{why}"),
        Err(why) => return eprintln!("skipped: {why}"),
    };
    let dir = tempfile::tempdir().unwrap();
    let history = history_copy(dir.path());
    let lines = std::fs::read_to_string(&history).unwrap().lines().count();
    let file = format!("{CLASS}.jsonl");
    for (format, out) in [("csv", "h.csv"), ("jsonl", "h.jsonl")] {
        let o = export(dir.path(), &[&file, "--format", format, "--out", out]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        // The damaged line is named by its number and left out; the rest is exported.
        let damaged = format!("{file} line {}:", lines - 2);
        assert!(text(&o.stderr).contains(&damaged), "{}", text(&o.stderr));
        assert!(text(&o.stderr).contains(&format!("{} records", lines - 1)));
    }
    let o = Command::new(&python)
        .args(["-c", PANDAS_CHECK])
        .args(["h.csv", "h.jsonl", &file])
        .current_dir(dir.path())
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
fn a_folder_of_histories_exports_every_class_and_never_overwrites_one() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("history");
    std::fs::create_dir(&folder).unwrap();
    let one = history_copy(dir.path());
    let records = std::fs::read_to_string(&one).unwrap();
    for class in ["ClassA-2cpu", "ClassB-2cpu"] {
        let path = folder.join(format!("{class}.jsonl"));
        std::fs::write(path, records.replace(CLASS, class)).unwrap();
    }
    let o = export(dir.path(), &["history"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let single = export(dir.path(), &[&format!("{CLASS}.jsonl")]);
    let rows = |o: &Output| text(&o.stdout).lines().count() - 1;
    assert!(rows(&single) > 2000, "{}", text(&single.stderr));
    assert_eq!(rows(&o), 2 * rows(&single));
    let before = std::fs::read(folder.join("ClassA-2cpu.jsonl")).unwrap();
    refused(
        &export(
            dir.path(),
            &["history", "--out", "history/ClassA-2cpu.jsonl"],
        ),
        "is also an input of this command (HISTORY)",
    );
    assert_eq!(
        std::fs::read(folder.join("ClassA-2cpu.jsonl")).unwrap(),
        before
    );
}

#[test]
fn the_help_and_the_outputs_page_name_every_history_column() {
    let o = bin().args(["export-results", "--help"]).output().unwrap();
    assert!(o.status.success());
    let help = text(&o.stdout);
    let page = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/reference/outputs.md"),
    )
    .unwrap();
    let section = page
        .split("**A history**")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .expect("docs/reference/outputs.md's export-results section has a history part");
    for (c, _) in nbody_harness::history::tidy::HISTORY_COLUMNS {
        assert!(help.contains(&format!("  {c} ")), "--help: {c}");
        assert!(
            section.contains(&format!("`{c}`")),
            "outputs.md does not name `{c}`"
        );
    }
}

/// `value` as Python's `json.dumps` writes it: a space after every `:` and `,`.
fn spaced(value: &Value) -> String {
    match value {
        Value::Object(map) => {
            let fields: Vec<String> = map
                .iter()
                .map(|(k, v)| format!("{}: {}", Value::from(k.as_str()), spaced(v)))
                .collect();
            format!("{{{}}}", fields.join(", "))
        }
        Value::Array(items) => {
            let items: Vec<String> = items.iter().map(spaced).collect();
            format!("[{}]", items.join(", "))
        }
        other => other.to_string(),
    }
}

#[test]
fn a_history_is_known_by_its_records_whatever_their_spacing_or_first_line() {
    let dir = tempfile::tempdir().unwrap();
    let committed = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("results/history/{CLASS}.jsonl")),
    )
    .unwrap();
    let records: Vec<Value> = committed
        .lines()
        .take(5)
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let folder = dir.path().join("history");
    std::fs::create_dir(&folder).unwrap();
    // One file as json.dumps writes it; one whose first line a writer left half-written.
    let python: String = records.iter().map(|r| spaced(r) + "\n").collect();
    // Keys sorted (as `json.dumps(sort_keys=True)` writes them): the schema not first.
    assert!(python.starts_with("{\"build\": {"), "{python}");
    assert!(
        python.contains("\"schema\": \"nbody-bench-history/1\", "),
        "{python}"
    );
    let damaged = format!(
        "{{\"schema\": \"nbody-bench-hist\n{}",
        records.iter().map(|r| format!("{r}\n")).collect::<String>()
    );
    let [spaced_file, damaged_file] =
        ["AuthenticAMD-26-2-1-2cpu.jsonl", "Damaged-1cpu.jsonl"].map(|name| folder.join(name));
    std::fs::write(&spaced_file, &python).unwrap();
    std::fs::write(
        &damaged_file,
        damaged.replace("AuthenticAMD-26-2-1-2cpu", "Damaged-1cpu"),
    )
    .unwrap();
    let rows = |o: &Output| text(&o.stdout).lines().count() - 1;
    let o = export(dir.path(), &["history/AuthenticAMD-26-2-1-2cpu.jsonl"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(rows(&o), 5);
    let o = export(dir.path(), &["history"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(rows(&o), 10, "both files, every record");
    assert!(
        text(&o.stderr).contains("Damaged-1cpu.jsonl line 1: not a history record"),
        "{}",
        text(&o.stderr)
    );
    // Neither is ever overwritten: each is an input of the folder's export, and a file that
    // holds history records is no output of any export.
    let before = [&spaced_file, &damaged_file].map(|f| std::fs::read(f).unwrap());
    refused(
        &export(
            dir.path(),
            &["history", "--out", "history/Damaged-1cpu.jsonl"],
        ),
        "is also an input of this command (HISTORY)",
    );
    let results = dir.path().join("results.json");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("results/quick/results.json"),
        &results,
    )
    .unwrap();
    for out in [
        "history/AuthenticAMD-26-2-1-2cpu.jsonl",
        "history/Damaged-1cpu.jsonl",
    ] {
        refused(
            &export(
                dir.path(),
                &["results.json", "--format", "jsonl", "--out", out],
            ),
            "history records (lines of schema nbody-bench-history/1): export-results never \
             replaces a history",
        );
    }
    assert_eq!(
        [&spaced_file, &damaged_file].map(|f| std::fs::read(f).unwrap()),
        before
    );
}
