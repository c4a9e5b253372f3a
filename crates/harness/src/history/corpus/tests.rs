//! The corpus's own tests: as described, deterministic, and scored as the page says.

use super::edivisive::{beta_regularized, t_test};
use super::*;
use std::sync::OnceLock;

const PAGE: &str = "docs/explanation/change-points.md";
const BEGIN: &str = "<!-- corpus-scores:begin -->";
const END: &str = "<!-- corpus-scores:end -->";
const UPDATE: &str = "NBODY_BENCH_UPDATE_DOCS";

/// The corpus is scored once for all the tests that read the scores.
fn scores() -> &'static CorpusScores {
    static SCORES: OnceLock<CorpusScores> = OnceLock::new();
    SCORES.get_or_init(|| score_corpus(&corpus()))
}

/// `page` with the region between the marks replaced by `region`.
fn splice(page: &str, region: &str) -> Option<String> {
    let begin = page.find(BEGIN)? + BEGIN.len();
    let end = begin + page[begin..].find(END)?;
    Some(format!("{}\n{region}{}", &page[..begin], &page[end..]))
}

#[test]
fn the_corpus_is_as_described() {
    let c = corpus();
    assert_eq!(c.len(), 850);
    assert_eq!(c, corpus(), "the same on every call");
    for s in &c {
        assert!((30..=120).contains(&s.values.len()), "{:?}", s.kind);
        assert!(s.values.iter().all(|v| v.is_finite() && *v > 0.0));
        for t in &s.steps {
            let size = (t.ratio - 1.0).abs();
            assert!((0.03..=0.20).contains(&size), "{t:?}");
            let room = if s.kind == Kind::RampAndStep { 5 } else { 10 };
            assert!(t.index >= room && t.index + room <= s.values.len(), "{t:?}");
        }
        if let Some(d) = s.drift {
            assert!(d.end < s.values.len());
            if matches!(s.kind, Kind::Ramp | Kind::RampAndStep) {
                let rate = d.per_point.ln().abs();
                assert!((0.001..0.005).contains(&rate), "{d:?}");
                assert!((20..=60).contains(&(d.end - d.start + 1)), "{d:?}");
                assert!(d.ratio().ln().abs() >= 1.05f64.ln() - 1e-12, "{d:?}");
                // The step beside it is outside its range.
                assert!(
                    s.steps
                        .iter()
                        .all(|t| !(d.start..=d.end).contains(&t.index))
                );
            }
        }
        assert_eq!(
            s.drift.is_some(),
            matches!(s.kind, Kind::Drift | Kind::Ramp | Kind::RampAndStep)
        );
    }
}

#[test]
fn the_t_test_gives_the_tables_p_values() {
    // t = 2.228 with 10 degrees of freedom is the two-sided 5% point; 12.706 with 1.
    let two_sided = |t: f64, df: f64| beta_regularized(df / 2.0, 0.5, df / (df + t * t));
    assert!((two_sided(2.228, 10.0) - 0.05).abs() < 2e-4);
    assert!((two_sided(12.706, 1.0) - 0.05).abs() < 2e-4);
    assert!((two_sided(0.0, 5.0) - 1.0).abs() < 1e-12);
    assert_eq!(t_test(&[1.0, 1.0], &[2.0, 2.0]), 0.0);
}

#[test]
fn the_model_meets_its_targets_on_the_corpus() {
    let chosen = &scores().methods[0];
    assert!(chosen.method.contains("chosen"), "{chosen:?}");
    assert!(chosen.f1 >= 0.95 && chosen.f1_small >= 0.95, "{chosen:?}");
    assert_eq!(chosen.spike_changes, 0, "{chosen:?}");
    assert_eq!(chosen.spike_drifts, 0, "{chosen:?}");
    assert!(chosen.drifts > 100, "{chosen:?}");
    assert_eq!(chosen.drift_recall, 1.0, "{chosen:?}");
    // Targets 0, not met yet (docs/explanation/change-points.md, Limits): a few drifts found
    // shorter than they are, with a step of 2–4% left at one end; and two-state series whose
    // states ran unevenly for a stretch, which the step detector alone reports too. Held at
    // what the model does today, so that neither grows unseen.
    assert!(chosen.steps_in_drifts <= 3, "{chosen:?}");
    assert!(chosen.drifts_as_one_step <= 3, "{chosen:?}");
    assert!(chosen.two_state_changed <= 2, "{chosen:?}");
    let steps_alone = &scores().methods[1];
    assert!(
        steps_alone.steps_in_drifts > 10 * chosen.steps_in_drifts.max(1),
        "{steps_alone:?}"
    );
    // The step detector alone, scored after every point: what the model's steps are when it
    // finds no drift.
    assert_eq!(
        steps_alone.spike_changes_any_prefix,
        Some(0),
        "{steps_alone:?}"
    );
    assert!(
        steps_alone.median_delay.is_some_and(|d| d <= 5.0),
        "{steps_alone:?}"
    );
}

/// docs/explanation/change-points.md shows the scores this corpus gives; under
/// `NBODY_BENCH_UPDATE_DOCS=1` the test rewrites the page's region instead.
#[test]
fn the_explanation_page_shows_the_corpus_scores() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(PAGE);
    let page = std::fs::read_to_string(&path).unwrap();
    let generated = splice(&page, &render_scores_markdown(scores()))
        .unwrap_or_else(|| panic!("{PAGE} keeps the marks {BEGIN} and {END}"));
    if std::env::var(UPDATE).as_deref() == Ok("1") {
        std::fs::write(&path, &generated).unwrap();
        return;
    }
    assert!(
        page == generated,
        "{PAGE}'s corpus scores are stale: regenerate them with `{UPDATE}=1 cargo test \
         --release -p nbody-harness --lib -- history::corpus`, review the diff and commit it\n\
         generated:\n{}",
        render_scores_markdown(scores())
    );
}
