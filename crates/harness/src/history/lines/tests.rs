use super::*;
use crate::history::store::tests::record;
use crate::history::store::{HISTORY_SCHEMA, Record};

fn line(r: &Record) -> String {
    serde_json::to_string(r).unwrap()
}

#[test]
fn a_record_is_known_by_its_schema_field_not_its_text() {
    let r = record("c", "abc", 1e-3);
    // As Python's json.dumps writes it: spaces after the separators, keys sorted.
    let value: serde_json::Value = serde_json::from_str(&line(&r)).unwrap();
    let sorted: std::collections::BTreeMap<String, serde_json::Value> =
        serde_json::from_value(value).unwrap();
    let spaced = serde_json::to_string(&sorted)
        .unwrap()
        .replace("\":", "\": ")
        .replace(",\"", ", \"");
    assert!(spaced.starts_with("{\"build\": {"), "{spaced}");
    let lines = parse_lines::<Record>(format!("{spaced}\r\n").as_bytes(), None);
    assert_eq!(lines.good, [r]);
    assert_eq!(lines.tagged, 1);
}

#[test]
fn each_bad_line_costs_itself_only_and_says_why() {
    let good = record("c", "abc", 1e-3);
    let mut negative = good.clone();
    negative.median_s = -1.0;
    let mut other_class = good.clone();
    other_class.class = "Other-4cpu".into();
    let mut bytes = Vec::new();
    for l in [
        line(&good).into_bytes(),
        {
            let mut b = line(&good).into_bytes();
            b[20] = 0xff;
            b
        },
        line(&negative).into_bytes(),
        line(&other_class).into_bytes(),
        line(&good)
            .replace("\"median_s\"", "\"median\"")
            .into_bytes(),
        b"{\"schema\": \"other/1\"}".to_vec(),
        b"[1, 2]".to_vec(),
        b"  ".to_vec(),
        line(&good).into_bytes(),
    ] {
        bytes.extend(l);
        bytes.push(b'\n');
    }
    let lines = parse_lines::<Record>(&bytes, Some(&good.class));
    assert_eq!(lines.good, [good.clone(), good]);
    let bad: Vec<(usize, &str)> = lines
        .bad
        .iter()
        .map(|b| (b.line, b.problem.as_str()))
        .collect();
    assert_eq!(bad.len(), 6, "{bad:?}");
    let expect = [
        (2, "not UTF-8 text (an invalid byte at column 21)"),
        (3, "median_s = -1 is not a time"),
        (
            4,
            "of machine class `Other-4cpu` in the file of class `Test-1-2-3-2cpu`",
        ),
        (5, "missing field `median_s`"),
        (
            6,
            "schema `other/1`, this version reads `nbody-bench-history/1`",
        ),
        (7, "no `schema` field"),
    ];
    for ((line, problem), (want_line, want)) in bad.iter().zip(expect) {
        assert_eq!(*line, want_line);
        assert!(problem.contains(want), "line {line}: {problem}");
    }
    // Lines 1, 3, 4, 5 and 9 carry the history schema: a history file, however damaged.
    assert_eq!(lines.tagged, 5);
    assert!(HISTORY_SCHEMA.starts_with("nbody-bench-history"));
}

#[test]
fn a_file_is_of_the_class_it_is_named_after() {
    use crate::history::verdicts::GateRun;
    let p = Path::new;
    assert_eq!(
        class_of_file::<Record>(p("h/Intel-4cpu.jsonl")).as_deref(),
        Some("Intel-4cpu")
    );
    assert_eq!(class_of_file::<Record>(p("h/Intel-4cpu.gate.jsonl")), None);
    assert_eq!(class_of_file::<Record>(p("/dev/fd/63")), None);
    assert_eq!(
        class_of_file::<GateRun>(p("h/Intel-4cpu.gate.jsonl")).as_deref(),
        Some("Intel-4cpu")
    );
}
