//! The step as one region of a worker team, the way an OpenMP parallel region or a GROMACS MD
//! step runs: no fork or join inside, the passes separated by barriers. Each worker owns a
//! contiguous block of particles for the integration, the walls and the displacement test; the
//! kernel's plan ([`TeamPlan`]) says how the pair work is shared.
//!
//! 1. Each worker: half kick and drift of its block, the walls, the displacement test against
//!    the structure. Barrier.
//! 2. If some block failed the walls, or moved too far for the structure, every worker
//!    returns; the step goes on outside the region (the walls' error, or the re-ordering and
//!    rebuild, which the kernel runs on the rayon pool).
//! 3. Each worker: its share of the kernel's preparation. Barrier.
//! 4. The parts of colour 0, each claimed by the next free worker. Barrier. Colour 1. Barrier.
//!    (A list whose colours are not disjoint runs its parts on worker 0, in the same order.)
//! 5. Each worker: its share of the kernel's finish, and the half kick of its block.
//!
//! Every particle's arithmetic is the same in any block, and the kernel adds the pair forces
//! in one order whatever the workers, so a run is bitwise the same on any number of workers.

use super::Simulation;
use crate::boundary::BlockCheck;
use crate::integrator::{kick_block, kick_drift_block};
use crate::kernels::{StateView, TeamPlan};
use crate::par::team::{SharedSlice, Stopped, Team, Worker, shared};
use crate::real::Real;
use crate::state::State;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Instant;

/// Instants of worker 0 at the ends of the region's phases: the drift, the walls, the
/// displacement test (with the wait for the others), the forces, the kick.
#[derive(Clone, Copy)]
struct Marks([Option<Instant>; 5]);

impl<T: Real, const D: usize> Simulation<T, D> {
    /// One step as a team region, if the kernel has a plan for it; `None` leaves the step to
    /// the caller (nothing done).
    pub(super) fn step_on_team(&mut self) -> Option<Result<(), crate::boundary::BoundaryError>> {
        let threads = rayon::current_num_threads().max(1);
        if self.team.as_ref().map(Team::size) != Some(threads) {
            self.team = Team::new(threads).ok();
        }
        let n = self.state.len();
        let half = self.dt * T::of(0.5);
        let t0 = Instant::now();
        let Simulation {
            state,
            forces,
            kernel,
            boundary,
            external,
            dt,
            team,
            ..
        } = self;
        let team = team.as_mut()?;
        let plan = kernel.team_plan(n)?;
        let region = Region {
            plan: &*plan,
            boundary,
            external: *external,
            half,
            dt: *dt,
            n,
            found: Mutex::new(BlockCheck::empty()),
            failed: AtomicBool::new(false),
            due: AtomicBool::new(false),
            claims: [AtomicUsize::new(0), AtomicUsize::new(0)],
            marks: Mutex::new(Marks([None; 5])),
        };
        let State {
            pos,
            vel,
            mass,
            source,
            ..
        } = state;
        let (pos, vel) = (
            SharedSlice::each(pos.each_mut().map(|x| x.as_mut_slice())),
            SharedSlice::each(vel.each_mut().map(|v| v.as_mut_slice())),
        );
        let out = SharedSlice::each(forces.each_mut().map(|f| f.as_mut_slice()));
        let arrays = Arrays {
            pos,
            vel,
            mass,
            source,
            forces: out,
        };
        if let Err(e) = team.run(|w| region.run(w, &arrays).map_err(|Stopped| "stopped".into())) {
            // A panic or a failure in a worker ends the step like a panic on one thread.
            panic!("the step's worker team failed: {e}");
        }
        let work = plan.work();
        let found = region.found.into_inner().unwrap_or_else(|p| p.into_inner());
        let marks = region
            .marks
            .into_inner()
            .unwrap_or_else(|p| p.into_inner())
            .0;
        let due = region.due.into_inner();
        drop(plan);
        let at = |k: usize| marks[k].unwrap_or(t0);
        self.phases.integrate += (at(0) - t0).as_secs_f64();
        self.phases.boundary += (at(1) - at(0)).as_secs_f64();
        self.phases.force_build += (at(2) - at(1)).as_secs_f64();
        let step = self.step + 1;
        self.bounds = match self.boundary.conclude(&self.state, step, found) {
            Ok(b) => b,
            Err(e) => return Some(Err(e)),
        };
        if due {
            self.forces_and_kick();
        } else {
            self.phases.force_interact += (at(3) - at(2)).as_secs_f64();
            self.phases.integrate += (at(4) - at(3)).as_secs_f64();
            self.step += 1;
            self.work += work;
        }
        Some(Ok(()))
    }
}

