//! `mpi-check`: the final state of a distributed run against a serial run of the same system
//! and kernel: the same particles (none lost, none duplicated) at the same positions and
//! velocities to rounding.

use crate::geometry::Bounds;
use crate::real::Real;
use crate::state::State;
use serde::Serialize;

/// How the distributed final state compares with the serial one.
#[derive(Clone, Debug, Serialize)]
pub struct CheckReport {
    /// Particles in the serial run's final state.
    pub n_serial: usize,
    /// Particles in the distributed run's final state, gathered from the ranks.
    pub n_distributed: usize,
    /// Every id `0..n` appears exactly once in the distributed state.
    pub ids_complete: bool,
    /// Σ id over the distributed state, and what it should be (n(n−1)/2).
    pub id_sum: u64,
    /// n(n−1)/2: the sum of the ids when each of `0..n` appears once.
    pub id_sum_expected: u64,
    /// Largest position difference over the box size (the serial state's largest extent), and
    /// largest velocity difference over the largest serial speed component.
    pub position_error: f64,
    /// Largest velocity difference over the largest serial speed component.
    pub velocity_error: f64,
    /// Particles that changed rank, in all and beyond the neighbouring regions.
    pub migrated: u64,
    /// Of those, particles that moved beyond the neighbouring regions in one step.
    pub far_migrated: u64,
    /// Forces and energy, for the decompositions that distribute the tree.
    pub tree: Option<TreeCheck>,
}

/// How a decomposition that distributes the Barnes-Hut tree compares with the serial tree. Its
/// forces differ from the serial tree's within the opening-angle error (other nodes are
/// accepted), so trajectories part at that level, not at rounding: the check holds its forces
/// to the bound `validate` holds the serial tree to, and its energy drift to the serial run's.
#[derive(Clone, Debug, Serialize)]
pub struct TreeCheck {
    /// Median relative force error against the f64 direct sum at the distributed run's final
    /// positions: of its own forces, of the serial octree's there, and `validate`'s bound at
    /// this θ.
    pub force_error: f64,
    /// Median relative force error of the serial octree at the same positions and θ.
    pub serial_force_error: f64,
    /// The bound `validate` holds the serial octree to at this θ.
    pub force_tolerance: f64,
    /// |E_end − E_0| over the start's |kinetic| + |potential| + |external|, of the distributed
    /// and of the serial run ([`relative_drift`]).
    pub energy_drift: f64,
    /// The serial run's energy drift, which the distributed drift is held to (see
    /// [`DRIFT_FACTOR`]).
    pub serial_energy_drift: f64,
}

/// The distributed run's energy drift may be this many times the serial run's... The drift of
/// a tree code is a random walk of its force errors, so a run whose errors sit in other nodes
/// drifts by an amount of the same order, not the same amount (on a 2001-body galaxy over 300
/// steps, 1-4 ranks: 0.97-2.7 times the serial drift).
pub const DRIFT_FACTOR: f64 = 4.0;
/// ...plus this much (about the rounding of an energy summed in f32).
pub const DRIFT_FLOOR: f64 = 1e-5;

impl TreeCheck {
    /// Whether the forces are within the tolerance and the drift within [`DRIFT_FACTOR`] times the
    /// serial drift plus [`DRIFT_FLOOR`].
    pub fn passes(&self) -> bool {
        self.force_error <= self.force_tolerance
            && self.energy_drift <= DRIFT_FACTOR * self.serial_energy_drift + DRIFT_FLOOR
    }
}

/// |e1 − e0| / scale, with `scale` the sum of the magnitudes of the energy's parts at the
/// start (kinetic, potential, external): the total of a plasma of both signs can be near 0,
/// which would make any drift look huge. 0 when nothing changed.
pub fn relative_drift(e0: f64, scale: f64, e1: f64) -> f64 {
    let d = (e1 - e0).abs();
    if d == 0.0 { 0.0 } else { d / scale }
}

impl CheckReport {
    /// Whether the states agree: the same particles, and positions and velocities within
    /// `tolerance` (relative, see the fields) or, for a distributed tree, its [`TreeCheck`].
    pub fn passes(&self, tolerance: f64) -> bool {
        let same_particles = self.n_serial == self.n_distributed
            && self.ids_complete
            && self.id_sum == self.id_sum_expected;
        match &self.tree {
            Some(tree) => same_particles && tree.passes(),
            None => {
                same_particles
                    && self.position_error <= tolerance
                    && self.velocity_error <= tolerance
            }
        }
    }
}

