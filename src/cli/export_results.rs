//! `nbody-bench export-results`: a results file, or a performance history, as a tidy table for
//! notebooks: one row per sample (`nbody_records::tidy::samples`) or per history record
//! (`nbody_harness::history::tidy::records`).

use crate::cli::args::ExportResultsArgs;
use nbody_harness::history::store::{self, HISTORY_SCHEMA};
use nbody_records::locate;
use nbody_records::results::ResultsFile;
use nbody_records::tidy::{self, TidyTable};
use std::path::{Path, PathBuf};

pub fn export_results(args: ExportResultsArgs) -> anyhow::Result<i32> {
    let history = history_files(&args.results)?;
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
    // The output is checked before anything is read: never an input (through a link either),
    // never a directory or a device.
    if let Some(out) = &args.out {
        let inputs: Vec<(&str, &Path)> = match &history {
            Some(files) => files.iter().map(|f| ("HISTORY", f.as_path())).collect(),
            None => vec![("RESULTS", path.as_path())],
        };
        nbody_engine::output::check_outputs(&[("--out", out)], &inputs)?;
    }
    let (table, what) = match &history {
        Some(files) => history_table(files)?,
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

/// The history files `input` names: a history file (its first record line carries the history
/// schema), or a folder of them (`<class>.jsonl`, every class); `None` for anything else (a
/// results file, a run or a config name).
fn history_files(input: &Path) -> anyhow::Result<Option<Vec<PathBuf>>> {
    if input.is_dir() {
        let mut files: Vec<PathBuf> = std::fs::read_dir(input)
            .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", input.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "jsonl") && is_history(p))
            .collect();
        files.sort();
        return Ok((!files.is_empty()).then_some(files));
    }
    Ok(is_history(input).then(|| vec![input.to_path_buf()]))
}

/// Whether the first non-empty line of the file at `path` is a history record's.
fn is_history(path: &Path) -> bool {
    use std::io::BufRead;
    if !path.is_file() {
        return false;
    }
    let Ok(file) = std::fs::File::open(path) else {
        return false;
    };
    std::io::BufReader::new(file)
        .lines()
        .map_while(Result::ok)
        .find(|l| !l.trim().is_empty())
        .is_some_and(|l| l.contains(&format!("\"schema\":\"{HISTORY_SCHEMA}\"")))
}

/// Every record of the history files as one table; a damaged line is named and skipped.
fn history_table(files: &[PathBuf]) -> anyhow::Result<(TidyTable, String)> {
    let mut records = Vec::new();
    for file in files {
        let history = store::read(file)?;
        for bad in &history.bad {
            eprintln!(
                "warning: {} line {}: {}; left out",
                file.display(),
                bad.line,
                bad.problem
            );
        }
        records.extend(history.records);
    }
    let table = nbody_harness::history::tidy::records(&records);
    let what = format!(
        "{} records of {} history files",
        table.rows.len(),
        files.len()
    );
    Ok((table, what))
}
