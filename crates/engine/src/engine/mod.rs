//! The simulation loop: one kernel, one system, velocity Verlet, phase timers and counters.
//!
//! A step whose kernel keeps a structure between steps (a neighbour list) runs as one region
//! of a worker team ([`team_step`]); any other step, and a step that rebuilds the structure,
//! runs its passes one after another, each on the rayon pool when worth it.

mod team_step;

use crate::boundary::{Boundary, BoundaryError};
use crate::geometry::Bounds;
use crate::integrator::{kick, kick_drift};
use crate::kernels::{ForceKernel, WorkCounters};
use crate::par::team::Team;
use crate::real::Real;
use crate::scenario::System;
use crate::state::{Field, State, zero_field};
use serde::Serialize;
use std::time::Instant;

/// Seconds spent in each phase of the step, summed over steps.
#[derive(Clone, Copy, Debug, Default, Serialize, serde::Deserialize, PartialEq)]
pub struct PhaseTimes {
    /// Force: building cells, trees and sort orders (including the periodic re-ordering).
    pub force_build: f64,
    /// Force: evaluating interactions.
    pub force_interact: f64,
    /// Kicks and drift.
    pub integrate: f64,
    /// Walls or bounding box.
    pub boundary: f64,
    /// Trajectory frames written by the driver.
    pub output: f64,
}

impl PhaseTimes {
    /// Seconds over all phases.
    pub fn total(&self) -> f64 {
        self.force_build + self.force_interact + self.integrate + self.boundary + self.output
    }

    /// Every phase divided by `steps` (at least one): seconds per step.
    pub fn per_step(self, steps: u64) -> PhaseTimes {
        let k = steps.max(1) as f64;
        PhaseTimes {
            force_build: self.force_build / k,
            force_interact: self.force_interact / k,
            integrate: self.integrate / k,
            boundary: self.boundary / k,
            output: self.output / k,
        }
    }
}

/// The time spent between two snapshots of the same running sums.
impl std::ops::Sub for PhaseTimes {
    type Output = PhaseTimes;

    fn sub(self, earlier: PhaseTimes) -> PhaseTimes {
        PhaseTimes {
            force_build: self.force_build - earlier.force_build,
            force_interact: self.force_interact - earlier.force_interact,
            integrate: self.integrate - earlier.integrate,
            boundary: self.boundary - earlier.boundary,
            output: self.output - earlier.output,
        }
    }
}

/// Energies of the current state.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Energy {
    /// Kinetic energy Σ ½ m v².
    pub kinetic: f64,
    /// Pair potential energy, each pair once (Lennard-Jones: shifted to 0 at the cutoff).
    pub potential: f64,
    /// Potential energy in the external field.
    pub external: f64,
}

impl Energy {
    /// Kinetic plus pair potential plus field energy.
    pub fn total(&self) -> f64 {
        self.kinetic + self.potential + self.external
    }

    /// This energy, if its total is a finite number; the one blow-up check of `run`, the
    /// sweep's measurements and the MPI drivers (`step` is the step it was probed after).
    pub fn finite_after(self, step: u64) -> Result<Energy, EnergyBlowUp> {
        if self.total().is_finite() {
            Ok(self)
        } else {
            Err(EnergyBlowUp {
                step,
                energy: self.total(),
            })
        }
    }
}

/// The total energy stopped being a finite number: the time step is too large for the forces.
#[derive(Clone, Copy, Debug, thiserror::Error)]
#[error(
    "energy is not finite after step {step} (E = {energy}); the simulation blew up — reduce --dt"
)]
pub struct EnergyBlowUp {
    /// The step the energy was probed after.
    pub step: u64,
    /// The non-finite total (NaN or ±infinity).
    pub energy: f64,
}