/// Compares `distributed` (in id order, as gathered) with `serial` (any order).
pub fn compare<T: Real, const D: usize>(
    serial: &State<T, D>,
    distributed: &State<T, D>,
    migrated: u64,
    far_migrated: u64,
) -> CheckReport {
    let n = serial.len();
    let mut seen = vec![0u32; n];
    let mut id_sum = 0u64;
    for &id in &distributed.id {
        id_sum += id as u64;
        if let Some(s) = seen.get_mut(id as usize) {
            *s += 1;
        }
    }
    let ids_complete = distributed.len() == n && seen.iter().all(|&s| s == 1);
    let Bounds { lo, hi } = serial.bounding_box();
    let extent = (0..D)
        .map(|d| (hi[d] - lo[d]).as_f64().abs())
        .fold(f64::MIN_POSITIVE, f64::max);
    let speed = serial
        .vel
        .iter()
        .flatten()
        .map(|v| v.as_f64().abs())
        .fold(f64::MIN_POSITIVE, f64::max);
    let (mut dx, mut dv) = (0.0f64, 0.0f64);
    if ids_complete {
        let at = distributed.slots_by_id();
        for i in 0..n {
            let j = at[serial.id[i] as usize];
            for d in 0..D {
                dx = dx.max((serial.pos[d][i].as_f64() - distributed.pos[d][j].as_f64()).abs());
                dv = dv.max((serial.vel[d][i].as_f64() - distributed.vel[d][j].as_f64()).abs());
            }
        }
    } else {
        dx = f64::INFINITY;
        dv = f64::INFINITY;
    }
    CheckReport {
        n_serial: n,
        n_distributed: distributed.len(),
        ids_complete,
        id_sum,
        id_sum_expected: (n as u64) * (n as u64).saturating_sub(1) / 2,
        position_error: dx / extent,
        velocity_error: dv / speed,
        migrated,
        far_migrated,
        tree: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_lost_duplicated_and_moved_particles() {
        let mut serial = State::<f64, 2>::new(4);
        serial.pos = [vec![0.0, 1.0, 2.0, 3.0], vec![0.0, 0.5, 1.0, 1.5]];
        serial.vel = [vec![1.0, -2.0, 0.5, 0.0], vec![0.0; 4]];
        let same = serial.clone();
        let r = compare(&serial, &same, 3, 0);
        assert!(r.passes(0.0), "{r:?}");
        let mut moved = serial.clone();
        moved.pos[1][2] += 0.03;
        let r = compare(&serial, &moved, 0, 0);
        assert!((r.position_error - 0.01).abs() < 1e-12, "{r:?}");
        assert!(r.passes(0.02) && !r.passes(0.005));
        let mut dup = serial.clone();
        dup.id[3] = 2;
        let r = compare(&serial, &dup, 0, 0);
        assert!(!r.ids_complete && !r.passes(1.0));
        let mut lost = State::<f64, 2>::new(3);
        lost.id = vec![0, 1, 3];
        let r = compare(&serial, &lost, 0, 0);
        assert!(!r.passes(1.0) && r.n_distributed == 3);
    }

    #[test]
    fn a_distributed_tree_is_held_to_the_force_bound_and_the_serial_drift() {
        let serial = State::<f64, 2>::new(4);
        let mut moved = serial.clone();
        moved.pos[0][1] += 0.5;
        let tree = TreeCheck {
            force_error: 8e-4,
            serial_force_error: 7e-4,
            force_tolerance: 1e-3,
            energy_drift: 3e-4,
            serial_energy_drift: 2e-4,
        };
        let mut r = compare(&serial, &moved, 0, 0);
        assert!(!r.passes(1e-9));
        r.tree = Some(tree.clone());
        // Positions part at the force-error level: the tree check decides.
        assert!(r.passes(1e-9), "{r:?}");
        r.tree = Some(TreeCheck {
            force_error: 2e-3,
            ..tree.clone()
        });
        assert!(!r.passes(1e-9));
        r.tree = Some(TreeCheck {
            energy_drift: 9e-4,
            ..tree
        });
        assert!(!r.passes(1e-9));
        assert!((relative_drift(-2.0, 4.0, -2.004) - 1e-3).abs() < 1e-12);
        assert_eq!(relative_drift(0.0, 0.0, 0.0), 0.0);
    }
}
