//! What a newcomer reads in `summary.md` and `fits.json` is true: a sweep measured on a shared
//! machine says so in every scaling reading and blames nothing on the code; the Karp-Flatt
//! column carries the measured e(p) even where no trend can be read; the cost table says at
//! which n its times are; a growth class is never named beside an exponent interval that
//! excludes it; a crossover always comes with the span of sizes it lies in.

use super::bin;
use serde_json::Value;
use std::path::Path;

/// `analyze RESULTS --out OUT`: the summary and the fits it wrote.
fn analyze(results: &Path, out: &Path) -> (String, Value) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let o = bin()
        .current_dir(root)
        .arg("analyze")
        .arg(results)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    let fits = serde_json::from_str(&std::fs::read_to_string(out.join("fits.json")).unwrap());
    (summary, fits.unwrap())
}

/// The committed results of sweep `name`, their calibration at the start of the sweep
/// measuring `background_cpus` of other processes' load, written into `dir`.
fn with_load(name: &str, background_cpus: f64, dir: &Path) -> std::path::PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("results").join(name).join("results.json"));
    let mut results: Value = serde_json::from_str(&text.unwrap()).unwrap();
    results["calibration"]["start"]["background_cpus"] = background_cpus.into();
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, serde_json::to_string(&results).unwrap()).unwrap();
    path
}

/// The section of `summary` under the heading `## {title}`, up to the next heading.
fn section<'a>(summary: &'a str, title: &str) -> &'a str {
    let start = summary
        .find(&format!("## {title}\n"))
        .unwrap_or_else(|| panic!("no section {title:?} in:\n{summary}"));
    let rest = &summary[start + 3..];
    &rest[..rest.find("\n## ").unwrap_or(rest.len())]
}

