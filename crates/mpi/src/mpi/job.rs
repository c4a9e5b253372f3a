//! One distributed run: every rank builds the system from the seed, runs its driver, and
//! rank 0 gathers the statistics and the final state, computes the energies, and (for
//! `mpi-check`) integrates the same system serially to compare.

use super::allgather::Allgather;
use super::communicator::{Comm, Lent};
use super::domain::{Domain, DomainOptions};
use super::driver::{Driver, Timeline, drive, pack_owned};
use super::error::MpiError;
use super::tree::{EssentialTree, OctantTree};
use crate::decomp::Decomposition;
use crate::decomp::check::{CheckReport, TreeCheck, compare, relative_drift};
use crate::decomp::stats::{MasterSummary, MpiReport, RankStats, attribute_waits, reduce};
use crate::decomp::wire::{bytes_of, floats_of, packed_id, particle_values, push_particle};
use crate::engine::{PhaseTimes, Simulation};
use crate::kernels::CompiledKernels;
use crate::kernels::{KernelKind, KernelParams, WorkCounters};
use crate::output::dump;
use crate::real::Real;
use crate::run::{Measured, RunOutcome};
use crate::scenario::{System, SystemJob};
use crate::state::{Field, State, zero_field};
use crate::stats::StepHistogram;
use crate::validate::{octree_tolerance, sampled_force_error};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Bodies whose forces `mpi-check` compares with the direct sum for a distributed tree (all of
/// them up to this n; the sum costs n per body).
const TREE_CHECK_BODIES: usize = 4000;

/// What to run on every rank.
#[derive(Clone, Debug)]
pub struct MpiSpec {
    /// The force kernel every rank runs (and rank 0's serial check).
    pub kernel: KernelKind,
    /// Its parameters (θ, expansion order, skin...).
    pub params: KernelParams,
    /// How the particles and the work are split over the ranks.
    pub decomp: Decomposition,
    /// Timed steps, after the warm-up.
    pub steps: u64,
    /// Untimed steps before the timed ones.
    pub warmup: u64,
    /// Threads per rank.
    pub threads: usize,
    /// Rank grid and rebalancing of `--decomp domain` (ignored by the other decompositions).
    pub domain: DomainOptions,
    /// Where rank 0 writes the final state and forces; `None`: not written.
    pub dump_state: Option<PathBuf>,
    /// Also integrate serially on rank 0 and compare the final states (`mpi-check`).
    pub check: bool,
}

/// What rank 0 ends up with.
pub struct RootResult {
    /// The run's timings, work and energies, with the per-rank MPI report.
    pub outcome: RunOutcome,
    /// The comparison with a serial run of the same steps; `Some` only when `check` was asked.
    pub check: Option<CheckReport>,
}

/// Runs `spec` on the system it is given; `Some` on rank 0.
pub(crate) struct MpiJob<'a> {
    pub spec: &'a MpiSpec,
    pub comm: &'a mut Comm,
}

/// One rank's statistics as sent to rank 0.
#[derive(Serialize, Deserialize)]
struct RankRecord {
    stats: RankStats,
    host: String,
    compute_s: Vec<f64>,
    wall_ns: Vec<u64>,
    work: WorkCounters,
    build_s: f64,
    far_migrated: u64,
}

impl SystemJob for MpiJob<'_> {
    type Output = Result<Option<RootResult>, MpiError>;

    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        system: System<T, L, D>,
    ) -> Self::Output {
        let MpiJob { spec, comm } = self;
        spec.decomp.check(spec.kernel)?;
        if spec.decomp != Decomposition::Domain && spec.domain.rank_grid.is_some() {
            return Err(MpiError::Usage(
                "--rank-grid applies to --decomp domain only".into(),
            ));
        }
        let kernel = system.kernel(spec.kernel, &spec.params)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(spec.threads)
            .build()
            .map_err(|source| MpiError::Pool {
                threads: spec.threads,
                source,
            })?;
        let reference = comm.is_root().then(|| system.clone());
        let law = system.law;
        let mut lent = Lent::new(&mut *comm);
        let (line, records, last) = pool.install(move || -> Result<_, MpiError> {
            let comm = lent.get();
            let mut driver: Box<dyn Driver<T, D>> = match spec.decomp {
                Decomposition::Allgather => {
                    Box::new(Allgather::new(system, spec.kernel, kernel, comm)?)
                }
                Decomposition::Domain => {
                    // The border system is made of new particles every step: a Verlet list
                    // kept between steps would be rebuilt every time, so it gets a cell list.
                    let border = KernelKind::CellList.build::<T, L, D>(law, &spec.params)?;
                    Box::new(Domain::new(system, kernel, border, &spec.domain, comm)?)
                }
                Decomposition::Octants => Box::new(OctantTree::new(system, &spec.params, comm)?),
                Decomposition::Tree => Box::new(EssentialTree::new(
                    system,
                    &spec.params,
                    spec.domain.rebalance_above,
                    comm,
                )?),
            };
            let line = drive(driver.as_mut(), comm, spec.warmup, spec.steps)?;
            let records = gather_records(driver.as_ref(), &line, comm)?;
            let (state, forces) = driver.owned();
            let last = gather_state(state, forces, comm)?;
            Ok((
                line,
                records.map(|r| (r, driver.rank_grid(), driver.rebalances())),
                last,
            ))
        })?;
        let (Some(reference), Some((records, grid, rebalances)), Some((state, forces))) =
            (reference, records, last)
        else {
            return Ok(None);
        };
        let report = mpi_report(spec, comm, &line, records, grid, rebalances);
        pool.install(|| finish(spec, reference, state, forces, report, &line))
            .map(Some)
    }
}

