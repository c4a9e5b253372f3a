//! The whole step on the pool's threads: sizes at which every pass forks (binning, the
//! re-ordering, kick and drift, walls, the field), and the results those passes must keep.
//! The cell list gathers each target's force in a fixed order; the lists add their parts'
//! forces in an order fixed by the list (the team step and the rayon passes alike): a run is
//! bitwise the same at any thread count, re-orderings and rebuilds included. An error in one
//! worker's block ends the step with that error on every thread count, without a hang.

use nbody_engine::engine::Simulation;
use nbody_engine::kernels::CompiledKernels;
use nbody_engine::kernels::{KernelKind, KernelParams};
use nbody_engine::real::Real;
use nbody_engine::scenario::{Precision, ScenarioKind, Setup, System, SystemJob};
use nbody_engine::state::zero_field;

/// Enough particles that every per-particle pass forks (above `par::MIN_FORK_ELEMENTS`).
const N: usize = 20_000;

fn setup(scenario: ScenarioKind, precision: Precision) -> Setup {
    let mut s = Setup::new(scenario);
    // The melt's lattice holds 4k³ atoms: the largest within N.
    s.n = Some(scenario.count_at_most(N));
    s.precision = Some(precision);
    s.seed = 11;
    s.allow_fewer = true;
    s
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

/// Positions, velocities and ids (as bits) after `steps` steps of `kernel` on `threads`, and
/// the rebuilds of its list.
struct Trajectory {
    kernel: KernelKind,
    threads: usize,
    steps: u64,
}

impl SystemJob for Trajectory {
    type Output = (Vec<u64>, u64);
    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        sys: System<T, L, D>,
    ) -> (Vec<u64>, u64) {
        let kernel = sys.kernel(self.kernel, &KernelParams::default()).unwrap();
        pool(self.threads).install(|| {
            let mut sim = Simulation::new(sys, kernel);
            for _ in 0..self.steps {
                sim.step().unwrap();
            }
            let s = &sim.state;
            let mut bits: Vec<u64> = s.id.iter().map(|&i| i as u64).collect();
            for d in 0..D {
                bits.extend(
                    s.pos[d]
                        .iter()
                        .chain(&s.vel[d])
                        .map(|x| x.as_f64().to_bits()),
                );
            }
            (bits, sim.work.rebuilds)
        })
    }
}

#[test]
fn a_cell_list_run_is_bitwise_the_same_at_any_thread_count() {
    // Walls and the field (lj-box), walls alone (lj-liquid), periodic boxes (lj-gas, lj-melt).
    for (scenario, precision) in [
        (ScenarioKind::LjBox, Precision::F32),
        (ScenarioKind::LjLiquid, Precision::F64),
        (ScenarioKind::LjGas, Precision::F32),
        (ScenarioKind::LjMelt, Precision::F64),
    ] {
        let run = |threads| {
            setup(scenario, precision)
                .dispatch(Trajectory {
                    kernel: KernelKind::CellList,
                    threads,
                    steps: 25,
                })
                .unwrap()
        };
        let one = run(1);
        for threads in [2, 3] {
            assert!(
                run(threads) == one,
                "{scenario:?}: the state after 25 steps differs at {threads} threads"
            );
        }
    }
}

#[test]
fn a_list_run_is_bitwise_the_same_on_one_two_and_three_workers() {
    let cases = [
        (KernelKind::Verlet, ScenarioKind::LjBox),
        (KernelKind::Verlet, ScenarioKind::LjLiquid),
        // The periodic melt: slots wrapped across the faces between rebuilds, a list whose
        // first part reaches across them into the last.
        (KernelKind::Verlet, ScenarioKind::LjMelt),
        (KernelKind::Verlet, ScenarioKind::LjGas),
        (KernelKind::ClusterPair, ScenarioKind::LjBox),
        (KernelKind::ClusterPair, ScenarioKind::LjLiquid),
        (KernelKind::ClusterPair, ScenarioKind::LjGas),
        (KernelKind::ClusterPair, ScenarioKind::LjMelt),
    ];
    for (kernel, scenario) in cases {
        {
            for precision in [Precision::F32, Precision::F64] {
                let run = |threads| {
                    setup(scenario, precision)
                        .dispatch(Trajectory {
                            kernel,
                            threads,
                            steps: 30,
                        })
                        .unwrap()
                };
                let (one, rebuilds) = run(1);
                // Rebuilds (outside the team region) and kept lists (inside it) both ran.
                assert!(
                    (2..=20).contains(&rebuilds),
                    "{kernel:?} {scenario:?}: {rebuilds} rebuilds in 30 steps"
                );
                for threads in [2, 3] {
                    assert!(
                        run(threads).0 == one,
                        "{kernel:?} {scenario:?} {precision:?}: the state after 30 steps \
                         differs at {threads} workers"
                    );
                }
            }
        }
    }
}

