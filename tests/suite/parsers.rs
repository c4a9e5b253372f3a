//! The parsers and validation of user input never panic: random and mutated sweep configs and
//! CSV tables give a value or an error, nothing else.

use nbody_harness::fit::csv;
use nbody_records::config::SweepConfig;
use proptest::prelude::*;
use std::path::Path;

/// Real configs to mutate: every committed one and the test corpus.
fn seeds() -> Vec<String> {
    let mut texts = Vec::new();
    for dir in ["configs", "tests/configs/good", "tests/configs/bad"] {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            if entry.path().extension().is_some_and(|e| e == "toml") {
                texts.push(std::fs::read_to_string(entry.path()).unwrap());
            }
        }
    }
    texts
}

/// Values that break assumptions: huge, negative, fractional, non-finite, wrong types.
const ODD_VALUES: &[&str] = &[
    "0",
    "-1",
    "1e300",
    "18446744073709551615",
    "99999999999999999999999",
    "0.5",
    "-0.0",
    "nan",
    "inf",
    "\"\"",
    "\"..\"",
    "[]",
    "[0]",
    "[\"x\"]",
    "{}",
    "{ from = 10, to = 1, factor = 2 }",
    "{ from = 1, to = 1000000000000, factor = 1.0000001 }",
    "true",
];

/// `text` with the value of its `k`-th `key = value` line replaced by `value`.
fn mutate(text: &str, k: usize, value: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let assignments: Vec<usize> = (0..lines.len())
        .filter(|&i| {
            let l = lines[i].trim_start();
            !l.starts_with('#') && !l.starts_with('[') && l.contains('=')
        })
        .collect();
    if assignments.is_empty() {
        return text.to_string();
    }
    let target = assignments[k % assignments.len()];
    lines
        .iter()
        .enumerate()
        .map(|(i, l)| match (i == target, l.split_once('=')) {
            (true, Some((key, _))) => format!("{key}= {value}"),
            _ => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn mutated_configs_never_panic(seed in any::<usize>(), key in any::<usize>(), value in 0..ODD_VALUES.len()) {
        let texts = seeds();
        let text = mutate(&texts[seed % texts.len()], key, ODD_VALUES[value]);
        // Parsing validates; either outcome is fine, a panic is not.
        let _ = SweepConfig::parse(&text, Path::new("mutated.toml"));
    }

    #[test]
    fn random_text_configs_never_panic(text in "[a-z_\\[\\]=\"{}., 0-9\\n#-]{0,200}") {
        let _ = SweepConfig::parse(&text, Path::new("random.toml"));
    }

    #[test]
    fn csv_tables_never_panic(
        rows in proptest::collection::vec(
            proptest::collection::vec(
                prop_oneof![
                    Just("1".to_string()), Just("0".to_string()), Just("-3".to_string()),
                    Just("1e308".to_string()), Just("nan".to_string()), Just("inf".to_string()),
                    Just("".to_string()), Just("p".to_string()), Just("time".to_string()),
                    Just("n".to_string()), Just("\"2\"".to_string()), "[0-9.e+-]{1,8}",
                ],
                0..5,
            ),
            0..12,
        )
    ) {
        let text: String = rows.iter().map(|r| r.join(",") + "\n").collect();
        let _ = csv::parse_threads(&text);
        let _ = csv::parse_sizes(&text);
        let _ = csv::parse_weak(&text);
    }
}