/// Sends this rank's statistics to rank 0; there, every rank's.
fn gather_records<T: Real, const D: usize>(
    driver: &dyn Driver<T, D>,
    line: &Timeline,
    comm: &mut Comm,
) -> Result<Option<Vec<RankRecord>>, MpiError> {
    let tally = driver.tally();
    let record = RankRecord {
        stats: RankStats {
            rank: comm.rank(),
            particles: driver.owned().0.len() as u64,
            particles_mean: line.particles_mean,
            compute_s: line.compute_s.iter().sum(),
            force_s: tally.force_s,
            comm_s: line.comm.seconds,
            wait_s: 0.0,
            transfer_s: 0.0,
            bytes_sent: line.comm.bytes_sent,
            messages_sent: line.comm.messages_sent,
            collectives: line.comm.collectives,
            ghosts_received: tally.ghosts_received,
            migrated_out: tally.migrated_out,
            pair_checks: tally.work.pair_checks,
        },
        host: ::mpi::environment::processor_name().unwrap_or_else(|_| "unknown".into()),
        compute_s: line.compute_s.clone(),
        wall_ns: line.wall_ns.clone(),
        work: tally.work,
        build_s: tally.build_s,
        far_migrated: tally.far_migrated,
    };
    let bytes = serde_json::to_vec(&record).map_err(|e| MpiError::Serialize(e.to_string()))?;
    let Some(all) = comm.gather_to_root(&bytes)? else {
        return Ok(None);
    };
    all.iter()
        .map(|b| serde_json::from_slice(b).map_err(|e| MpiError::Serialize(e.to_string())))
        .collect::<Result<Vec<RankRecord>, _>>()
        .map(Some)
}

/// Particles and their forces.
type Particles<T, const D: usize> = (State<T, D>, Field<T, D>);

/// Gathers every rank's particles and forces on rank 0, in id order.
fn gather_state<T: Real, const D: usize>(
    state: &State<T, D>,
    forces: &Field<T, D>,
    comm: &mut Comm,
) -> Result<Option<Particles<T, D>>, MpiError> {
    let packed = pack_owned(state, forces);
    let Some(parts) = comm.gather_to_root(bytes_of(&packed))? else {
        return Ok(None);
    };
    let width = particle_values(D) + D;
    let mut records: Vec<f64> = Vec::new();
    for p in &parts {
        records.extend(floats_of::<f64>(p));
    }
    let mut rows: Vec<&[f64]> = records.chunks_exact(width).collect();
    rows.sort_by(|a, b| packed_id::<D>(a).total_cmp(&packed_id::<D>(b)));
    let mut out = State::<T, D>::new(0);
    let mut f = zero_field::<T, D>(0);
    for r in rows {
        push_particle(r, &mut out);
        for d in 0..D {
            f[d].push(T::of(r[particle_values(D) + d]));
        }
    }
    Ok(Some((out, f)))
}

/// Every rank's statistics, combined on rank 0.
struct Combined {
    report: MpiReport,
    /// Work of all ranks.
    work: WorkCounters,
    /// Mean over ranks of the seconds spent building cells or trees.
    build_mean: f64,
    /// Particles that moved beyond the neighbouring regions, all ranks.
    far_migrated: u64,
}

/// The `mpi` block of the result, from every rank's record.
fn mpi_report(
    spec: &MpiSpec,
    comm: &Comm,
    line: &Timeline,
    mut records: Vec<RankRecord>,
    grid: Option<Vec<usize>>,
    rebalances: u64,
) -> Combined {
    let compute: Vec<Vec<f64>> = records.iter().map(|r| r.compute_s.clone()).collect();
    let mut per_rank: Vec<RankStats> = records.iter().map(|r| r.stats.clone()).collect();
    attribute_waits(&mut per_rank, &compute);
    let steps = records.iter().map(|r| r.wall_ns.len()).min().unwrap_or(0);
    let step_ns: Vec<u64> = (0..steps)
        .map(|s| records.iter().map(|r| r.wall_ns[s]).max().unwrap_or(0))
        .collect();
    let mut work = WorkCounters::default();
    for r in &records {
        work += r.work;
    }
    let build_mean = records.iter().map(|r| r.build_s).sum::<f64>() / records.len() as f64;
    let far_migrated: u64 = records.iter().map(|r| r.far_migrated).sum();
    let hosts = records.drain(..).map(|r| r.host).collect();
    let library = ::mpi::environment::library_version()
        .map(|v| v.trim_end_matches('\0').trim().to_string())
        .unwrap_or_else(|_| "unknown".into());
    let reduced = reduce(&per_rank);
    let report = MpiReport {
        ranks: comm.size(),
        decomposition: spec.decomp,
        threads_per_rank: spec.threads,
        rank_grid: grid,
        library,
        hosts,
        warmup_steps: spec.warmup,
        rebalances,
        master_summary: MasterSummary {
            communication_s: line.comm.seconds,
            computation_s: line.total_s - line.comm.seconds,
            interactions: work.pair_checks,
        },
        per_rank,
        reduced,
        step_ns,
    };
    Combined {
        report,
        work,
        build_mean,
        far_migrated,
    }
}

