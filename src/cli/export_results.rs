//! `nbody-bench export-results`: a results file, or a performance history, as a tidy table for
//! notebooks: one row per sample (`nbody_records::tidy::samples`) or per history record
//! (`nbody_harness::history::tidy::records`).

use crate::cli::args::ExportResultsArgs;
use nbody_engine::output::neutral::control::visible;
use nbody_harness::history::store::{self, HISTORY_SCHEMA, History};
use nbody_records::locate;
use nbody_records::results::ResultsFile;
use nbody_records::tidy::{self, TidyTable};
use std::path::{Path, PathBuf};

pub fn export_results(args: ExportResultsArgs) -> anyhow::Result<i32> {
    let history = history_input(&args.results)?;
    if history.is_none() && args.results.is_dir() && !args.results.join("results.json").exists() {
        anyhow::bail!(
            "{} holds neither a results.json nor a history file (<class>.jsonl): pass a run \
             directory, a results.json, a history file or the folder of them (results/history)",
            args.results.display()
        );
    }
    let path = match &history {
        Some(_) => args.results.clone(),
        None => locate::find_results(&args.results, Path::new("results"))?,
    };
    if path != args.results {
        eprintln!("exporting {}", path.display());
    }
    // The output is checked before anything is written: never an input (through a link
    // either), never a directory or a device, never a file that holds history records.
    if let Some(out) = &args.out {
        let inputs: Vec<(&str, &Path)> = match &history {
            Some(h) => h.read.iter().map(|f| ("HISTORY", f.as_path())).collect(),
            None => vec![("RESULTS", path.as_path())],
        };
        nbody_engine::output::check_outputs(&[("--out", out)], &inputs)?;
        refuse_a_history(out)?;
    }
    let (table, what) = match &history {
        Some(h) => history_table(h),
        None => {
            let results = ResultsFile::load(&path)?;
            let table = tidy::samples(&results);
            if table.rows.is_empty() {
                eprintln!(
                    "warning: {} has no successful sample: the table has no rows",
                    path.display()
                );
            }
            let what = format!(
                "{} samples of {} cases",
                table.rows.len(),
                results.cases.len()
            );
            (table, what)
        }
    };
    let text = args.format.write(&table);
    match &args.out {
        Some(out) => {
            nbody_engine::output::write_atomic(out, text.as_bytes())?;
            eprintln!("wrote {} ({what})", out.display());
        }
        None => out!("{text}"),
    }
    Ok(0)
}

/// The history files an input names, each read once by the history's reader.
struct HistoryInput {
    /// The history files (a line of the history's schema in each, however damaged), sorted.
    files: Vec<(PathBuf, History)>,
    /// Every file read to find them: the history files, and the `.jsonl` files of a folder that
    /// turned out to hold no record. None of them is ever an output.
    read: Vec<PathBuf>,
}

/// The history `input` names: a file with a line whose `schema` field is the history's (by
/// the parsed field, not the text: spaces, key order or a damaged first line change nothing),
/// or a folder of `<class>.jsonl` files (every class; the gate's `<class>.gate.jsonl` aside).
/// `None` for anything else (a results file, a run or a config name).
fn history_input(input: &Path) -> anyhow::Result<Option<HistoryInput>> {
    let candidates: Vec<PathBuf> = if input.is_dir() {
        let mut files: Vec<PathBuf> = std::fs::read_dir(input)
            .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", input.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                let name = p.file_name().unwrap_or_default().to_string_lossy();
                name.ends_with(".jsonl") && !name.ends_with(".gate.jsonl") && p.is_file()
            })
            .collect();
        files.sort();
        files
    } else if input.is_file() {
        // A pipe is read once only, by the results reader; a history is a file.
        vec![input.to_path_buf()]
    } else {
        return Ok(None);
    };
    let mut found = HistoryInput {
        files: Vec::new(),
        read: Vec::new(),
    };
    let mut others = Vec::new();
    for file in candidates {
        let history = store::read(&file)?;
        found.read.push(file.clone());
        if history.tagged > 0 {
            found.files.push((file, history));
        } else {
            others.push(file);
        }
    }
    if found.files.is_empty() {
        return Ok(None);
    }
    for other in others {
        eprintln!(
            "warning: {} holds no line of schema {HISTORY_SCHEMA}: not a history file, left out",
            other.display()
        );
    }
    Ok(Some(found))
}

/// Refuses an output file that holds history records: exporting over a history would lose
/// every measurement in it.
fn refuse_a_history(out: &Path) -> anyhow::Result<()> {
    if !out.is_file() {
        return Ok(());
    }
    let held = store::read(out)
        .map_err(|e| anyhow::anyhow!("--out {}: cannot check what it holds: {e}", out.display()))?;
    if held.tagged > 0 {
        anyhow::bail!(
            "--out {} holds {} history records (lines of schema {HISTORY_SCHEMA}): export-results \
             never replaces a history; name a new file",
            out.display(),
            held.tagged
        );
    }
    Ok(())
}

/// Every record of the history files as one table; a line left out is named.
fn history_table(input: &HistoryInput) -> (TidyTable, String) {
    let mut records = Vec::new();
    for (file, history) in &input.files {
        for bad in &history.bad {
            eprintln!("warning: {}", visible(&bad.warning(file)));
        }
        records.extend(history.records.iter().cloned());
    }
    if records.is_empty() {
        eprintln!("warning: no line of the history is a readable record: the table has no rows");
    }
    let table = nbody_harness::history::tidy::records(&records);
    let what = format!(
        "{} records of {} history files",
        table.rows.len(),
        input.files.len()
    );
    (table, what)
}
