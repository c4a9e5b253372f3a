//! The history as a tidy table: one row per record, every field its own column, the case key
//! taken apart into the case's fields, the work counters one column each. `export-results`
//! writes it as CSV or JSON lines ([`nbody_records::tidy`]).

use super::store::Record;
use nbody_engine::kernels::{Multipole, WorkCounters};
use nbody_engine::scenario::Precision;
use nbody_records::tidy::TidyTable;
use serde_json::Value;

/// The columns of [`records`] and what each holds; `export-results --help` and
/// docs/reference/outputs.md list them from here.
pub const HISTORY_COLUMNS: [(&str, &str); 40] = [
    ("case", "the case key"),
    ("scenario", "the scenario simulated (from the key)"),
    (
        "kernel",
        "the built-in kernel, or the external program's name",
    ),
    ("n", "particles the case asked for"),
    ("threads", "threads per rank"),
    ("ranks", "MPI ranks (1 without MPI)"),
    ("seed", "seed of the initial state"),
    ("theta", "opening angle (octree and fmm; else empty)"),
    (
        "multipole",
        "the octree's expansion when not the monopole (else empty)",
    ),
    ("order", "the fmm's expansion order p (else empty)"),
    (
        "skin",
        "the neighbour-list skin when the config set one (else empty)",
    ),
    (
        "precision",
        "f32 or f64 when the config set it (else empty)",
    ),
    (
        "time_factor",
        "simulated-time factor of a weak-by-time study (else 1)",
    ),
    ("decomp", "the MPI decomposition (empty without MPI)"),
    (
        "commit",
        "the commit measured (empty when the results named none)",
    ),
    (
        "parent",
        "its first parent (empty when git did not know it)",
    ),
    (
        "commit_date",
        "its committer date, ISO 8601 (empty when unknown)",
    ),
    ("dirty", "the build had uncommitted changes"),
    ("measured", "when the measurement started, UTC"),
    ("class", "the machine class: CPU signature and logical CPUs"),
    ("tool_version", "the nbody-bench version that measured"),
    ("profile", "the cargo profile"),
    ("simd", "the instruction set the pair loops ran with"),
    (
        "features",
        "the build's cargo features, joined by '+' (empty: none)",
    ),
    ("config", "the sweep config's name"),
    ("source", "what made the record: sweep, gate or backfill"),
    ("median_s", "median time per step, seconds"),
    (
        "ci95_lo_s",
        "lower end of its bootstrap 95% interval, seconds",
    ),
    ("ci95_hi_s", "upper end, seconds"),
    (
        "normalized_median",
        "median time per step over the reference workload timed before each sample (empty \
         when not timed)",
    ),
    ("normalized_ci95_lo", "lower end of its 95% interval"),
    ("normalized_ci95_hi", "upper end"),
    ("samples", "successful samples the median is of"),
    (
        "work_pair_checks",
        "pair distance evaluations of one force computation on the initial state (every \
         work_ column is empty when the record has no work counters)",
    ),
    ("work_pairs_interacting", "pairs that interact"),
    (
        "work_cells_visited",
        "cells whose particles were visited (cell list)",
    ),
    ("work_nodes_opened", "tree nodes opened"),
    ("work_nodes_accepted", "tree nodes accepted whole"),
    ("work_rebuilds", "neighbour lists built (Verlet list)"),
    ("work_list_entries", "neighbour-list entries evaluated"),
];

/// One row per record, in the file's order.
pub fn records(records: &[Record]) -> TidyTable {
    let mut table = TidyTable::new(HISTORY_COLUMNS.map(|(name, _)| name));
    for r in records {
        let mut row = case_fields(&r.case).to_vec();
        let norm = r.normalized;
        row.extend([
            Value::from(r.commit.as_str()).non_empty(),
            Value::from(r.parent.as_deref()),
            Value::from(r.commit_date.as_deref()),
            Value::from(r.dirty),
            Value::from(r.measured.as_str()),
            Value::from(r.class.as_str()),
            Value::from(r.build.tool_version.as_str()),
            Value::from(r.build.profile.as_str()),
            Value::from(r.build.simd.as_str()),
            Value::from(r.build.features.join("+")),
            Value::from(r.config.as_str()),
            Value::from(r.source.as_str()),
            Value::from(r.median_s),
            Value::from(r.ci95_s[0]),
            Value::from(r.ci95_s[1]),
            Value::from(norm.map(|n| n.median)),
            Value::from(norm.map(|n| n.ci95[0])),
            Value::from(norm.map(|n| n.ci95[1])),
            Value::from(r.samples),
        ]);
        row.extend(work_fields(r.work.as_ref()));
        table.push(row);
    }
    table
}

trait NonEmpty {
    fn non_empty(self) -> Value;
}

impl NonEmpty for Value {
    /// An empty string is "not known": null.
    fn non_empty(self) -> Value {
        match self {
            Value::String(s) if s.is_empty() => Value::Null,
            v => v,
        }
    }
}

fn work_fields(work: Option<&WorkCounters>) -> [Value; 7] {
    match work {
        Some(w) => [
            w.pair_checks,
            w.pairs_interacting,
            w.cells_visited,
            w.nodes_opened,
            w.nodes_accepted,
            w.rebuilds,
            w.list_entries,
        ]
        .map(Value::from),
        None => [(); 7].map(|_| Value::Null),
    }
}

/// The case's fields from its key (`scenario/kernel/n=../p=../r=../seed=..` and the optional
/// parts [`nbody_records::plan::Case::key`] appends); a part the key lacks is null.
fn case_fields(key: &str) -> [Value; 14] {
    let mut parts = key.split('/');
    let scenario = Value::from(parts.next());
    let kernel = Value::from(parts.next());
    let [
        mut n,
        mut p,
        mut r,
        mut seed,
        mut theta,
        mut order,
        mut skin,
    ] = [(); 7].map(|_| Value::Null);
    let [mut multipole, mut precision, mut decomp] = [(); 3].map(|_| Value::Null);
    let mut time_factor = Value::from(1);
    let number = |v: &str| {
        serde_json::from_str::<serde_json::Number>(v)
            .map(Value::Number)
            .unwrap_or_else(|_| Value::from(v))
    };
    for part in parts {
        let word = Value::from(part);
        if let Some((name, value)) = part.split_once('=') {
            let slot = match name {
                "n" => &mut n,
                "p" => &mut p,
                "r" => &mut r,
                "seed" => &mut seed,
                "theta" => &mut theta,
                "order" => &mut order,
                "skin" => &mut skin,
                _ => continue,
            };
            *slot = number(value);
        } else if let Some(factor) = part.strip_prefix("time-x") {
            time_factor = number(factor);
        } else if serde_json::from_value::<Multipole>(word.clone()).is_ok() {
            multipole = word;
        } else if serde_json::from_value::<Precision>(word.clone()).is_ok() {
            precision = word;
        } else {
            decomp = word;
        }
    }
    [
        Value::from(key),
        scenario,
        kernel,
        n,
        p,
        r,
        seed,
        theta,
        multipole,
        order,
        skin,
        precision,
        time_factor,
        decomp,
    ]
}