/// The rows of the first Markdown table in `text`, each as its cells (header row first).
fn table_rows(text: &str) -> Vec<Vec<String>> {
    text.lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .filter(|l| !l.starts_with("|---"))
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

const BLAME: [&str; 3] = ["synchronisation", "communication", "contention"];

#[test]
fn a_sweep_on_a_shared_machine_is_read_as_shared_in_every_scaling_reading() {
    let dir = tempfile::tempdir().unwrap();
    // Strong scaling: quick with one CPU of two busy while calibrating.
    let (summary, fits) = analyze(&with_load("quick", 1.0, dir.path()), &dir.path().join("q"));
    let strong = section(&summary, "Strong scaling");
    for blame in BLAME {
        assert!(!strong.contains(blame), "{blame:?} in:\n{strong}");
    }
    assert!(
        strong.contains("other processes used 1.00 CPUs"),
        "{strong}"
    );
    let rows = table_rows(strong);
    let header = &rows[0];
    let col = |name: &str| header.iter().position(|h| h.starts_with(name)).unwrap();
    let (amdahl, karp_flatt) = (col("Amdahl f"), col("Karp-Flatt"));
    for row in &rows[1..] {
        for c in [amdahl, karp_flatt] {
            assert!(row[c].ends_with("(shared machine)"), "{row:?}");
        }
    }
    for st in fits["strong"].as_array().unwrap() {
        assert_eq!(st["shared_machine"]["background_cpus"], 1.0);
        let meaning = st["fit"]["fit"]["karp_flatt_trend"]["meaning"]
            .as_str()
            .unwrap();
        assert!(meaning.contains("the machine was shared"), "{meaning}");
        assert!(BLAME.iter().all(|b| !meaning.contains(b)), "{meaning}");
    }
    // Weak scaling, and the same sweep on a quiet machine for comparison.
    let (summary, fits) = analyze(&with_load("weak", 0.6, dir.path()), &dir.path().join("w"));
    let weak = section(&summary, "Weak scaling");
    assert!(weak.contains("other processes used 0.60 CPUs"), "{weak}");
    for row in &table_rows(weak)[1..] {
        assert!(
            row.iter()
                .all(|c| c.ends_with("(shared machine)") || !c.contains('['))
        );
    }
    assert_eq!(fits["weak"][0]["shared_machine"]["background_cpus"], 0.6);
    let (quiet, fits) = analyze(
        &with_load("weak", 0.1, dir.path()),
        &dir.path().join("quiet"),
    );
    assert!(!quiet.contains("shared machine"), "{quiet}");
    assert!(fits["weak"][0].get("shared_machine").is_none());
}

#[test]
fn the_karp_flatt_column_carries_e_of_2_where_no_trend_can_be_read() {
    let dir = tempfile::tempdir().unwrap();
    let (summary, _) = analyze(Path::new("results/quick/results.json"), dir.path());
    let rows = table_rows(section(&summary, "Strong scaling"));
    let c = rows[0].iter().position(|h| h == "Karp-Flatt").unwrap();
    assert!(rows.len() > 10);
    for row in &rows[1..] {
        // Quick measures p = 1 and 2: one e(p) and no trend, the value shown all the same.
        assert!(row[c].starts_with("e(2) = "), "{row:?}");
        assert!(row[c].contains('%') && row[c].contains('['), "{row:?}");
        assert!(row[c].ends_with("trend: needs two p > 1"), "{row:?}");
    }
}

#[test]
fn the_cost_table_names_the_n_its_times_are_at_and_no_class_contradicts_k() {
    let dir = tempfile::tempdir().unwrap();
    let (summary, fits) = analyze(Path::new("results/complexity/results.json"), dir.path());
    let rows = table_rows(section(&summary, "Cost vs n"));
    let col = |name: &str| rows[0].iter().position(|h| h == name).unwrap();
    let (range, at, time) = (col("n measured"), col("at n"), col("time/step"));
    assert_eq!(
        at + 1,
        time,
        "\"at n\" stands right before the time it qualifies"
    );
    for row in &rows[1..] {
        let (_, largest) = row[range].split_once('–').unwrap();
        assert_eq!(row[at], largest, "{row:?}");
    }
    // Every class a reading names grows over the measured n with an exponent in k's CI.
    let growth = col("growth");
    for (c, row) in fits["complexity"]
        .as_array()
        .unwrap()
        .iter()
        .zip(&rows[1..])
    {
        let fit = &c["fit"]["fit"];
        let [lo, hi] = [0, 1].map(|i| fit["exponent"]["ci95"][i].as_f64().unwrap());
        let inputs = fit["inputs"].as_array().unwrap();
        let n = |i: usize| inputs[i]["x"].as_f64().unwrap();
        let (n_lo, n_hi) = (n(0), n(inputs.len() - 1));
        let named: Vec<&str> = match fit["reading"]["kind"].as_str().unwrap() {
            "class" => vec![fit["reading"]["class"].as_str().unwrap()],
            "not-distinguished" => fit["reading"]["classes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|c| c.as_str().unwrap())
                .collect(),
            _ => {
                assert!(row[growth].starts_with("n^"), "{row:?}");
                assert!(row[growth].contains("no class"), "{row:?}");
                vec![]
            }
        };
        for class in named {
            let (k, log) = match class {
                "n" => (1.0, false),
                "n log n" => (1.0, true),
                "n^1.5" => (1.5, false),
                "n^2" => (2.0, false),
                "n^2 log n" => (2.0, true),
                _ => (3.0, false),
            };
            let local = |n: f64| if log { k + 1.0 / n.ln() } else { k };
            assert!(
                local(n_hi) <= hi && lo <= local(n_lo),
                "{class} named beside k in [{lo}, {hi}]"
            );
            assert!(row[growth].contains(class), "{row:?}");
        }
    }
}

#[test]
fn a_crossover_always_comes_with_the_span_of_sizes_it_lies_in() {
    let dir = tempfile::tempdir().unwrap();
    let (summary, fits) = analyze(Path::new("results/complexity/results.json"), dir.path());
    let crossovers = fits["crossovers"].as_array().unwrap();
    let mut changes = 0;
    for x in crossovers {
        match (x["n"].as_f64(), x.get("between")) {
            (Some(n), Some(between)) => {
                let [a, b] = [0, 1].map(|i| between[i].as_f64().unwrap());
                assert!(a < n && n < b, "{x}");
                changes += 1;
            }
            (None, None) => {}
            _ => panic!("a size without its span, or a span without a size: {x}"),
        }
    }
    assert!(changes > 0, "the committed complexity sweep has crossovers");
    let text = section(&summary, "Crossovers");
    assert_eq!(
        text.matches("the order changes between them").count(),
        changes,
        "{text}"
    );
    assert!(!text.contains("null"), "{text}");
}
