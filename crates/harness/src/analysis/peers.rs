//! Our kernels next to the external programs measured in the same sweep (the vs-*.toml
//! configs): each built-in kernel's case against the fastest external case of the same
//! scenario, n and worker count (and θ) — a peer may be run in several ways, e.g. LAMMPS with
//! its defaults and tuned, and a comparison counts against its best — with the ratio of their
//! times and a bootstrap CI, the slower variants kept beside it; for tree codes swept over θ,
//! each code's cost interpolated to one median force error, so that cost is compared at equal
//! accuracy.

use super::ThetaAnalysis;
use super::groups::{Point, workers_suffix};
use nbody_engine::stats::{BOOTSTRAP_RESAMPLES, bootstrap_ratio_ci};
use serde::Serialize;

/// The median relative force error at which tree codes are compared: the octree's target
/// at θ = 0.5.
pub(crate) const EQUAL_ERROR: f64 = 1e-3;

/// Tighter errors also compared at, where the other code's settings reach them (a fast
/// multipole code's higher orders do; a θ sweep of a tree code usually does not).
const TIGHTER_ERRORS: [f64; 3] = [1e-4, 1e-6, 1e-8];

/// The seed of the ratio bootstraps: the same results give the same intervals.
const SEED: u64 = 0x9EE2;

/// One of our cases next to the fastest external case of the same system and workers.
#[derive(Clone, Debug, Serialize)]
pub struct PeerRatio {
    /// The scenario both cases simulate, by name.
    pub scenario: String,
    /// Particles, the same for both.
    pub n: usize,
    /// Threads × ranks, the same for both.
    pub workers: usize,
    /// Our case's label: kernel, θ, expansion, workers.
    pub ours: String,
    /// The fastest external case's label.
    pub theirs: String,
    /// Nanoseconds per particle-step: median and bootstrap 95% CI.
    pub(crate) ours_ns: f64,
    pub(crate) ours_ci_ns: [f64; 2],
    /// Their median, nanoseconds per particle-step.
    pub theirs_ns: f64,
    pub(crate) theirs_ci_ns: [f64; 2],
    /// Their time over ours (> 1: ours is faster), from the medians, with the bootstrap 95%
    /// CI of that ratio over both sets of samples.
    pub speedup: f64,
    /// The bootstrap 95% CI of `speedup`; `None` when either case has no samples.
    pub speedup_ci: Option<[f64; 2]>,
    /// Median relative force errors, where measured.
    pub(crate) ours_error: Option<f64>,
    pub(crate) theirs_error: Option<f64>,
    /// Either case ran more workers than logical CPUs.
    pub oversubscribed: bool,
    /// The other external cases of the same system and workers (the other ways a peer was
    /// run, e.g. with its defaults), slower than `theirs`, fastest first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub others: Vec<PeerVariant>,
}

/// An external case that was not the fastest of its system and workers, against the same case
/// of ours.
#[derive(Clone, Debug, Serialize)]
pub struct PeerVariant {
    /// The external case's label.
    pub theirs: String,
    /// Its median, nanoseconds per particle-step.
    pub theirs_ns: f64,
    pub(crate) theirs_ci_ns: [f64; 2],
    /// Its time over ours (from the medians).
    pub speedup: f64,
    /// It or our case ran more workers than logical CPUs.
    pub oversubscribed: bool,
}

/// Each code's time per step at a median force error, interpolated over its settings (log
/// time linear in log error between the two settings that bracket it).
#[derive(Clone, Debug, Serialize)]
pub(crate) struct EqualErrorCost {
    pub scenario: String,
    pub n: usize,
    pub workers: usize,
    pub error: f64,
    pub ours: String,
    pub theirs: String,
    /// Seconds per step at `error`; `None` when the code's measured errors do not bracket it.
    pub(crate) ours_s: Option<f64>,
    pub(crate) theirs_s: Option<f64>,
    /// `theirs_s / ours_s`.
    pub speedup: Option<f64>,
    /// The two settings each time was interpolated between (the same one twice when a
    /// setting has exactly that error).
    pub(crate) ours_between: Option<[String; 2]>,
    pub(crate) theirs_between: Option<[String; 2]>,
    /// The range of median errors each code measured, to say why a cost is missing.
    pub(crate) ours_errors: [f64; 2],
    pub(crate) theirs_errors: [f64; 2],
}

