//! Velocity Verlet (kick-drift-kick), shared by every scenario:
//! `v += a·dt/2; x += v·dt; (boundary); a = F(x)/m + g; v += a·dt/2`.

use crate::real::Real;
use crate::state::{Field, State};

/// Half kick: `v += (F/m + external)·dt/2`.
pub fn kick<T: Real, const D: usize>(
    state: &mut State<T, D>,
    forces: &Field<T, D>,
    external: [T; D],
    half_dt: T,
) {
    for d in 0..D {
        let (g, f) = (external[d], &forces[d]);
        for ((v, &f), &m) in state.vel[d].iter_mut().zip(f).zip(&state.mass) {
            *v += (f / m + g) * half_dt;
        }
    }
}

/// Drift: `x += v·dt`.
pub fn drift<T: Real, const D: usize>(state: &mut State<T, D>, dt: T) {
    for d in 0..D {
        for (x, &v) in state.pos[d].iter_mut().zip(&state.vel[d]) {
            *x += v * dt;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::zero_field;

    #[test]
    fn free_fall_in_a_constant_field_is_exact() {
        // With constant acceleration velocity Verlet is exact: x = x0 + v0 t + g t²/2.
        let mut s = State::<f64, 2>::new(1);
        s.vel[0][0] = 1.0;
        let f = zero_field::<f64, 2>(1);
        let (g, dt) = ([0.0, -9.81], 0.01);
        for _ in 0..100 {
            kick(&mut s, &f, g, dt / 2.0);
            drift(&mut s, dt);
            kick(&mut s, &f, g, dt / 2.0);
        }
        assert!((s.pos[0][0] - 1.0).abs() < 1e-12);
        assert!((s.pos[1][0] + 0.5 * 9.81).abs() < 1e-10);
        assert!((s.vel[1][0] + 9.81).abs() < 1e-10);
    }
}
