//! `mpi-check`: the final state of a distributed run against a serial run of the same system
//! and kernel: the same particles (none lost, none duplicated) at the same positions and
//! velocities to rounding.

use crate::real::Real;
use crate::state::State;
use serde::Serialize;

/// How the distributed final state compares with the serial one.
#[derive(Clone, Debug, Serialize)]
pub struct CheckReport {
    pub n_serial: usize,
    pub n_distributed: usize,
    /// Every id `0..n` appears exactly once in the distributed state.
    pub ids_complete: bool,
    /// Σ id over the distributed state, and what it should be (n(n−1)/2).
    pub id_sum: u64,
    pub id_sum_expected: u64,
    /// Largest position difference over the box size (the serial state's largest extent), and
    /// largest velocity difference over the largest serial speed component.
    pub position_error: f64,
    pub velocity_error: f64,
    /// Particles that changed rank, in all and beyond the neighbouring regions.
    pub migrated: u64,
    pub far_migrated: u64,
}

impl CheckReport {
    /// Whether the states agree within `tolerance` (relative, see the fields).
    pub fn passes(&self, tolerance: f64) -> bool {
        self.n_serial == self.n_distributed
            && self.ids_complete
            && self.id_sum == self.id_sum_expected
            && self.position_error <= tolerance
            && self.velocity_error <= tolerance
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
    let (lo, hi) = serial.bounding_box();
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
}