/// A case's legend label: code, θ, expansion order, workers.
pub(crate) fn case_label(p: &Point) -> String {
    let mut s = p.case.kernel.name().to_string();
    if let Some(t) = p.theta {
        s.push_str(&format!(" θ={t}"));
    }
    // The octree names its expansion whichever it is: a bare "octree θ=0.5" would read as the
    // default, which is the quadrupole.
    if p.case.kernel.kernel() == Some(nbody_engine::kernels::KernelKind::Octree)
        || p.case.multipole != nbody_engine::kernels::Multipole::Monopole
    {
        s.push_str(&format!(" {}", p.case.multipole.name()));
    }
    if let Some(order) = p.case.order {
        s.push_str(&format!(" order {order}"));
    }
    if let Some(skin) = p.case.skin {
        s.push_str(&format!(" skin {skin}"));
    }
    s.push_str(&workers_suffix(p.threads, p.ranks));
    s
}

fn ns_per_particle(p: &Point, seconds: f64) -> f64 {
    seconds * 1e9 / p.n.max(1) as f64
}

/// Whether an external case `t` is the same system and workers as our case `o`: scenario, n,
/// threads × ranks, and θ when the external case has one.
fn same_case(o: &Point, t: &Point) -> bool {
    o.case.scenario == t.case.scenario
        && o.n == t.n
        && o.p() == t.p()
        && (t.theta.is_none() || o.theta == t.theta)
}

/// Each of our cases against the fastest (lowest median) external case of the same scenario, n
/// and worker count (when the external case has a θ, the same θ), with the other external cases
/// of that system beside it; our cases with no external counterpart are left out.
pub(crate) fn ratios(cases: &[Point]) -> Vec<PeerRatio> {
    let (theirs, ours): (Vec<&Point>, Vec<&Point>) =
        cases.iter().partition(|p| p.case.kernel.is_external());
    let mut out = Vec::new();
    for o in &ours {
        let mut peers: Vec<&Point> = theirs.iter().copied().filter(|t| same_case(o, t)).collect();
        // Stable: of equal medians, the first in the file.
        peers.sort_by(|a, b| a.median_s.total_cmp(&b.median_s));
        let Some((t, slower)) = peers.split_first() else {
            continue;
        };
        out.push(PeerRatio {
            scenario: o.case.scenario.name().into(),
            n: o.n,
            workers: o.p(),
            ours: case_label(o),
            theirs: case_label(t),
            ours_ns: ns_per_particle(o, o.median_s),
            ours_ci_ns: o.ci95_s.map(|s| ns_per_particle(o, s)),
            theirs_ns: ns_per_particle(t, t.median_s),
            theirs_ci_ns: t.ci95_s.map(|s| ns_per_particle(t, s)),
            speedup: t.median_s / o.median_s,
            speedup_ci: bootstrap_ratio_ci(&o.samples, &t.samples, BOOTSTRAP_RESAMPLES, SEED),
            ours_error: o.force_error.map(|e| e[0]),
            theirs_error: t.force_error.map(|e| e[0]),
            oversubscribed: o.oversubscribed || t.oversubscribed,
            others: slower
                .iter()
                .map(|s| PeerVariant {
                    theirs: case_label(s),
                    theirs_ns: ns_per_particle(s, s.median_s),
                    theirs_ci_ns: s.ci95_s.map(|x| ns_per_particle(s, x)),
                    speedup: s.median_s / o.median_s,
                    oversubscribed: s.oversubscribed,
                })
                .collect(),
        });
    }
    // One system's rows together: by scenario, n, workers and θ (stable: our kernels in file
    // order within each).
    out.sort_by(|a, b| {
        (a.scenario.as_str(), a.n, a.workers).cmp(&(b.scenario.as_str(), b.n, b.workers))
    });
    out
}

#[cfg(test)]
fn cost_at_error(points: &[(f64, f64)], target: f64) -> Option<f64> {
    bracket(points, target).map(|(s, _)| s)
}

