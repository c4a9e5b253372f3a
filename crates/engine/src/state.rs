//! Structure-of-arrays particle state, generic over precision `T` and dimension `D`.
//!
//! Each coordinate lives in its own contiguous `Vec<T>` so that the pair loops read unit-stride
//! streams and vectorize. Particles carry a stable `id`; kernels may ask the engine to reorder the
//! arrays (cell or Morton order) for locality, and output is always written in `id` order.

use crate::geometry::Bounds;
use crate::real::Real;

/// One value per particle for each of the `D` components (x, y[, z]).
pub type Field<T, const D: usize> = [Vec<T>; D];

/// Allocates a zeroed field for `n` particles.
pub fn zero_field<T: Real, const D: usize>(n: usize) -> Field<T, D> {
    std::array::from_fn(|_| vec![T::zero(); n])
}

/// The dynamic state of `n` particles.
#[derive(Clone, Debug)]
pub struct State<T: Real, const D: usize> {
    /// Positions, one array per coordinate, indexed by slot (`id` gives each slot's particle).
    pub pos: Field<T, D>,
    /// Velocities, laid out as `pos`.
    pub vel: Field<T, D>,
    /// Inertial mass (divides the force in the integrator).
    pub mass: Vec<T>,
    /// The law's per-particle source strength: charge for Coulomb, gravitational mass for gravity,
    /// unused (1) for Lennard-Jones.
    pub source: Vec<T>,
    /// Stable particle identity, `0..n` at creation; survives reordering.
    pub id: Vec<u32>,
}

impl<T: Real, const D: usize> State<T, D> {
    /// A state of `n` particles at rest at the origin with unit mass and source.
    pub fn new(n: usize) -> Self {
        State {
            pos: zero_field(n),
            vel: zero_field(n),
            mass: vec![T::one(); n],
            source: vec![T::one(); n],
            id: (0..n as u32).collect(),
        }
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.mass.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.mass.is_empty()
    }

    /// Position of particle `i` as an array.
    #[inline(always)]
    pub fn position(&self, i: usize) -> [T; D] {
        std::array::from_fn(|d| self.pos[d][i])
    }

    /// Keeps the particles whose `keep` entry is true, in order (the rest leave the state,
    /// e.g. for another rank).
    pub fn retain(&mut self, keep: &[bool]) {
        fn keep_in<V: Copy>(v: &mut Vec<V>, keep: &[bool]) {
            let mut k = keep.iter();
            v.retain(|_| *k.next().expect("one flag per particle"));
        }
        assert_eq!(keep.len(), self.len(), "one flag per particle");
        for d in 0..D {
            keep_in(&mut self.pos[d], keep);
            keep_in(&mut self.vel[d], keep);
        }
        keep_in(&mut self.mass, keep);
        keep_in(&mut self.source, keep);
        keep_in(&mut self.id, keep);
    }

    /// Reorders every per-particle array so that new slot `k` holds old particle `order[k]`.
    /// `extra` fields (e.g. the current forces) are permuted the same way.
    pub fn permute(&mut self, order: &[u32], extra: &mut [&mut Field<T, D>]) {
        assert_eq!(order.len(), self.len(), "permutation length must equal n");
        // One scratch array, swapped with each field in turn: the old field becomes the next
        // scratch, so a permutation allocates one array, not one per field.
        // Each gather runs on the pool's threads when the particles are many.
        let mut scratch: Vec<T> = Vec::with_capacity(order.len());
        let mut gather = |v: &mut Vec<T>| {
            crate::par::gather(v, order, &mut scratch);
            std::mem::swap(v, &mut scratch);
        };
        for d in 0..D {
            gather(&mut self.pos[d]);
            gather(&mut self.vel[d]);
            for f in extra.iter_mut() {
                gather(&mut f[d]);
            }
        }
        gather(&mut self.mass);
        gather(&mut self.source);
        let mut id = Vec::with_capacity(order.len());
        crate::par::gather(&self.id, order, &mut id);
        self.id = id;
    }

    /// Slot of each particle id: `slots[id] = index into the arrays`.
    pub fn slots_by_id(&self) -> Vec<usize> {
        let mut slots = vec![0; self.len()];
        for (slot, &id) in self.id.iter().enumerate() {
            slots[id as usize] = slot;
        }
        slots
    }

    /// Converts to another precision (used to compute f64 reference forces).
    pub fn convert<U: Real>(&self) -> State<U, D> {
        let conv = |v: &Vec<T>| v.iter().map(|x| U::of(x.as_f64())).collect::<Vec<U>>();
        State {
            pos: std::array::from_fn(|d| conv(&self.pos[d])),
            vel: std::array::from_fn(|d| conv(&self.vel[d])),
            mass: conv(&self.mass),
            source: conv(&self.source),
            id: self.id.clone(),
        }
    }

    /// Axis-aligned bounding box of all positions (NaN skipped, empty without particles: see
    /// [`crate::geometry`]).
    #[inline(always)]
    pub(crate) fn bounding_box(&self) -> Bounds<T, D> {
        Bounds::of_columns(self.pos.each_ref().map(Vec::as_slice))
    }

    /// Total kinetic energy, accumulated in f64.
    pub(crate) fn kinetic_energy(&self) -> f64 {
        let mut e = 0.0;
        for i in 0..self.len() {
            let v2: f64 = (0..D).map(|d| self.vel[d][i].as_f64().powi(2)).sum();
            e += 0.5 * self.mass[i].as_f64() * v2;
        }
        e
    }

    /// Total momentum, accumulated in f64.
    pub fn momentum(&self) -> [f64; D] {
        std::array::from_fn(|d| {
            (0..self.len())
                .map(|i| self.mass[i].as_f64() * self.vel[d][i].as_f64())
                .sum()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn retain_keeps_particles_together() {
        let mut s = State::<f32, 2>::new(4);
        s.pos[0] = vec![0.0, 1.0, 2.0, 3.0];
        s.vel[1] = vec![5.0, 6.0, 7.0, 8.0];
        s.retain(&[true, false, true, false]);
        assert_eq!(s.id, vec![0, 2]);
        assert_eq!(s.pos[0], vec![0.0, 2.0]);
        assert_eq!(s.vel[1], vec![5.0, 7.0]);
        assert_eq!(s.len(), 2);
    }

    #[test]
    fn permute_keeps_particles_together() {
        let mut s = State::<f64, 2>::new(4);
        for i in 0..4 {
            s.pos[0][i] = i as f64;
            s.vel[1][i] = 10.0 * i as f64;
            s.source[i] = -(i as f64);
        }
        let mut f = zero_field::<f64, 2>(4);
        f[0] = vec![0.5, 1.5, 2.5, 3.5];
        s.permute(&[2, 0, 3, 1], &mut [&mut f]);
        assert_eq!(s.id, vec![2, 0, 3, 1]);
        assert_eq!(s.pos[0], vec![2.0, 0.0, 3.0, 1.0]);
        assert_eq!(s.vel[1], vec![20.0, 0.0, 30.0, 10.0]);
        assert_eq!(s.source, vec![-2.0, -0.0, -3.0, -1.0]);
        assert_eq!(f[0], vec![2.5, 0.5, 3.5, 1.5]);
        assert_eq!(s.slots_by_id(), vec![1, 3, 0, 2]);
    }
}
