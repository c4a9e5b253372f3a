//! Energy conservation of velocity Verlet over a few hundred steps for every scenario, and a
//! two-body circular orbit that stays circular (the fmm's through its expansions).

use nbody_engine::boundary::Boundary;
use nbody_engine::engine::Simulation;
use nbody_engine::kernels::{KernelKind, KernelParams};
use nbody_engine::physics::Gravity;
use nbody_engine::run::{RunJob, RunSpec};
use nbody_engine::scenario::{Precision, ScenarioKind, Setup, System, SystemInfo};
use nbody_engine::state::State;

fn drift(scenario: ScenarioKind, kernel: KernelKind, n: usize, steps: u64, dt: Option<f64>) -> f64 {
    drift_in(scenario, kernel, n, steps, dt, None)
}

fn drift_in(
    scenario: ScenarioKind,
    kernel: KernelKind,
    n: usize,
    steps: u64,
    dt: Option<f64>,
    precision: Option<Precision>,
) -> f64 {
    let mut setup = Setup::new(scenario);
    setup.n = Some(n);
    setup.dt = dt;
    setup.precision = precision;
    let spec = RunSpec {
        kernel,
        params: KernelParams::default(),
        steps,
        threads: 2,
        trajectory: None,
        dump_state: None,
    };
    let clock = nbody_engine::clock::WallClock::new();
    let r = setup.dispatch(RunJob(&spec, &clock)).unwrap().unwrap();
    assert_eq!(r.steps, steps);
    r.energy.rel_drift
}

#[test]
fn energy_drift_is_bounded_for_every_scenario() {
    // (scenario, kernel, n, steps, dt, bound on |ΔE/E|). LJ energies are the shifted potential;
    // the truncated force still jumps at the cutoff, which sets the LJ bounds.
    let cases = [
        (
            ScenarioKind::LjBox,
            KernelKind::CellList,
            500,
            300,
            None,
            2e-3,
        ),
        (ScenarioKind::LjBox, KernelKind::Naive, 500, 300, None, 2e-3),
        (
            ScenarioKind::LjBox,
            KernelKind::Verlet,
            500,
            300,
            None,
            2e-3,
        ),
        (
            ScenarioKind::LjLiquid,
            KernelKind::Verlet,
            2000,
            300,
            None,
            1e-2,
        ),
        (
            ScenarioKind::LjLiquid,
            KernelKind::CellList,
            2000,
            300,
            None,
            1e-2,
        ),
        // The gas in a periodic square: pairs through the faces, slots wrapped by the integrator.
        (
            ScenarioKind::LjGas,
            KernelKind::CellList,
            500,
            300,
            None,
            2e-3,
        ),
        (
            ScenarioKind::LjGas,
            KernelKind::Verlet,
            500,
            300,
            None,
            2e-3,
        ),
        (
            ScenarioKind::LjGas,
            KernelKind::ClusterPair,
            500,
            300,
            None,
            2e-3,
        ),
        (
            ScenarioKind::Galaxy,
            KernelKind::Symmetric,
            1000,
            300,
            None,
            1e-4,
        ),
        (
            ScenarioKind::Galaxy,
            KernelKind::Octree,
            1000,
            300,
            None,
            1e-3,
        ),
        (ScenarioKind::Galaxy, KernelKind::Fmm, 1000, 300, None, 1e-3),
        // At the source's dt = 1e-5 the closest opposite charges collapse within ~100 steps and
        // cross the quench radius, where the zeroed force does not conserve energy; a smaller
        // step keeps the check about the integrator.
        (
            ScenarioKind::Coulomb,
            KernelKind::PerThread,
            1000,
            300,
            Some(1e-6),
            1e-4,
        ),
    ];
    for (scenario, kernel, n, steps, dt, bound) in cases {
        let d = drift(scenario, kernel, n, steps, dt);
        assert!(
            d.abs() < bound,
            "{scenario:?}/{kernel:?}: relative drift {d:e} exceeds {bound:e}"
        );
    }
}

/// The largest relative energy drift of LAMMPS's runs of `n` melt atoms in the committed
/// energy study (configs/melt-energy.toml: 1000 steps of its own, on the state we export).
fn lammps_melt_drift(n: usize) -> f64 {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/results/melt-energy/results.json"
    );
    let text = std::fs::read_to_string(path).expect("the committed melt energy study");
    let results: serde_json::Value = serde_json::from_str(&text).unwrap();
    let drifts: Vec<f64> = results["cases"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["case"]["kernel"] == "lammps" && c["n"] == n)
        .flat_map(|c| c["rounds"].as_array().unwrap())
        .map(|r| {
            r["energy_drift"]
                .as_f64()
                .expect("LAMMPS printed its energy twice")
        })
        .collect();
    assert!(!drifts.is_empty(), "no LAMMPS run of {n} atoms in {path}");
    drifts.iter().fold(0.0, |m: f64, d| m.max(d.abs()))
}

