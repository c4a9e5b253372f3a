use super::markdown::{Base, summary};
use super::*;
use crate::gate::Verdict;
use crate::history::verdicts::tests::run;

/// `n` commits of `case` on `class`, the level times `ratio` from commit `step` on.
fn stepped(class: &str, case: &str, n: usize, step: usize, ratio: f64) -> Vec<Record> {
    (0..n)
        .map(|i| {
            let level = if i >= step { ratio } else { 1.0 };
            let wobble = 1.0 + 0.003 * ((i * 7 % 5) as f64 - 2.0);
            let mut r = crate::history::store::tests::record(
                case,
                &format!("{:07x}{}", 0xa00_0000 + i, "0".repeat(33)),
                1e-3 * level * wobble,
            );
            r.class = class.into();
            r.commit_date = Some(format!("2026-11-{:02}T10:00:00Z", i + 1));
            r
        })
        .collect()
}

fn loaded() -> Loaded {
    let mut a = stepped("A-1cpu", "lj-box/naive/n=1000", 12, 6, 1.25);
    a.extend(stepped("A-1cpu", "x<script>", 12, 12, 1.0));
    let b = stepped("B-2cpu", "lj-box/naive/n=1000", 12, 12, 1.0);
    let verdicts = Verdicts {
        runs: vec![
            run("2026-12-01T00:00:00Z", "old", "older", &[]),
            run(
                "2026-12-02T00:00:00Z",
                "a000005",
                "a000006",
                &[("lj-box/naive/n=1000", Verdict::Regressed, 1.25)],
            ),
        ],
        bad: vec![],
    };
    Loaded {
        classes: vec![
            ClassFiles {
                class: "A-1cpu".into(),
                records: a,
                verdicts,
            },
            ClassFiles {
                class: "B-2cpu".into(),
                records: b,
                verdicts: Verdicts::default(),
            },
        ],
        warnings: vec![],
    }
}

#[test]
fn cases_sit_side_by_side_with_their_steps_and_latest_verdicts() {
    let page = page(&loaded(), Vec::new()).unwrap();
    let keys: Vec<&str> = page.cases.iter().map(|c| c.key.as_str()).collect();
    assert_eq!(keys, ["lj-box/naive/n=1000", "x<script>"]);
    let lj = &page.cases[0];
    let classes: Vec<&str> = lj.charts.iter().map(|c| c.series.class.as_str()).collect();
    assert_eq!(classes, ["A-1cpu", "B-2cpu"]);
    assert_eq!(lj.charts[0].steps.len(), 1);
    assert!(lj.charts[1].steps.is_empty());
    assert_eq!(
        lj.charts[0].verdict.as_ref().unwrap().verdict,
        Verdict::Regressed
    );
    assert_eq!(page.cases[1].absent, ["B-2cpu"]);
    let html = html(&page);
    assert!(html.contains(r#"<section class="case" data-case="lj-box/naive/n=1000">"#));
    assert!(html.contains(r#"<g class="change slower" data-between="a000005..a000006""#));
    assert!(html.contains(r#"<svg class="chart" data-class="B-2cpu""#));
    // A key is text, never markup.
    assert!(html.contains("x&lt;script&gt;") && !html.contains("x<script>"));
    assert!(!html.contains("http://") && !html.contains("https://"));
}

#[test]
fn the_summary_counts_from_the_base() {
    let page = page(&loaded(), Vec::new()).unwrap();
    let base = |name: &str| Base {
        name: name.into(),
        commit: None,
        repo: ".".into(),
        none: None,
    };
    let before = summary(&page, &base("a000003"));
    assert!(before.contains("`a000005..a000006`"), "{before}");
    assert!(before.contains("+25.2% slower"), "{before}");
    assert!(
        before.contains("1 regressed, 0 improved, 0 unchanged"),
        "{before}"
    );
    let after = summary(&page, &base("a000007"));
    assert!(
        after.contains("No change since `a000007` in any of 2 cases"),
        "{after}"
    );
}

#[test]
fn an_accepted_regression_is_shown_with_its_reason() {
    let mut loaded = loaded();
    let latest = &mut loaded.classes[0].verdicts.runs[1];
    latest.acceptance = Some(crate::history::verdicts::Acceptance {
        accepted: "2026-12-02T00:10:00Z".into(),
        class: "A-1cpu".into(),
        replaced_commit: "a000005".into(),
        new_commit: "a000006".into(),
        reason: "exact <forces>".into(),
        cases: vec![crate::history::verdicts::AcceptedCase {
            key: "lj-box/naive/n=1000".into(),
            ratio: 1.25,
            ci95: [1.2, 1.3],
        }],
    });
    let page = page(&loaded, Vec::new()).unwrap();
    let html = html(&page);
    assert!(
        html.contains("<code>lj-box/naive/n=1000</code>, because: exact &lt;forces&gt;"),
        "{html}"
    );
    let base = Base {
        name: "a000003".into(),
        commit: None,
        repo: ".".into(),
        none: None,
    };
    let md = summary(&page, &base);
    assert!(
        md.contains("Accepted into the baseline when it was saved (2026-12-02T00:10:00Z): `lj-box/naive/n=1000`, because: exact &lt;forces&gt;"),
        "{md}"
    );
}