/// The step's error when one particle, in the last worker's block, is thrown through a wall
/// at a speed that takes it past the opposite one.
struct ThrownOut {
    kernel: KernelKind,
    threads: usize,
}

impl SystemJob for ThrownOut {
    type Output = String;
    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        sys: System<T, L, D>,
    ) -> String {
        let kernel = sys.kernel(self.kernel, &KernelParams::default()).unwrap();
        pool(self.threads).install(|| {
            let mut sim = Simulation::new(sys, kernel);
            sim.step().unwrap();
            let last = sim.state.len() - 1;
            sim.state.vel[0][last] = T::of(1e9);
            let id = sim.state.id[last];
            let err = sim.step().expect_err("a particle beyond both walls");
            format!("{id}: {err}")
        })
    }
}

#[test]
fn an_error_in_one_block_ends_the_step_on_every_worker() {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut said = Vec::new();
        for kernel in [KernelKind::Verlet, KernelKind::ClusterPair] {
            for threads in [1, 2, 3] {
                said.push(
                    setup(ScenarioKind::LjLiquid, Precision::F64)
                        .dispatch(ThrownOut { kernel, threads })
                        .unwrap(),
                );
            }
        }
        let _ = tx.send(said);
    });
    let said = rx
        .recv_timeout(std::time::Duration::from_secs(120))
        .expect("the step hung after an error in one block");
    for s in &said {
        let (id, err) = s.split_once(": ").unwrap();
        assert!(
            err.contains("still outside the box") && err.contains(&format!("particle {id} ")),
            "{s}"
        );
    }
}

/// The Verlet list's forces at 1 and 2 threads, on the state of a few steps in (sorted by the
/// kernel, lists rebuilt), against each other and against the cell list's.
struct Forces {
    threads: usize,
}

impl SystemJob for Forces {
    type Output = (f64, f64);
    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        sys: System<T, L, D>,
    ) -> (f64, f64) {
        let params = KernelParams::default();
        let n = sys.state.len();
        let law = sys.law;
        let mut sim = Simulation::new(
            sys,
            KernelKind::Verlet.build::<T, L, D>(law, &params).unwrap(),
        );
        for _ in 0..12 {
            sim.step().unwrap();
        }
        let state = sim.state.clone();
        let mut verlet = KernelKind::Verlet.build::<T, L, D>(law, &params).unwrap();
        let mut cells = KernelKind::CellList.build::<T, L, D>(law, &params).unwrap();
        let (mut a, mut b, mut c) = (zero_field(n), zero_field(n), zero_field(n));
        verlet.compute(&state, &mut a, false);
        pool(self.threads).install(|| {
            // Twice: the second call runs on the kept list.
            verlet.compute(&state, &mut b, false);
            verlet.compute(&state, &mut b, false);
            cells.compute(&state, &mut c, false);
        });
        let (mut worst, mut scale) = (0.0f64, 0.0f64);
        let mut worst_cells = 0.0f64;
        for d in 0..D {
            for i in 0..n {
                let (x, y, z) = (a[d][i].as_f64(), b[d][i].as_f64(), c[d][i].as_f64());
                worst = worst.max((x - y).abs());
                worst_cells = worst_cells.max((y - z).abs());
                scale = scale.max(x.abs());
            }
        }
        (worst / scale, worst_cells / scale)
    }
}

#[test]
fn verlet_forces_agree_to_rounding_where_the_step_forks() {
    for (scenario, precision, tol) in [
        (ScenarioKind::LjBox, Precision::F32, 1e-4),
        (ScenarioKind::LjLiquid, Precision::F32, 1e-4),
        (ScenarioKind::LjLiquid, Precision::F64, 1e-11),
    ] {
        for threads in [2, 3] {
            let (threads_err, cells_err) = setup(scenario, precision)
                .dispatch(Forces { threads })
                .unwrap();
            assert!(
                threads_err <= tol && cells_err <= tol,
                "{scenario:?} {precision:?} p={threads}: 1 vs {threads} threads {threads_err:e}, \
                 against the cell list {cells_err:e}"
            );
        }
    }
}