/// Rank 0: energies, the dump, the result, and the comparison with a serial run.
fn finish<T: Real, L: CompiledKernels<T, D>, const D: usize>(
    spec: &MpiSpec,
    reference: System<T, L, D>,
    state: State<T, D>,
    forces: Field<T, D>,
    combined: Combined,
    line: &Timeline,
) -> Result<RootResult, MpiError> {
    let Combined {
        report,
        work,
        build_mean,
        far_migrated,
    } = combined;
    let n = state.len();
    let steps_done = spec.warmup + spec.steps;
    let serial_kernel = || spec.kernel.build::<T, L, D>(reference.law, &spec.params);
    let mut start = Simulation::new(reference.clone(), serial_kernel()?);
    let e0 = start.probe();
    let p0 = start.state.momentum().to_vec();
    let last = System {
        state: state.clone(),
        ..reference.clone()
    };
    let mut end = Simulation::new(last, serial_kernel()?);
    let e1 = end.probe().finite_after(steps_done)?;
    let info = &reference.info;
    if let Some(path) = &spec.dump_state {
        let header = dump::run_header::<T, D>(info, n, steps_done);
        let law = reference.law.parameters();
        let text = dump::state_dump(&header, &law, &state, &forces);
        crate::output::write_atomic(path, text.as_bytes())?;
    }
    let check = if spec.check {
        let mut serial = Simulation::new(reference.clone(), serial_kernel()?);
        for _ in 0..steps_done {
            serial
                .step()
                .map_err(|error| MpiError::Boundary { rank: 0, error })?;
        }
        let migrated = report.per_rank.iter().map(|r| r.migrated_out).sum();
        let mut check = compare(&serial.state, &state, migrated, far_migrated);
        if spec.decomp.distributes_the_tree() {
            // `end` holds the serial octree's forces at the distributed final positions.
            let e_serial = serial.probe().finite_after(steps_done)?;
            let picks = n.min(TREE_CHECK_BODIES);
            let scale = e0.kinetic.abs() + e0.potential.abs() + e0.external.abs();
            // (`end` holds its state in the kernel's order, the gathered one in id order.)
            let error = |s: &State<T, D>, f: &Field<T, D>| {
                sampled_force_error(&reference.law, s, f, picks, 1).0
            };
            check.tree = Some(TreeCheck {
                force_error: error(&state, &forces),
                serial_force_error: error(&end.state, &end.forces),
                force_tolerance: octree_tolerance(reference.law.kind(), spec.params.theta),
                energy_drift: relative_drift(e0.total(), scale, e1.total()),
                serial_energy_drift: relative_drift(e0.total(), scale, e_serial.total()),
            });
        }
        Some(check)
    } else {
        None
    };
    let ranks_here = report
        .hosts
        .iter()
        .filter(|h| **h == report.hosts[0])
        .count();
    let mut step_ns = StepHistogram::new();
    for &ns in &report.step_ns {
        step_ns.record(ns);
    }
    let mean = |f: &dyn Fn(&RankStats) -> f64| {
        report.per_rank.iter().map(f).sum::<f64>() / report.per_rank.len() as f64
    };
    let phases = PhaseTimes {
        force_build: build_mean,
        force_interact: mean(&|r| r.force_s) - build_mean,
        integrate: mean(&|r| r.compute_s - r.force_s),
        boundary: 0.0,
        output: 0.0,
    };
    let outcome = RunOutcome::new::<T, D>(Measured {
        info,
        law: reference.law.kind().name(),
        kernel: spec.kernel,
        params: spec.params,
        n,
        steps: spec.steps,
        threads: spec.threads,
        threads_here: spec.threads * ranks_here,
        total_s: line.total_s,
        step_ns: &step_ns,
        phases,
        work,
        pairs_interacting_final: end.probe_work().pairs_interacting,
        energy: [e0, e1],
        momentum: [p0, state.momentum().to_vec()],
        mpi: Some(report),
    });
    Ok(RootResult { outcome, check })
}
