//! Particles on the wire. Messages are plain bytes: the engine's precision `T` is a type
//! parameter (`f32` or `f64`), and viewing float slices as bytes avoids one MPI datatype per
//! precision and a copy per message.

use crate::real::Real;
use crate::state::State;
use std::any::TypeId;

/// `T` is one of the two plain float types the engine runs in.
fn assert_plain_float<T: Real>() {
    assert!(
        TypeId::of::<T>() == TypeId::of::<f32>() || TypeId::of::<T>() == TypeId::of::<f64>(),
        "wire format defined for f32 and f64 only"
    );
}

/// The bytes of a slice of `f32` or `f64`.
pub fn bytes_of<T: Real>(v: &[T]) -> &[u8] {
    assert_plain_float::<T>();
    // SAFETY: T is f32 or f64 (checked above): no padding, so every byte is initialized, and
    // u8 has alignment 1. The length covers exactly the slice's memory.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

/// The bytes of a mutable slice of `f32` or `f64`.
pub fn bytes_of_mut<T: Real>(v: &mut [T]) -> &mut [u8] {
    assert_plain_float::<T>();
    // SAFETY: as in `bytes_of`; in addition every bit pattern is a valid f32/f64, so any bytes
    // written through the view leave valid floats.
    unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast::<u8>(), std::mem::size_of_val(v)) }
}

/// Floats of a received byte message (copied: a `Vec<u8>` is not aligned for `T`).
pub fn floats_of<T: Real>(bytes: &[u8]) -> Vec<T> {
    let size = std::mem::size_of::<T>();
    let len = bytes.len() / size;
    let mut out = vec![T::zero(); len];
    bytes_of_mut(&mut out).copy_from_slice(&bytes[..len * size]);
    out
}

/// Values per migrating particle: position, velocity, mass, source, id.
pub const fn particle_values(dim: usize) -> usize {
    2 * dim + 3
}

/// Appends particle `i` of `state` as f64 values (exact for f32 and f64, and for ids below 2^53).
pub fn pack_particle<T: Real, const D: usize>(state: &State<T, D>, i: usize, out: &mut Vec<f64>) {
    for d in 0..D {
        out.push(state.pos[d][i].as_f64());
    }
    for d in 0..D {
        out.push(state.vel[d][i].as_f64());
    }
    out.push(state.mass[i].as_f64());
    out.push(state.source[i].as_f64());
    out.push(state.id[i] as f64);
}

/// The id of a record written by [`pack_particle`].
pub fn packed_id<const D: usize>(record: &[f64]) -> f64 {
    record[2 * D + 2]
}

/// Appends the particle of a record written by [`pack_particle`] (its first
/// `particle_values(D)` values; a record may carry more after them) to `state`.
pub fn push_particle<T: Real, const D: usize>(record: &[f64], state: &mut State<T, D>) {
    for d in 0..D {
        state.pos[d].push(T::of(record[d]));
        state.vel[d].push(T::of(record[D + d]));
    }
    state.mass.push(T::of(record[2 * D]));
    state.source.push(T::of(record[2 * D + 1]));
    state.id.push(packed_id::<D>(record) as u32);
}

/// Appends the particles packed by [`pack_particle`] to `state`.
pub fn unpack_particles<T: Real, const D: usize>(bytes: &[u8], state: &mut State<T, D>) {
    let values: Vec<f64> = floats_of(bytes);
    for record in values.chunks_exact(particle_values(D)) {
        push_particle(record, state);
    }
}

/// Appends a source particle to `state`: at rest with unit mass, as the force kernels see
/// ghosts and imported nodes (only position and source enter the forces).
pub fn push_source<T: Real, const D: usize>(
    state: &mut State<T, D>,
    x: [T; D],
    source: T,
    id: u32,
) {
    for d in 0..D {
        state.pos[d].push(x[d]);
        state.vel[d].push(T::zero());
    }
    state.mass.push(T::one());
    state.source.push(source);
    state.id.push(id);
}

/// Appends the point sources of a message (D coordinates and the source each, in `T`) to
/// `state` with [`push_source`] and no id (`u32::MAX`); returns how many.
pub fn unpack_sources<T: Real, const D: usize>(bytes: &[u8], state: &mut State<T, D>) -> usize {
    let values: Vec<T> = floats_of(bytes);
    let records = values.chunks_exact(D + 1);
    let count = records.len();
    for g in records {
        push_source(state, std::array::from_fn(|d| g[d]), g[D], u32::MAX);
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn particles_round_trip_exactly() {
        let mut s = State::<f32, 3>::new(3);
        for i in 0..3 {
            for d in 0..3 {
                s.pos[d][i] = 0.1 + i as f32 / 3.0 + d as f32;
                s.vel[d][i] = -1.0 / (1.0 + i as f32 + d as f32);
            }
            s.source[i] = -(i as f32);
        }
        s.id = vec![7, 16_777_217, 3];
        let mut packed = Vec::new();
        for i in [2, 0, 1] {
            pack_particle(&s, i, &mut packed);
        }
        let mut t = State::<f32, 3>::new(0);
        unpack_particles(bytes_of(&packed), &mut t);
        assert_eq!(t.id, vec![3, 7, 16_777_217]);
        for (k, i) in [2, 0, 1].into_iter().enumerate() {
            assert_eq!(t.position(k), s.position(i));
            assert_eq!(t.vel[1][k], s.vel[1][i]);
            assert_eq!(t.source[k], s.source[i]);
        }
        let v = [1.5f64, -2.0];
        assert_eq!(floats_of::<f64>(bytes_of(&v)), v.to_vec());
    }

    #[test]
    fn sources_arrive_at_rest_with_unit_mass_and_no_id() {
        let sent = [1.0f32, 2.0, -0.5, 3.0, 4.0, 0.25];
        let mut t = State::<f32, 2>::new(1);
        assert_eq!(unpack_sources(bytes_of(&sent), &mut t), 2);
        assert_eq!(t.len(), 3);
        assert_eq!(t.position(1), [1.0, 2.0]);
        assert_eq!(t.position(2), [3.0, 4.0]);
        assert_eq!(t.source[1..], [-0.5, 0.25]);
        assert_eq!(t.mass[1..], [1.0, 1.0]);
        assert_eq!(t.vel[0][1..], [0.0, 0.0]);
        assert_eq!(t.id[1..], [u32::MAX, u32::MAX]);
    }
}
