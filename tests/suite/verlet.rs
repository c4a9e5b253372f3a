//! The Verlet list in runs: at every step of runs of several hundred steps that cross many
//! rebuilds, its forces are the naive kernel's to rounding (the gas with walls and gravity and
//! the liquid with walls, on 1 and 2 threads, the liquid's list split over the threads); a
//! particle that moves exactly half the skin keeps the list and the forces exact.

use nbody_engine::engine::Simulation;
use nbody_engine::kernels::CompiledKernels;
use nbody_engine::kernels::verlet::{parts_for, step_work};
use nbody_engine::kernels::{KernelKind, KernelParams};
use nbody_engine::real::Real;
use nbody_engine::scenario::{ScenarioKind, Setup, System, SystemJob};
use nbody_engine::state::{Field, State, zero_field};
use nbody_engine::validate::{EXACT_ULPS, reference_forces};

/// The largest |F − F_naive| / Σ_j |F_ij| over the particles of `state` (0 for particles
/// without partners, which must then feel nothing).
fn rounding_ratio<T: Real, L: CompiledKernels<T, D>, const D: usize>(
    law: &L,
    state: &State<T, D>,
    forces: &Field<T, D>,
) -> f64 {
    let n = state.len();
    let mut naive = zero_field::<T, D>(n);
    KernelKind::Naive
        .build::<T, L, D>(*law, &KernelParams::default())
        .unwrap()
        .compute(state, &mut naive, false);
    let (_, abs_sum) = reference_forces(&law.widen(), &state.convert::<f64>());
    let mut worst = 0.0f64;
    for i in 0..n {
        let err = (0..D)
            .map(|d| (forces[d][i].as_f64() - naive[d][i].as_f64()).powi(2))
            .sum::<f64>()
            .sqrt();
        if abs_sum[i] > 0.0 {
            worst = worst.max(err / abs_sum[i]);
        } else {
            assert_eq!(err, 0.0, "particle {i} has no partner but feels a force");
        }
    }
    worst
}

/// Steps a system with the Verlet list and checks the forces after every step.
struct EveryStep {
    steps: u64,
    threads: usize,
}

/// Rebuilds and list entries over the run, and the particles.
struct Ran {
    rebuilds: u64,
    entries: u64,
    n: usize,
}

impl SystemJob for EveryStep {
    type Output = Ran;
    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(self, sys: System<T, L, D>) -> Ran {
        let law = sys.law;
        let name = sys.info.scenario.name();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()
            .unwrap();
        pool.install(|| {
            let kernel = KernelKind::Verlet
                .build::<T, L, D>(law, &KernelParams::default())
                .unwrap();
            let mut sim = Simulation::new(sys, kernel);
            let limit = EXACT_ULPS * T::EPSILON_F64;
            for step in 1..=self.steps {
                sim.step().unwrap();
                let ratio = rounding_ratio(&law, &sim.state, &sim.forces);
                assert!(
                    ratio <= limit,
                    "{name} p={}: step {step}: |dF|/sum|F_ij| = {ratio:e}",
                    self.threads
                );
            }
            Ran {
                rebuilds: sim.work.rebuilds,
                entries: sim.work.list_entries,
                n: sim.state.len(),
            }
        })
    }
}

fn run(scenario: ScenarioKind, n: usize, steps: u64, threads: usize) -> Ran {
    let mut setup = Setup::new(scenario);
    setup.n = Some(n);
    let ran = setup.dispatch(EveryStep { steps, threads }).unwrap();
    // Many rebuilds, and lists kept over several steps in between.
    assert!(
        ran.rebuilds >= steps / 10 && ran.rebuilds <= steps / 2,
        "{scenario:?} p={threads}: {} rebuilds in {steps} steps",
        ran.rebuilds
    );
    ran
}

#[test]
fn gas_with_walls_and_gravity_at_every_step() {
    for threads in [1, 2] {
        run(ScenarioKind::LjBox, 1000, 300, threads);
    }
}

#[test]
fn liquid_with_walls_at_every_step_on_one_and_split_over_two_threads() {
    let steps = 300;
    run(ScenarioKind::LjLiquid, 2000, steps, 1);
    let ran = run(ScenarioKind::LjLiquid, 2000, steps, 2);
    // The work estimate cuts this list into parts: the colours ran on two threads.
    let per_step = ran.entries / steps;
    assert!(
        parts_for(ran.n, step_work(ran.n, per_step)) > 1,
        "{per_step} entries"
    );
}

/// Two particles a little more than the cutoff plus half the skin apart, each moved exactly
/// half the skin toward the other in f32: the list is kept, and the pair, now inside the
/// cutoff, is in it.
struct HalfSkin;

impl SystemJob for HalfSkin {
    type Output = ();
    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(self, sys: System<T, L, D>) {
        // A skin of 2^-9 (0.2σ): its half is a power of two, which f32 adds exactly to
        // coordinates in [1, 2).
        let skin = 1.0 / 512.0;
        let params = KernelParams {
            skin,
            ..KernelParams::default()
        };
        let law = sys.law;
        let rc = law.cutoff().unwrap().as_f64();
        let mut kernel = KernelKind::Verlet.build::<T, L, D>(law, &params).unwrap();
        let mut s = sys.state;
        let a = (0..s.len())
            .find(|&i| (1.0..1.2).contains(&s.pos[0][i].as_f64()))
            .expect("a particle in [1, 1.2)");
        let b = (a + 1) % s.len();
        s.pos[0][b] = T::of(s.pos[0][a].as_f64() + rc + 0.75 * skin);
        s.pos[1][b] = s.pos[1][a];
        let mut f = zero_field::<T, D>(s.len());
        assert_eq!(kernel.compute(&s, &mut f, false).work.rebuilds, 1);
        let (xa, xb) = (s.pos[0][a], s.pos[0][b]);
        s.pos[0][a] = T::of(xa.as_f64() + skin / 2.0);
        s.pos[0][b] = T::of(xb.as_f64() - skin / 2.0);
        for (now, then) in [(s.pos[0][a], xa), (s.pos[0][b], xb)] {
            assert_eq!(
                (now.as_f64() - then.as_f64()).abs(),
                skin / 2.0,
                "moved exactly"
            );
        }
        let r = s.pos[0][b] - s.pos[0][a];
        assert!(law.interacts(r * r), "the pair is inside the cutoff now");
        let report = kernel.compute(&s, &mut f, false);
        assert_eq!(report.work.rebuilds, 0, "half the skin keeps the list");
        let ratio = rounding_ratio(&law, &s, &f);
        assert!(ratio <= EXACT_ULPS * T::EPSILON_F64, "{ratio:e}");
        // A little further, and the list is rebuilt.
        s.pos[0][a] = T::of(s.pos[0][a].as_f64() + skin / 64.0);
        assert_eq!(kernel.compute(&s, &mut f, false).work.rebuilds, 1);
        assert!(rounding_ratio(&law, &s, &f) <= EXACT_ULPS * T::EPSILON_F64);
    }
}

#[test]
fn a_particle_moved_exactly_half_the_skin_keeps_the_list_and_the_forces() {
    let mut setup = Setup::new(ScenarioKind::LjBox);
    setup.n = Some(1500);
    setup.dispatch(HalfSkin).unwrap();
}