/// The time at median error `target` from `(error, seconds)` points, interpolating log time
/// linearly in log error between the first two neighbours (in error) that bracket it, with
/// their indices in `points`; `None` when no pair does. A point that another beats on both (no
/// larger error, less time) is left out: nobody would choose that setting, so a code is
/// compared at its best.
fn bracket(points: &[(f64, f64)], target: f64) -> Option<(f64, [usize; 2])> {
    let mut v: Vec<(f64, f64, usize)> = points
        .iter()
        .enumerate()
        .map(|(i, &(e, s))| (e, s, i))
        .filter(|&(e, s, _)| e > 0.0 && s > 0.0 && e.is_finite() && s.is_finite())
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut fastest = f64::INFINITY;
    v.retain(|&(_, s, _)| {
        let better = s < fastest;
        fastest = fastest.min(s);
        better
    });
    v.windows(2).find_map(|w| {
        let ((e0, s0, i0), (e1, s1, i1)) = (w[0], w[1]);
        if !(e0 <= target && target <= e1) {
            return None;
        }
        if e0 == e1 {
            return Some(if s0 <= s1 {
                (s0, [i0, i0])
            } else {
                (s1, [i1, i1])
            });
        }
        let f = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
        Some(((s0.ln() + f * (s1.ln() - s0.ln())).exp(), [i0, i1]))
    })
}

/// One code's settings on one system at one worker count: every case of its series over θ,
/// for ours all expansion orders together (a user picks the best of them), for an external
/// program its θ sweep or the members of its family.
struct Settings {
    scenario: nbody_engine::scenario::ScenarioKind,
    n: usize,
    workers: usize,
    code: String,
    /// `(median error, seconds per step)` of each setting, and its label.
    points: Vec<(f64, f64)>,
    labels: Vec<String>,
}

impl Settings {
    /// The settings of `series` grouped by code, system and workers, in first-seen order.
    fn of<'a>(series: impl IntoIterator<Item = &'a ThetaAnalysis>) -> Vec<Settings> {
        let mut out: Vec<Settings> = Vec::new();
        for t in series {
            let (scenario, n, w) = (t.series.scenario, t.series.n.unwrap_or(0), workers(t));
            let code = t.series.kernel.name().to_string();
            let at = match out.iter().position(|s| {
                s.scenario == scenario && s.n == n && s.workers == w && s.code == code
            }) {
                Some(i) => i,
                None => {
                    out.push(Settings {
                        scenario,
                        n,
                        workers: w,
                        code: code.clone(),
                        points: Vec::new(),
                        labels: Vec::new(),
                    });
                    out.len() - 1
                }
            };
            for p in &t.points {
                if let Some([median, _]) = p.force_error {
                    out[at].points.push((median, p.median_s));
                    out[at].labels.push(setting(p, &code));
                }
            }
        }
        out
    }

    /// The time at `error` and the two settings it lies between.
    fn at(&self, error: f64) -> Option<(f64, [String; 2])> {
        let (s, [a, b]) = bracket(&self.points, error)?;
        Some((s, [self.labels[a].clone(), self.labels[b].clone()]))
    }

    /// [`Settings::at`], or when no two settings bracket `error` but some are more accurate,
    /// the fastest of those, named with its error: an upper bound on the time at `error`.
    /// Used for our codes only, so that a comparison can understate our speed, never overstate
    /// it.
    fn at_most(&self, error: f64) -> Option<(f64, [String; 2])> {
        self.at(error).or_else(|| {
            let (i, &(e, s)) = self
                .points
                .iter()
                .enumerate()
                .filter(|(_, (e, s))| *e <= error && s.is_finite() && *s > 0.0)
                .min_by(|a, b| a.1.1.total_cmp(&b.1.1))?;
            let label = format!("{} at {e:.1e}", self.labels[i]);
            Some((s, [label.clone(), label]))
        })
    }
}

/// A case's setting within its code: "θ=0.5 quadrupole", "θ=0.4 order 6", or a family
/// member's name without the family's ("eps1e-2" of "fmm3d-eps1e-2"), after the θ it ran at
/// when the sweep gave it one ("θ=0.7 quadrupole" of "pytreegrav-quadrupole").
fn setting(p: &Point, code: &str) -> String {
    if let Some(member) = p.family_setting(code) {
        return match p.theta {
            Some(t) => format!("θ={t} {member}"),
            None => member,
        };
    }
    let mut parts = Vec::new();
    if let Some(t) = p.theta {
        parts.push(format!("θ={t}"));
    }
    if p.case.multipole != nbody_engine::kernels::Multipole::Monopole {
        parts.push(p.case.multipole.name().to_string());
    }
    if let Some(order) = p.case.order {
        parts.push(format!("order {order}"));
    }
    if let Some(skin) = p.case.skin {
        parts.push(format!("skin {skin}"));
    }
    parts.join(" ")
}

fn error_range(points: &[(f64, f64)]) -> [f64; 2] {
    points
        .iter()
        .fold([f64::INFINITY, 0.0], |[lo, hi], &(e, _)| {
            [lo.min(e), hi.max(e)]
        })
}

