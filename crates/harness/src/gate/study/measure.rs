//! Measuring the study's blocks: every case's rounds of each side, interleaved, and then, look
//! by look, the rounds the gate's A/B decisions would measure further.

use super::Load;
use super::decide::{self, Side};
use super::{Block, RawStudy, SLOWDOWNS};
use crate::experiment::measure::{RoundSpec, measure_round};
use nbody_engine::clock::WallClock;
use nbody_records::config::SweepConfig;
use nbody_records::kernel_or_program::KernelOrProgram;
use nbody_records::plan::Case;
use nbody_records::results::CaseRecord;

/// A spinning `sh` loop, stopped when dropped, and killed by the kernel when the study's
/// process ends any other way (interrupted, killed): left behind, it would spin on and hold
/// whatever the study inherited, such as the measurement lock of `flock`.
struct Spinner(std::process::Child);

impl Spinner {
    fn start() -> std::io::Result<Spinner> {
        use std::os::unix::process::CommandExt;
        let mut command = std::process::Command::new("sh");
        command.args(["-c", "while :; do :; done"]);
        // SAFETY: prctl between fork and exec only sets the child's own death signal.
        unsafe {
            command.pre_exec(|| {
                if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) == 0 {
                    Ok(())
                } else {
                    Err(std::io::Error::last_os_error())
                }
            });
        }
        command.spawn().map(Spinner)
    }
}

impl Drop for Spinner {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Measures `blocks` blocks (one decision each) of the cases of `raw.config` (built-in
/// kernels only): every case's first look of each side, then the rounds the decisions leave
/// undecided, look by look; `progress` hears of each block.
pub fn measure_blocks(
    raw: &RawStudy,
    cases: &[Case],
    blocks: usize,
    progress: &mut dyn FnMut(usize, &Block),
) -> Result<Vec<Block>, String> {
    let _spinner = match raw.load {
        Load::Quiet => None,
        Load::Spin => Some(Spinner::start().map_err(|e| format!("cannot start `sh`: {e}"))?),
    };
    let logical = nbody_engine::run::logical_cpus();
    let slowed = raw.slowed_kernel;
    let mut out = Vec::with_capacity(blocks);
    for b in 0..blocks {
        let started = std::time::Instant::now();
        let fresh = |cases: &[&Case]| -> Vec<CaseRecord> {
            cases
                .iter()
                .map(|c| CaseRecord::new((*c).clone(), 0, logical))
                .collect()
        };
        let all: Vec<&Case> = cases.iter().collect();
        let slow_cases: Vec<&Case> = cases
            .iter()
            .filter(|c| c.kernel == KernelOrProgram::Kernel(slowed))
            .collect();
        let slowed_records = || SLOWDOWNS.iter().map(|_| fresh(&slow_cases)).collect();
        let mut block = Block {
            wall_s: 0.0,
            a: fresh(&all),
            b: fresh(&all),
            slowed: slowed_records(),
            partners: if raw.duet {
                slowed_records()
            } else {
                Vec::new()
            },
        };
        let looks = decide::looks();
        // The first look: every side of every case.
        let mut need: Vec<(String, Side)> = Vec::new();
        for c in cases {
            need.push((c.key(), Side::A));
            need.push((c.key(), Side::B));
            if c.kernel == KernelOrProgram::Kernel(slowed) {
                for k in 0..SLOWDOWNS.len() {
                    need.push((c.key(), Side::Slowed(k)));
                    if raw.duet {
                        need.push((c.key(), Side::Partner(k)));
                    }
                }
            }
        }
        for &until in &looks {
            measure_look(raw, cases, &mut block, &need, until)?;
            need = decide::needs(raw, &block);
            if need.is_empty() {
                break;
            }
        }
        block.wall_s = started.elapsed().as_secs_f64();
        progress(b, &block);
        out.push(block);
    }
    Ok(out)
}

/// Rounds of the sides `need` names until each has `until`: round by round, the cases' order
/// reversed every round, each case's sides in an order rotating over rounds and cases (duet:
/// each pair a decision compares at the same moment, one per CPU).
fn measure_look(
    raw: &RawStudy,
    cases: &[Case],
    block: &mut Block,
    need: &[(String, Side)],
    until: usize,
) -> Result<(), String> {
    let config = &raw.config;
    let drift = config.measure.max_energy_drift;
    let samples = raw.samples_per_round;
    let slot = |block: &Block, key: &str| {
        block
            .slowed
            .first()
            .and_then(|s| s.iter().position(|r| r.key == key))
    };
    let from = need
        .iter()
        .map(|(k, s)| record(block, k, *s, slot(block, k)).map_or(0, |r| r.rounds.len()))
        .min()
        .unwrap_or(until);
    for round in from..until {
        let mut order: Vec<usize> = (0..cases.len()).collect();
        if round % 2 == 1 {
            order.reverse();
        }
        for i in order {
            let case = &cases[i];
            let key = case.key();
            let j = slot(block, &key);
            let mut sides: Vec<Side> = need
                .iter()
                .filter(|(k, s)| {
                    k == &key && record(block, k, *s, j).is_some_and(|r| r.rounds.len() == round)
                })
                .map(|(_, s)| *s)
                .collect();
            if sides.is_empty() {
                continue;
            }
            let runs: Vec<Vec<Side>> = if raw.duet && crate::gate::duet::suits(case) {
                duet_pairs(&sides)
            } else {
                // Each side goes first as often as the others, over rounds and cases.
                let shift = (round + i) % sides.len();
                sides.rotate_left(shift);
                sides.into_iter().map(|s| vec![s]).collect()
            };
            for run in runs {
                let outcomes = if run.len() == 2 {
                    duet_round(config, case, samples, [run[0], run[1]], round)?
                } else {
                    vec![one_round(config, case, samples, factor(run[0]))?]
                };
                for (side, outcome) in run.into_iter().zip(outcomes) {
                    match (side, j) {
                        (Side::A, _) => block.a[i].add_round(outcome, drift),
                        (Side::B, _) => block.b[i].add_round(outcome, drift),
                        (Side::Slowed(k), Some(j)) => block.slowed[k][j].add_round(outcome, drift),
                        (Side::Partner(k), Some(j)) => {
                            block.partners[k][j].add_round(outcome, drift)
                        }
                        // Slowed sides are only planned for the slowed kernel's cases.
                        (Side::Slowed(_) | Side::Partner(_), None) => {}
                    }
                }
            }
        }
    }
    Ok(())
}

/// The slowdown knob's factor for `side` (1: unchanged code).
fn factor(side: Side) -> f64 {
    match side {
        Side::Slowed(k) => SLOWDOWNS[k],
        _ => 1.0,
    }
}

/// A duet's sides grouped into the pairs measured at once: A with B, each slowdown with its
/// partner; a side without its pair (none, as the decisions ask for them) alone.
fn duet_pairs(sides: &[Side]) -> Vec<Vec<Side>> {
    let partner = |s: Side| match s {
        Side::A => Side::B,
        Side::B => Side::A,
        Side::Slowed(k) => Side::Partner(k),
        Side::Partner(k) => Side::Slowed(k),
    };
    let mut runs: Vec<Vec<Side>> = Vec::new();
    for &side in sides {
        if runs.iter().flatten().any(|&s| s == side) {
            continue;
        }
        let other = partner(side);
        if sides.contains(&other) {
            // The unchanged side (A or the partner) first: it takes the round's first CPU.
            let mut pair = vec![side, other];
            pair.sort_by_key(|s| matches!(s, Side::B | Side::Slowed(_)));
            runs.push(pair);
        } else {
            runs.push(vec![side]);
        }
    }
    runs
}

/// One round of each of `sides` at the same moment, each on a CPU of its own (swapped every
/// round, [`crate::gate::duet::cpu_of`]).
fn duet_round(
    config: &SweepConfig,
    case: &Case,
    samples: usize,
    sides: [Side; 2],
    round: usize,
) -> Result<Vec<nbody_records::round::RoundOutcome>, String> {
    use crate::gate::duet;
    let cpus = duet::cpus();
    let outcomes = std::thread::scope(|s| {
        let run = |slot: usize| {
            let side = sides[slot];
            s.spawn(move || {
                if let Some(cpus) = cpus {
                    duet::pin_this_thread(cpus[duet::cpu_of(slot, round)]);
                }
                one_round(config, case, samples, factor(side))
            })
        };
        let handles = [run(0), run(1)];
        handles.map(|h| h.join())
    });
    outcomes
        .into_iter()
        .map(|r| r.map_err(|_| format!("{}: a measuring thread panicked", case.key()))?)
        .collect()
}

/// The record of case `key` on `side` (`slot`: its index among the slowed kernel's cases).
fn record<'a>(
    block: &'a Block,
    key: &str,
    side: Side,
    slot: Option<usize>,
) -> Option<&'a CaseRecord> {
    match side {
        Side::A => block.a.iter().find(|r| r.key == key),
        Side::B => block.b.iter().find(|r| r.key == key),
        Side::Slowed(k) => block.slowed.get(k)?.get(slot?),
        Side::Partner(k) => block.partners.get(k)?.get(slot?),
    }
}

