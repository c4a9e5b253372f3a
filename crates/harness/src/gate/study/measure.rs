//! Measuring the study's blocks: every case's rounds of each side, interleaved.

use super::Load;
use super::{Block, SLOWDOWNS};
use crate::experiment::measure::{RoundSpec, measure_round};
use nbody_engine::clock::WallClock;
use nbody_engine::kernels::KernelKind;
use nbody_records::config::SweepConfig;
use nbody_records::kernel_or_program::KernelOrProgram;
use nbody_records::plan::Case;
use nbody_records::results::CaseRecord;

/// Which measurement a round belongs to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Side {
    A,
    B,
    /// The slowed kernel at `SLOWDOWNS[i]`.
    Slowed(usize),
}

/// A spinning `sh` loop, stopped when dropped.
struct Spinner(std::process::Child);

impl Spinner {
    fn start() -> std::io::Result<Spinner> {
        std::process::Command::new("sh")
            .args(["-c", "while :; do :; done"])
            .spawn()
            .map(Spinner)
    }
}

impl Drop for Spinner {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Measures `blocks` blocks of `cases` (built-in kernels only), each case `rounds` rounds of
/// `samples` samples per side; `progress` hears of each block.
#[allow(clippy::too_many_arguments)]
pub fn measure_blocks(
    config: &SweepConfig,
    cases: &[Case],
    blocks: usize,
    rounds: usize,
    samples: usize,
    slowed: KernelKind,
    load: Load,
    duet: bool,
    progress: &mut dyn FnMut(usize, &Block),
) -> Result<Vec<Block>, String> {
    let _spinner = match load {
        Load::Quiet => None,
        Load::Spin => Some(Spinner::start().map_err(|e| format!("cannot start `sh`: {e}"))?),
    };
    let logical = nbody_engine::run::logical_cpus();
    let mut out = Vec::with_capacity(blocks);
    for b in 0..blocks {
        let started = std::time::Instant::now();
        let fresh = |cases: &[&Case]| -> Vec<CaseRecord> {
            cases
                .iter()
                .map(|c| CaseRecord::new((*c).clone(), rounds, logical))
                .collect()
        };
        let all: Vec<&Case> = cases.iter().collect();
        let slow_cases: Vec<&Case> = cases
            .iter()
            .filter(|c| c.kernel == KernelOrProgram::Kernel(slowed))
            .collect();
        let mut block = Block {
            wall_s: 0.0,
            a: fresh(&all),
            b: fresh(&all),
            slowed: if duet {
                Vec::new()
            } else {
                SLOWDOWNS.iter().map(|_| fresh(&slow_cases)).collect()
            },
        };
        for round in 0..rounds {
            let mut order: Vec<usize> = (0..cases.len()).collect();
            if round % 2 == 1 {
                order.reverse();
            }
            for i in order {
                let case = &cases[i];
                if duet {
                    let (a, b) = std::thread::scope(|s| {
                        let a = s.spawn(|| one_round(config, case, samples, 1.0));
                        let b = s.spawn(|| one_round(config, case, samples, 1.0));
                        (a.join(), b.join())
                    });
                    let joined = |r: std::thread::Result<Result<_, String>>| {
                        r.map_err(|_| format!("{}: a measuring thread panicked", case.key()))?
                    };
                    block.a[i].add_round(joined(a)?, config.measure.max_energy_drift);
                    block.b[i].add_round(joined(b)?, config.measure.max_energy_drift);
                    continue;
                }
                let mut sides = vec![Side::A, Side::B];
                let slot = slow_cases.iter().position(|c| c.key() == case.key());
                if slot.is_some() {
                    sides.extend((0..SLOWDOWNS.len()).map(Side::Slowed));
                }
                // Each side goes first as often as the others, over rounds and cases.
                let shift = (round + i) % sides.len();
                sides.rotate_left(shift);
                for side in sides {
                    let factor = match side {
                        Side::Slowed(k) => SLOWDOWNS[k],
                        _ => 1.0,
                    };
                    let outcome = one_round(config, case, samples, factor)?;
                    let drift = config.measure.max_energy_drift;
                    match (side, slot) {
                        (Side::A, _) => block.a[i].add_round(outcome, drift),
                        (Side::B, _) => block.b[i].add_round(outcome, drift),
                        (Side::Slowed(k), Some(j)) => block.slowed[k][j].add_round(outcome, drift),
                        // Slowed sides are only planned for the slowed kernel's cases.
                        (Side::Slowed(_), None) => {}
                    }
                }
            }
        }
        block.wall_s = started.elapsed().as_secs_f64();
        progress(b, &block);
        out.push(block);
    }
    Ok(out)
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