fn workers(t: &ThetaAnalysis) -> usize {
    t.series.threads.unwrap_or(1) * t.series.ranks.unwrap_or(1)
}

/// Each of our tree codes (at its best over θ and expansion orders) next to each external one
/// of the same scenario, n and workers, at [`EQUAL_ERROR`], and at each of [`TIGHTER_ERRORS`]
/// that the external code reaches. Ours may stand in with a more accurate setting
/// ([`Settings::at_most`]); theirs must bracket the error.
pub(crate) fn equal_error(theta: &[ThetaAnalysis]) -> Vec<EqualErrorCost> {
    let (theirs, ours): (Vec<&ThetaAnalysis>, Vec<&ThetaAnalysis>) =
        theta.iter().partition(|t| t.series.kernel.is_external());
    let (theirs, ours) = (Settings::of(theirs), Settings::of(ours));
    let mut out = Vec::new();
    let levels =
        std::iter::once((EQUAL_ERROR, true)).chain(TIGHTER_ERRORS.iter().map(|&e| (e, false)));
    for (error, always) in levels {
        for t in &theirs {
            let at_theirs = t.at(error);
            if at_theirs.is_none() && !always {
                continue;
            }
            let same =
                |o: &&Settings| o.scenario == t.scenario && o.n == t.n && o.workers == t.workers;
            for o in ours.iter().filter(same) {
                let at_ours = o.at_most(error);
                out.push(EqualErrorCost {
                    scenario: o.scenario.name().into(),
                    n: o.n,
                    workers: o.workers,
                    error,
                    ours: o.code.clone(),
                    theirs: t.code.clone(),
                    ours_s: at_ours.as_ref().map(|a| a.0),
                    theirs_s: at_theirs.as_ref().map(|a| a.0),
                    speedup: at_ours
                        .as_ref()
                        .zip(at_theirs.as_ref())
                        .map(|(o, t)| t.0 / o.0),
                    ours_between: at_ours.map(|a| a.1),
                    theirs_between: at_theirs.clone().map(|a| a.1),
                    ours_errors: error_range(&o.points),
                    theirs_errors: error_range(&t.points),
                });
            }
        }
    }
    out
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use nbody_engine::kernels::Multipole;
    use nbody_engine::scenario::ScenarioKind;
    use nbody_records::kernel_or_program::KernelOrProgram;
    use nbody_records::plan::Case;

    /// A complete case of `code` on `scenario` whose samples are `median_s` per step ± 1%.
    pub(in crate::analysis) fn point(
        scenario: ScenarioKind,
        code: &str,
        n: usize,
        t: usize,
        r: usize,
        median_s: f64,
    ) -> Point {
        let case = Case {
            scenario,
            kernel: KernelOrProgram::from_name(code),
            n,
            threads: t,
            ranks: r,
            theta: None,
            multipole: Multipole::Monopole,
            order: None,
            skin: None,
            seed: 1,
            precision: None,
            time_factor: 1,
            decomp: None,
        };
        Point {
            key: case.key(),
            case,
            n,
            threads: t,
            ranks: r,
            time_factor: 1,
            theta: None,
            decomp: None,
            comm_s_per_step: None,
            bytes_per_step: None,
            transfer_s_per_step: None,
            compute_imbalance: None,
            samples: vec![median_s * 0.99, median_s, median_s * 1.01],
            median_s,
            ci95_s: [median_s * 0.99, median_s * 1.01],
            oversubscribed: false,
            ns_per_particle_step: median_s * 1e9 / n as f64,
            pair_evals_per_s: None,
            pair_checks_per_step: None,
            phases: Default::default(),
            named_phases: Vec::new(),
            step_ns: None,
            force_error: None,
            max_energy_drift: None,
            sanity_ok: None,
        }
    }

    #[test]
    fn the_octree_names_its_expansion_and_other_codes_none() {
        let mut tree = point(ScenarioKind::Galaxy, "octree", 1000, 2, 1, 1e-3);
        tree.theta = Some(0.5);
        assert_eq!(case_label(&tree), "octree θ=0.5 monopole, 2 threads");
        tree.case.multipole = Multipole::Quadrupole;
        assert_eq!(case_label(&tree), "octree θ=0.5 quadrupole, 2 threads");
        // An external program's expansion is its own: nothing is made up for it.
        let mut peer = point(ScenarioKind::Galaxy, "pytreegrav", 1000, 1, 1, 1e-3);
        peer.theta = Some(0.5);
        assert_eq!(case_label(&peer), "pytreegrav θ=0.5");
    }

    #[test]
    fn ours_are_set_against_the_fastest_peer_variant_of_each_case() {
        use ScenarioKind::{LjBox, LjLiquid};
        let n = 100_000;
        // Two LAMMPS variants: the tuned one is faster on one worker, the plain one on two
        // (ranks against our threads), and only the plain one ran the liquid.
        let cases = vec![
            point(LjBox, "verlet", n, 1, 1, 2e-3),
            point(LjBox, "verlet", n, 2, 1, 1.6e-3),
            point(LjBox, "lammps", n, 1, 1, 4.5e-3),
            point(LjBox, "lammps", n, 1, 2, 1.5e-3),
            point(LjBox, "lammps-tuned", n, 1, 1, 3e-3),
            point(LjBox, "lammps-tuned", n, 1, 2, 1.8e-3),
            // Another n: no peer there, no row.
            point(LjBox, "verlet", 2 * n, 1, 1, 4e-3),
            point(LjLiquid, "verlet", n, 1, 1, 6e-3),
            point(LjLiquid, "lammps", n, 1, 1, 9e-3),
        ];
        let rows = ratios(&cases);
        let got: Vec<(&str, usize, &str, Vec<&str>)> = rows
            .iter()
            .map(|r| {
                let others = r.others.iter().map(|o| o.theirs.as_str()).collect();
                (r.scenario.as_str(), r.workers, r.theirs.as_str(), others)
            })
            .collect();
        assert_eq!(
            got,
            vec![
                ("lj-box", 1, "lammps-tuned", vec!["lammps"]),
                (
                    "lj-box",
                    2,
                    "lammps, 2 ranks",
                    vec!["lammps-tuned, 2 ranks"]
                ),
                ("lj-liquid", 1, "lammps", vec![]),
            ]
        );
        // The ratio is against the fastest; the plain run keeps its own beside it.
        let one = &rows[0];
        assert!((one.speedup - 1.5).abs() < 1e-12, "{}", one.speedup);
        assert!((one.theirs_ns - 30.0).abs() < 1e-9);
        assert!((one.others[0].speedup - 2.25).abs() < 1e-12);
        assert!((one.others[0].theirs_ns - 45.0).abs() < 1e-9);
        let two = &rows[1];
        assert_eq!(two.ours, "verlet, 2 threads");
        assert!((two.speedup - 1.5e-3 / 1.6e-3).abs() < 1e-12);
        let ci = two.speedup_ci.unwrap();
        assert!(ci[0] <= two.speedup && two.speedup <= ci[1], "{ci:?}");
        // The same results in another order choose the same variants.
        let mut reversed = cases.clone();
        reversed.reverse();
        let again: Vec<String> = ratios(&reversed).iter().map(|r| r.theirs.clone()).collect();
        let first: Vec<String> = rows.iter().map(|r| r.theirs.clone()).collect();
        assert_eq!(again, first);
    }

    #[test]
    fn cost_at_error_is_exact_on_a_power_law_and_refuses_to_extrapolate() {
        // cost = 2e-3 · e^-0.5: straight in log-log, so the interpolation is exact.
        let law = |e: f64| 2e-3 * e.powf(-0.5);
        let pts: Vec<(f64, f64)> = [3e-4, 8e-4, 2.5e-3, 7e-3]
            .iter()
            .map(|&e| (e, law(e)))
            .collect();
        for target in [3e-4, 1e-3, 5e-3] {
            let got = cost_at_error(&pts, target).unwrap();
            assert!((got / law(target) - 1.0).abs() < 1e-12, "{target}: {got}");
        }
        // Outside the measured errors there is no answer, whatever the order of the points.
        let mut rev = pts.clone();
        rev.reverse();
        assert_eq!(cost_at_error(&rev, 1e-4), None);
        assert_eq!(cost_at_error(&rev, 1e-2), None);
        assert!(cost_at_error(&rev, 1e-3).is_some());
        // Points without an error or a time do not count.
        assert_eq!(cost_at_error(&[(0.0, 1.0), (f64::NAN, 1.0)], 1e-3), None);
    }

    /// A family member is named by its suffix, after the θ it ran at when it has one, so
    /// that a member swept over θ names each of its settings apart.
    #[test]
    fn a_family_member_is_named_with_its_theta() {
        let plain = point(ScenarioKind::Coulomb, "fmm3d-eps1e-2", 1000, 1, 1, 1.0);
        assert_eq!(setting(&plain, "fmm3d"), "eps1e-2");
        let mut swept = point(
            ScenarioKind::Galaxy,
            "pytreegrav-quadrupole",
            1000,
            1,
            1,
            1.0,
        );
        swept.theta = Some(0.7);
        assert_eq!(setting(&swept, "pytreegrav"), "θ=0.7 quadrupole");
        let mut head = point(ScenarioKind::Galaxy, "pytreegrav", 1000, 1, 1, 1.0);
        head.theta = Some(0.5);
        assert_eq!(setting(&head, "pytreegrav"), "θ=0.5");
    }

    #[test]
    fn tighter_errors_are_compared_only_where_the_other_code_reaches_them() {
        use crate::analysis::groups::SeriesKey;
        use nbody_engine::scenario::Precision;
        let series = |code: &str, errors: &[(f64, f64)]| {
            let points: Vec<Point> = errors
                .iter()
                .map(|&(error, s)| {
                    let mut p = point(ScenarioKind::Coulomb, code, 1000, 1, 1, s);
                    p.force_error = Some([error, 10.0 * error]);
                    // A θ to name the setting by: its time.
                    p.theta = Some(s);
                    p
                })
                .collect();
            let series = SeriesKey {
                scenario: ScenarioKind::Coulomb,
                kernel: KernelOrProgram::from_name(code),
                precision: Precision::F64,
                theta: None,
                multipole: Multipole::Monopole,
                order: None,
                skin: None,
                n: Some(1000),
                threads: Some(1),
                ranks: Some(1),
                decomp: None,
            };
            ThetaAnalysis {
                label: series.label(),
                series,
                points,
            }
        };
        let theta = [
            series("fmm", &[(1e-5, 4.0), (1e-3, 1.0)]),
            // Another order of ours: one code with the first, at its best of both.
            series("fmm", &[(1e-4, 1.5)]),
            // Reaches 1e-4 and 1e-6: compared there too.
            series("fast-multipole", &[(1e-6, 8.0), (1e-2, 2.0)]),
            // Does not: compared at 1e-3 only. Its setting at 2e-3 is slower than the one
            // at 5e-4 and is left out.
            series("tree", &[(5e-4, 6.0), (2e-3, 7.0), (1e-2, 3.0)]),
        ];
        let rows = equal_error(&theta);
        let got: Vec<(f64, &str)> = rows.iter().map(|r| (r.error, r.theirs.as_str())).collect();
        assert_eq!(
            got,
            [
                (1e-3, "fast-multipole"),
                (1e-3, "tree"),
                (1e-4, "fast-multipole"),
                (1e-6, "fast-multipole")
            ]
        );
        // At 1e-4 theirs interpolates between 1e-6 (8 s) and 1e-2 (2 s): 4 s; ours has a
        // setting there, 1.5 s (the other order would have given 2 s).
        let at = &rows[2];
        assert!((at.theirs_s.unwrap() - 4.0).abs() < 1e-12);
        assert!((at.ours_s.unwrap() - 1.5).abs() < 1e-12);
        assert!((at.speedup.unwrap() - 4.0 / 1.5).abs() < 1e-12);
        assert_eq!(at.theirs_between, Some(["θ=8".into(), "θ=2".into()]));
        assert_eq!(at.ours_between.as_ref().unwrap()[1], "θ=1.5");
        // Ours with every setting more accurate than the target: the fastest stands in.
        let tight = [
            series("fmm", &[(1e-6, 5.0), (2e-4, 3.0), (5e-4, 2.5)]),
            series("tree", &[(5e-4, 6.0), (1e-2, 3.0)]),
        ];
        let rows_tight = equal_error(&tight);
        assert_eq!(rows_tight[0].ours_s, Some(2.5));
        assert_eq!(
            rows_tight[0].ours_between,
            Some(["θ=2.5 at 5.0e-4".into(), "θ=2.5 at 5.0e-4".into()])
        );
        // Theirs never does: every setting of "tree" here is less accurate than 1e-4.
        assert!(rows_tight.iter().all(|r| r.error == EQUAL_ERROR));
        // At 1e-3, ours between its two orders' settings.
        assert_eq!(rows[0].ours_between, Some(["θ=1.5".into(), "θ=1".into()]));
        assert!((rows[0].ours_s.unwrap() - 1.0).abs() < 1e-12);
    }
}