/// One round of `case` in this process, its kernel's force computation made `factor` times as
/// long (1: unchanged).
fn one_round(
    config: &SweepConfig,
    case: &Case,
    samples: usize,
    factor: f64,
) -> Result<nbody_records::round::RoundOutcome, String> {
    let KernelOrProgram::Kernel(kernel) = case.kernel else {
        return Err(format!(
            "{}: the study measures built-in kernels only",
            case.key()
        ));
    };
    let spec = RoundSpec {
        samples,
        warmup_s: config.measure.warmup_s,
        min_sample_s: config.measure.min_sample_s,
        steps_per_sample: None,
        force_error_sample: 0,
        reference_s: config.measure.reference_s,
        slowdown: (factor != 1.0)
            .then_some(crate::experiment::slowdown::TestSlowdown { kernel, factor }),
    };
    let setup = crate::experiment::case_setup(case, None);
    measure_round(&setup, case, kernel, &spec, &WallClock::new())
        .map_err(|e| format!("{}: {e}", case.key()))?
        .map_err(|e| format!("{}: {e}", case.key()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_duet_pairs_each_side_with_the_one_its_decision_compares() {
        let sides = [
            Side::Slowed(1),
            Side::B,
            Side::Partner(0),
            Side::A,
            Side::Slowed(0),
            Side::Partner(1),
            Side::Slowed(2),
        ];
        let runs = duet_pairs(&sides);
        assert_eq!(
            runs,
            vec![
                vec![Side::Partner(1), Side::Slowed(1)],
                vec![Side::A, Side::B],
                vec![Side::Partner(0), Side::Slowed(0)],
                // A slowdown whose partner is not asked for runs alone.
                vec![Side::Slowed(2)],
            ]
        );
    }
}