/// A system being integrated with one kernel.
pub struct Simulation<T: Real, const D: usize> {
    /// The particles, in the slot order the kernel last asked for (`State::id` maps back).
    pub state: State<T, D>,
    /// Force on each particle (in slot order) from the last force computation.
    pub forces: Field<T, D>,
    kernel: Box<dyn ForceKernel<T, D>>,
    boundary: Boundary<T, D>,
    external: [T; D],
    dt: T,
    /// Steps taken so far.
    pub step: u64,
    /// Seconds per phase, summed over the steps taken.
    pub phases: PhaseTimes,
    /// Work summed over the steps taken (probe computations excluded).
    pub work: WorkCounters,
    /// Bounding box after the last boundary phase.
    pub bounds: Bounds<T, D>,
    /// Energy and work of the last probe.
    last_probe: (f64, WorkCounters),
    /// The workers of the team steps, as many as the rayon pool the steps run in (made at the
    /// first team step; `None` before, or when its threads could not be started).
    team: Option<Team>,
}

impl<T: Real, const D: usize> Simulation<T, D> {
    /// Prepares the run: spatial order for the kernel, initial forces (untimed).
    pub fn new<L>(system: System<T, L, D>, kernel: Box<dyn ForceKernel<T, D>>) -> Self {
        let n = system.state.len();
        let bounds = system.state.bounding_box();
        let mut sim = Simulation {
            state: system.state,
            forces: zero_field(n),
            kernel,
            boundary: system.boundary,
            external: system.external,
            dt: system.dt,
            step: 0,
            phases: PhaseTimes::default(),
            work: WorkCounters::default(),
            bounds,
            last_probe: (0.0, WorkCounters::default()),
            team: None,
        };
        if let Some(order) = sim.kernel.spatial_order(&sim.state) {
            sim.state.permute(&order, &mut [&mut sim.forces]);
        }
        sim.probe();
        sim
    }

    /// Recomputes the forces with energy accounting (outside the timed steps) and returns the
    /// energies. The forces are the same as the timed path's.
    pub fn probe(&mut self) -> Energy {
        let report = self.kernel.compute(&self.state, &mut self.forces, true);
        let potential = report.energy.unwrap_or(f64::NAN);
        self.last_probe = (potential, report.work);
        self.energy_with(potential)
    }

    /// Work counters of the last probe (including interacting pairs).
    pub fn probe_work(&self) -> WorkCounters {
        self.last_probe.1
    }

    fn energy_with(&self, potential: f64) -> Energy {
        let s = &self.state;
        let mut external = 0.0;
        for d in 0..D {
            let g = self.external[d].as_f64();
            if g != 0.0 {
                external -= g * s.pos[d]
                    .iter()
                    .zip(&s.mass)
                    .map(|(x, m)| x.as_f64() * m.as_f64())
                    .sum::<f64>();
            }
        }
        Energy {
            kinetic: s.kinetic_energy(),
            potential,
            external,
        }
    }

    /// One velocity-Verlet step.
    pub fn step(&mut self) -> Result<(), BoundaryError> {
        if let Some(done) = self.step_on_team() {
            return done;
        }
        let half = self.dt * T::of(0.5);
        let t0 = Instant::now();
        kick_drift(&mut self.state, &self.forces, self.external, half, self.dt);
        let t1 = Instant::now();
        self.bounds = self.boundary.apply(&mut self.state, self.step + 1)?;
        let t2 = Instant::now();
        self.phases.integrate += (t1 - t0).as_secs_f64();
        self.phases.boundary += (t2 - t1).as_secs_f64();
        self.forces_and_kick();
        Ok(())
    }

    /// The rest of a step after the drift and the walls: the re-ordering when the kernel asks
    /// for one, the forces, the second half kick.
    fn forces_and_kick(&mut self) {
        let half = self.dt * T::of(0.5);
        let t2 = Instant::now();
        let mut reorder_s = 0.0;
        if (self.step + 1).is_multiple_of(self.kernel.sort_every()) {
            if let Some(order) = self.kernel.spatial_order(&self.state) {
                self.state.permute(&order, &mut [&mut self.forces]);
            }
            reorder_s = t2.elapsed().as_secs_f64();
        }
        let t3 = Instant::now();
        let report = self.kernel.compute(&self.state, &mut self.forces, false);
        let t4 = Instant::now();
        kick(&mut self.state, &self.forces, self.external, half);
        let t5 = Instant::now();
        self.step += 1;
        self.work += report.work;
        let force = (t4 - t3).as_secs_f64();
        self.phases.integrate += (t5 - t4).as_secs_f64();
        self.phases.force_build += reorder_s + report.build_s;
        self.phases.force_interact += (force - report.build_s).max(0.0);
    }
}