/// The arrays the workers share.
struct Arrays<'a, T, const D: usize> {
    pos: [SharedSlice<'a, T>; D],
    vel: [SharedSlice<'a, T>; D],
    mass: &'a [T],
    source: &'a [T],
    forces: [SharedSlice<'a, T>; D],
}

/// What the workers of one step share besides the arrays.
struct Region<'a, T: Real, const D: usize> {
    plan: &'a dyn TeamPlan<T, D>,
    boundary: &'a crate::boundary::Boundary<T, D>,
    external: [T; D],
    half: T,
    dt: T,
    n: usize,
    /// What the walls found, joined over the blocks; whether some block failed them.
    found: Mutex<BlockCheck<T, D>>,
    failed: AtomicBool,
    /// Some block moved too far for the kernel's structure.
    due: AtomicBool,
    /// Next part of each colour to claim.
    claims: [AtomicUsize; 2],
    marks: Mutex<Marks>,
}

impl<T: Real, const D: usize> Region<'_, T, D> {
    fn mark(&self, w: &Worker, k: usize) {
        if w.index() == 0 {
            self.marks.lock().unwrap_or_else(|p| p.into_inner()).0[k] = Some(Instant::now());
        }
    }

    fn run(&self, w: &Worker, a: &Arrays<'_, T, D>) -> Result<(), Stopped> {
        let block = w.block(self.n);
        let mass = &a.mass[block.clone()];
        {
            // SAFETY: the workers' blocks are disjoint, and no one reads another's block of
            // positions, velocities or forces before the next barrier.
            let (x, v, f) = unsafe {
                (
                    shared::ranges_mut(&a.pos, block.clone()),
                    shared::ranges_mut(&a.vel, block.clone()),
                    shared::ranges_mut(&a.forces, block.clone()),
                )
            };
            let f = f.map(|f| &*f);
            kick_drift_block(x, v, f, mass, self.external, self.half, self.dt);
            self.mark(w, 0);
            // SAFETY: as above.
            let (x, v) = unsafe {
                (
                    shared::ranges_mut(&a.pos, block.clone()),
                    shared::ranges_mut(&a.vel, block.clone()),
                )
            };
            let check = self.boundary.apply_block(x, v);
            self.mark(w, 1);
            if check.fails() {
                self.failed.store(true, Ordering::Relaxed);
            }
            {
                let mut found = self.found.lock().unwrap_or_else(|p| p.into_inner());
                *found = BlockCheck::join(*found, check);
            }
            // SAFETY: as above.
            let x = unsafe { shared::ranges_mut(&a.pos, block.clone()) };
            if !self.plan.keeps(x.map(|x| &*x), block.clone()) {
                self.due.store(true, Ordering::Relaxed);
            }
        }
        w.barrier()?;
        self.mark(w, 2);
        if self.failed.load(Ordering::Relaxed) || self.due.load(Ordering::Relaxed) {
            // The rebuild runs on the rayon pool next: the helpers must not spin meanwhile.
            w.rest_after();
            return Ok(());
        }
        // SAFETY: positions and strengths are not written again in this step.
        let view = unsafe {
            StateView {
                pos: shared::wholes(&a.pos),
                source: a.source,
            }
        };
        // SAFETY: every worker prepares once between these barriers.
        unsafe { self.plan.prepare(w, view, &a.forces) };
        w.barrier()?;
        let colors = self.plan.colors();
        if colors.disjoint() {
            for (c, claim) in self.claims.iter().enumerate() {
                loop {
                    let k = claim.fetch_add(1, Ordering::Relaxed);
                    let Some(part) = colors.nth_of_color(c, k) else {
                        break;
                    };
                    // SAFETY: only this colour's parts run until the barrier, each once (the
                    // claim), and they touch disjoint places.
                    unsafe { self.plan.interact(part, view, &a.forces) };
                }
                w.barrier()?;
            }
        } else {
            if w.index() == 0 {
                for part in colors.order() {
                    // SAFETY: one worker runs every part, one at a time.
                    unsafe { self.plan.interact(part, view, &a.forces) };
                }
            }
            w.barrier()?;
        }
        // SAFETY: every part ran before the barrier; each worker finishes once.
        unsafe { self.plan.finish(w, &a.forces) };
        self.mark(w, 3);
        // SAFETY: the worker's own blocks; the forces of its block are final (its finish).
        let (v, f) = unsafe {
            (
                shared::ranges_mut(&a.vel, block.clone()),
                shared::ranges_mut(&a.forces, block),
            )
        };
        kick_block(v, f.map(|f| &*f), mass, self.external, self.half);
        self.mark(w, 4);
        Ok(())
    }
}
