//! The groupings the figures show, made here so that rendering only draws: one cost figure per
//! scenario, precision and parallelism; one strong-scaling set per scenario, n and precision;
//! one weak-scaling figure per scenario; and the cases worth a bar each.

use super::groups::Point;
use super::{Analysis, ComplexityAnalysis, StrongAnalysis, WeakAnalysis};
use nbody_engine::scenario::ScenarioKind;

/// Most bars a phase or percentile figure shows.
const MAX_BARS: usize = 16;

/// `items` grouped by `key`, the groups in the order of their first members.
pub(crate) fn grouped<T, K: PartialEq>(items: &[T], key: impl Fn(&T) -> K) -> Vec<Vec<&T>> {
    let mut keys: Vec<K> = Vec::new();
    let mut groups: Vec<Vec<&T>> = Vec::new();
    for item in items {
        let k = key(item);
        match keys.iter().position(|seen| *seen == k) {
            Some(i) => groups[i].push(item),
            None => {
                keys.push(k);
                groups.push(vec![item]);
            }
        }
    }
    groups
}

impl Analysis {
    /// Cost-vs-n series drawn together: one scenario, precision, thread and rank count.
    pub(crate) fn cost_groups(&self) -> Vec<Vec<&ComplexityAnalysis>> {
        grouped(&self.complexity, |c| {
            let s = &c.series;
            (s.scenario, s.precision, s.threads, s.ranks)
        })
    }

    /// Strong-scaling series drawn together: one scenario, n and precision.
    pub(crate) fn strong_groups(&self) -> Vec<Vec<&StrongAnalysis>> {
        grouped(&self.strong, |s| {
            (s.series.scenario, s.series.n, s.series.precision)
        })
    }

    /// Weak-scaling series drawn together: one scenario.
    pub(crate) fn weak_groups(&self) -> Vec<Vec<&WeakAnalysis>> {
        grouped(&self.weak, |w| w.series.scenario)
    }

    /// The scenarios of the measured cases, by name.
    pub(crate) fn scenarios(&self) -> Vec<ScenarioKind> {
        let mut out: Vec<ScenarioKind> = Vec::new();
        for c in &self.cases {
            if !out.contains(&c.case.scenario) {
                out.push(c.case.scenario);
            }
        }
        out.sort_by_key(|s| s.name());
        out
    }

    /// The cases of `scenario` worth a bar each: for every code and parallelism (kernel
    /// options and decomposition included), the largest n measured; at most 16.
    pub(crate) fn representative_cases(&self, scenario: ScenarioKind) -> Vec<&Point> {
        let mut out: Vec<&Point> = Vec::new();
        for c in self.cases.iter().filter(|c| c.case.scenario == scenario) {
            let same = |o: &&Point| {
                o.case.kernel == c.case.kernel
                    && o.threads == c.threads
                    && o.ranks == c.ranks
                    && o.theta == c.theta
                    && o.case.multipole == c.case.multipole
                    && o.case.order == c.case.order
                    && o.case.skin == c.case.skin
                    && o.decomp == c.decomp
            };
            match out.iter().position(same) {
                Some(i) if out[i].n < c.n => out[i] = c,
                Some(_) => {}
                None => out.push(c),
            }
        }
        out.truncate(MAX_BARS);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::grouped;

    #[test]
    fn groups_keep_the_order_of_first_appearance() {
        let items = [3, 1, 4, 1, 5, 9, 2, 6];
        let groups = grouped(&items, |x| x % 3);
        let values: Vec<Vec<i32>> = groups
            .iter()
            .map(|g| g.iter().map(|&&x| x).collect())
            .collect();
        assert_eq!(values, vec![vec![3, 9, 6], vec![1, 4, 1], vec![5, 2]]);
        assert!(grouped(&[] as &[i32], |x| *x).is_empty());
    }
}
