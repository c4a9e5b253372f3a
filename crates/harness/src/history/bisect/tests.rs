//! The bisection's decisions on made-up commits whose costs are known: a step, two steps in
//! the same direction, opposite steps, a drift, unbuildable commits, no step at all.

use super::*;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_pcg::Pcg64Mcg;

/// Commits "c0".."cN" with a cost each; `broken` ones do not build.
struct Made {
    cost: Vec<f64>,
    broken: Vec<usize>,
    rng: Pcg64Mcg,
    /// Builds asked for.
    builds: usize,
}

impl Made {
    fn new(cost: Vec<f64>, seed: u64) -> Self {
        Made {
            cost,
            broken: Vec::new(),
            rng: Pcg64Mcg::seed_from_u64(seed),
            builds: 0,
        }
    }

    fn path(&self) -> Vec<String> {
        (0..self.cost.len()).map(|i| format!("c{i}")).collect()
    }

    fn index(commit: &str) -> usize {
        commit[1..].parse().unwrap()
    }
}

impl Probe for Made {
    fn build(&mut self, commit: &str) -> Result<(), String> {
        self.builds += 1;
        if self.broken.contains(&Made::index(commit)) {
            Err("error[E0425]: cannot find value".into())
        } else {
            Ok(())
        }
    }

    fn measure(&mut self, a: &str, b: &str, rounds: usize) -> anyhow::Result<[Vec<f64>; 2]> {
        let (ca, cb) = (self.cost[Made::index(a)], self.cost[Made::index(b)]);
        let mut out = [Vec::new(), Vec::new()];
        for _ in 0..rounds * 3 {
            for (side, c) in [(0, ca), (1, cb)] {
                let z: f64 = self.rng.sample(StandardNormal);
                out[side].push(c * (0.02 * z).exp());
            }
        }
        Ok(out)
    }
}

fn settings() -> Settings {
    Settings {
        direction: Direction::Slower,
        threshold: crate::gate::AB_THRESHOLD,
        rounds: 4,
        seed: 7,
    }
}

fn run(made: &mut Made) -> Bisection {
    let path = made.path();
    bisect(&path, made, settings(), &mut |_| {}).unwrap()
}

/// Costs 1 up to commit `at` (excluded), `after` from there on.
fn step(n: usize, at: usize, after: f64) -> Vec<f64> {
    (0..n).map(|i| if i < at { 1.0 } else { after }).collect()
}

#[test]
fn a_step_is_named_at_every_position() {
    for at in 1..17 {
        let mut made = Made::new(step(17, at, 1.10), at as u64);
        let found = run(&mut made);
        match &found.finding {
            Finding::Named { culprit, step } => {
                assert_eq!(culprit, &format!("c{at}"));
                assert_eq!(step.from, format!("c{}", at - 1));
                assert_eq!(step.verdict, Verdict::Regressed);
            }
            other => panic!("step at c{at}: {other:?}"),
        }
        // 16 commits: the ends and at most ⌈log₂ 16⌉ + 1 midpoints.
        assert!(
            made.builds <= 4 + 3,
            "{} builds for a step at c{at}",
            made.builds
        );
    }
}

#[test]
fn commits_that_do_not_build_are_stepped_over() {
    let mut made = Made::new(step(17, 10, 1.10), 1);
    made.broken = vec![8, 12];
    let found = run(&mut made);
    assert!(
        matches!(&found.finding, Finding::Named { culprit, .. } if culprit == "c10"),
        "{:?}",
        found.finding
    );
    assert!(found.skipped.iter().any(|(c, _)| c == "c8"));
    // The culprit right after a broken commit: the answer is the range, never a guess.
    let mut made = Made::new(step(17, 9, 1.10), 2);
    made.broken = vec![8];
    let found = run(&mut made);
    match &found.finding {
        Finding::Among { step, unbuilt } => {
            assert_eq!(unbuilt, &["c8".to_string()]);
            assert_eq!((step.from.as_str(), step.to.as_str()), ("c7", "c9"));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(found.exit_code(), 1);
}

#[test]
fn opposite_steps_are_reported_not_resolved() {
    // Slower by 30% at c4, faster again at c12: BAD is still 8% slower than GOOD, but the
    // middle is slower than BAD.
    let cost: Vec<f64> = (0..17)
        .map(|i| match i {
            0..4 => 1.0,
            4..12 => 1.30,
            _ => 1.08,
        })
        .collect();
    let mut made = Made::new(cost, 3);
    let found = run(&mut made);
    assert!(
        matches!(found.finding, Finding::NotMonotone { .. }),
        "{:?}",
        found.finding
    );
    assert_eq!(found.exit_code(), 1);
}

#[test]
fn two_steps_the_same_way_follow_the_larger_and_report_the_other() {
    let cost: Vec<f64> = (0..17)
        .map(|i| match i {
            0..5 => 1.0,
            5..11 => 1.08,
            _ => 1.08 * 1.25,
        })
        .collect();
    let mut made = Made::new(cost, 4);
    let found = run(&mut made);
    assert!(
        matches!(&found.finding, Finding::Named { culprit, .. } if culprit == "c11"),
        "{:?}",
        found.finding
    );
    assert!(!found.also.is_empty());
}

#[test]
fn a_drift_is_not_pinned_on_one_commit() {
    // 1.5% a commit over 16 commits: +27% overall, no single step the gate can see.
    let cost: Vec<f64> = (0..17).map(|i| 1.015f64.powi(i)).collect();
    let mut made = Made::new(cost, 5);
    let found = run(&mut made);
    assert!(
        matches!(found.finding, Finding::Spread { .. }),
        "{:?}",
        found.finding
    );
}

#[test]
fn ends_that_do_not_differ_end_it_at_once() {
    let mut made = Made::new(vec![1.0; 17], 6);
    let found = run(&mut made);
    assert!(matches!(found.finding, Finding::NoStep { .. }));
    assert_eq!(made.builds, 2);
}

#[test]
fn the_next_midpoint_avoids_failed_commits() {
    let none = BTreeSet::new();
    assert_eq!(midpoint(0, 16, &none), Some(8));
    assert_eq!(midpoint(0, 1, &none), None);
    let failed: BTreeSet<usize> = [8].into();
    assert_eq!(midpoint(0, 16, &failed), Some(7));
    let failed: BTreeSet<usize> = [1, 2].into();
    assert_eq!(midpoint(0, 3, &failed), None);
}

#[test]
fn a_speedup_is_named_when_looking_for_one_and_is_no_step_otherwise() {
    let cost = step(17, 6, 0.80);
    let path = Made::new(cost.clone(), 8).path();
    let faster = Settings {
        direction: Direction::Faster,
        ..settings()
    };
    let found = bisect(&path, &mut Made::new(cost.clone(), 8), faster, &mut |_| {}).unwrap();
    assert!(
        matches!(&found.finding, Finding::Named { culprit, .. } if culprit == "c6"),
        "{:?}",
        found.finding
    );
    assert_eq!(found.direction, Direction::Faster);
    let found = bisect(&path, &mut Made::new(cost, 8), settings(), &mut |_| {}).unwrap();
    assert!(matches!(found.finding, Finding::NoStep { .. }));
}