#[test]
fn the_melt_conserves_energy_within_lammps_drift_on_the_same_state() {
    // 1000 steps of in.lj's time step from the 4000 atoms LAMMPS ran, in f64 as it computes.
    let bound = lammps_melt_drift(4000);
    for kernel in [
        KernelKind::Verlet,
        KernelKind::ClusterPair,
        KernelKind::CellList,
    ] {
        let d = drift_in(
            ScenarioKind::LjMelt,
            kernel,
            4000,
            1000,
            None,
            Some(Precision::F64),
        );
        assert!(
            d.abs() <= bound,
            "{kernel:?}: relative drift {d:e} over 1000 steps, LAMMPS's {bound:e}"
        );
    }
}

#[test]
fn two_body_circular_orbit_stays_circular() {
    // Equal masses m at distance 2r orbit their centre at speed v = sqrt(G m / (4 r)).
    let (m, r): (f64, f64) = (1.0, 0.5);
    let v = (m / (4.0 * r)).sqrt();
    let mut state = State::<f64, 3>::new(2);
    state.pos[0] = vec![r, -r];
    state.vel[1] = vec![v, -v];
    state.mass = vec![m, m];
    state.source = vec![m, m];
    let period = 2.0 * std::f64::consts::PI * r / v;
    let steps = 2000;
    let info = SystemInfo {
        scenario: ScenarioKind::Galaxy,
        n: 2,
        n_requested: 2,
        seed: 0,
        dt: period / steps as f64,
        precision: Precision::F64,
        density: None,
        box_side: None,
        initial: None,
    };
    for kernel in [
        KernelKind::Naive,
        KernelKind::Symmetric,
        KernelKind::Octree,
        KernelKind::Fmm,
    ] {
        let system = System {
            state: state.clone(),
            law: Gravity::<f64>::new(1.0, 0.0),
            boundary: Boundary::Open,
            external: [0.0; 3],
            dt: period / steps as f64,
            info: info.clone(),
        };
        // Leaves of one particle for the fmm: at its default leaf size both bodies share a
        // leaf and it is the direct sum; so each body has a cell of its own, whose radius is
        // zero, the two cells interact through their expansions (M2L, L2P) at any θ > 0.
        let params = KernelParams {
            fmm_leaf_size: 1,
            ..KernelParams::default()
        };
        assert!(params.theta > 0.0);
        let k = kernel.build::<f64, _, 3>(system.law, &params).unwrap();
        let mut sim = Simulation::new(system, k);
        let e0 = sim.probe().total();
        for _ in 0..steps {
            sim.step().unwrap();
            let sep: f64 = (0..3)
                .map(|d| (sim.state.pos[d][0] - sim.state.pos[d][1]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!((sep - 2.0 * r).abs() < 1e-4, "{kernel:?}: separation {sep}");
        }
        // After one period the bodies are back where they started.
        let slot = sim.state.slots_by_id();
        assert!(
            (sim.state.pos[0][slot[0]] - r).abs() < 1e-4 && sim.state.pos[1][slot[0]].abs() < 1e-3
        );
        assert!(((sim.probe().total() - e0) / e0).abs() < 1e-8);
        if kernel == KernelKind::Fmm {
            // Every step through the expansions, none through the particle pair.
            assert_eq!(
                sim.work.pair_checks, 0,
                "fmm: the bodies met in the near field"
            );
            assert!(sim.work.nodes_accepted >= steps, "{:?}", sim.work);
        }
    }
}

#[test]
fn run_times_its_steps_with_the_clock_it_is_given() {
    // Every reading of the scripted clock advances 1 ms, and two readings bracket a step: the
    // step percentiles are exactly 1 ms and the run's total is 2 ms per step plus one.
    let mut setup = Setup::new(ScenarioKind::LjBox);
    setup.n = Some(50);
    let spec = RunSpec {
        kernel: KernelKind::Naive,
        params: KernelParams::default(),
        steps: 20,
        threads: 1,
        trajectory: None,
        dump_state: None,
    };
    let clock = nbody_engine::clock::MockClock::new(std::time::Duration::from_millis(1));
    let r = setup.dispatch(RunJob(&spec, &clock)).unwrap().unwrap();
    let p = &r.timing.per_step_ns;
    // The step histogram keeps three significant digits.
    for ns in [p.min, p.p50, p.p99, p.max] {
        assert!((ns as f64 - 1e6).abs() <= 1e3, "{p:?}");
    }
    assert!(
        (r.timing.total_s - 0.041).abs() < 1e-9,
        "{}",
        r.timing.total_s
    );
}
