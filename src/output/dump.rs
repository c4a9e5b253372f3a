//! Plain-text dumps for comparing with other codes.
//!
//! State dump (`run --dump-state`), format `nbody-bench state v1`:
//! ```text
//! # nbody-bench state v1
//! # scenario lj-box dim 2 precision f32 n 500 seed 1 steps 100 dt 0.0001
//! # columns: id x y vx vy fx fy
//! 0 0.0123 ...
//! ```
//! One particle per line in id order; numbers in the shortest decimal form that reads back to
//! the same binary value; nothing that depends on the run (no kernel, thread count, timing or
//! date), so dumps of two runs can be compared with `diff`.
//!
//! Force dump (`validate --dump`), format `nbody-bench forces v1`: the same header style, then
//! per particle `id x y [z] fx_ref fy_ref [fz_ref]` followed by the force components of each
//! kernel in the order the `# columns:` line names them. `ref` is the naive sum in f64.

use crate::real::Real;
use crate::state::{Field, State};
use std::fmt::Write as _;

const AXES: [&str; 3] = ["x", "y", "z"];

/// Column names `prefix` + axis (+ suffix) for D components.
fn columns(prefix: &str, suffix: &str, d: usize) -> String {
    AXES[..d]
        .iter()
        .map(|a| format!(" {prefix}{a}{suffix}"))
        .collect()
}

/// The state dump text. `header` is the run description placed on the second line.
pub fn state_dump<T: Real, const D: usize>(
    header: &str,
    state: &State<T, D>,
    forces: &Field<T, D>,
) -> String {
    let mut out = String::with_capacity(state.len() * 16 * (3 * D + 1));
    out.push_str("# nbody-bench state v1\n");
    let _ = writeln!(out, "# {header}");
    let _ = writeln!(
        out,
        "# columns: id{}{}{}",
        columns("", "", D),
        columns("v", "", D),
        columns("f", "", D)
    );
    for (id, slot) in state.slots_by_id().into_iter().enumerate() {
        let _ = write!(out, "{id}");
        for field in [&state.pos, &state.vel, forces] {
            for d in 0..D {
                let _ = write!(out, " {:e}", field[d][slot]);
            }
        }
        out.push('\n');
    }
    out
}

/// The force dump text: positions, the f64 reference and each named kernel's forces, all
/// indexed by slot of `state` (written in id order).
pub fn force_dump<T: Real, const D: usize>(
    header: &str,
    state: &State<T, D>,
    reference: &Field<f64, D>,
    kernels: &[(&str, Field<T, D>)],
) -> String {
    let mut out = String::new();
    out.push_str("# nbody-bench forces v1\n");
    let _ = writeln!(out, "# {header}");
    let _ = write!(
        out,
        "# columns: id{}{}",
        columns("", "", D),
        columns("f", "_ref", D)
    );
    for (name, _) in kernels {
        out.push_str(&columns("f", &format!("_{name}"), D));
    }
    out.push('\n');
    for (id, slot) in state.slots_by_id().into_iter().enumerate() {
        let _ = write!(out, "{id}");
        for d in 0..D {
            let _ = write!(out, " {:e}", state.pos[d][slot]);
        }
        for d in 0..D {
            let _ = write!(out, " {:e}", reference[d][slot]);
        }
        for (_, f) in kernels {
            for d in 0..D {
                let _ = write!(out, " {:e}", f[d][slot]);
            }
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::zero_field;

    #[test]
    fn state_dump_is_in_id_order_and_round_trips() {
        let mut s = State::<f32, 2>::new(2);
        s.pos = [vec![0.1, 0.7], vec![0.2, 0.8]];
        let mut f = zero_field::<f32, 2>(2);
        f[0] = vec![1.5, -3.0];
        s.permute(&[1, 0], &mut [&mut f]);
        let text = state_dump("scenario test", &s, &f);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[2], "# columns: id x y vx vy fx fy");
        assert_eq!(lines[3], "0 1e-1 2e-1 0e0 0e0 1.5e0 0e0");
        let x: f32 = lines[4].split(' ').nth(1).unwrap().parse().unwrap();
        assert_eq!(x, 0.7f32);
    }
}
