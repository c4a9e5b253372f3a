//! Plain-text dumps for comparing with other codes.
//!
//! State dump (`run --dump-state`), format `nbody-bench state v2`:
//! ```text
//! # nbody-bench state v2
//! # scenario lj-box dim 2 precision f32 n 500 seed 1 steps 100 dt 0.0001
//! # law lennard-jones epsilon 1 sigma 0.01 rc 0.025 force truncated
//! # columns: id x y vx vy mass strength fx fy
//! 0 0.0123 ...
//! ```
//! The law line and each particle's inertial mass and source strength (charge for Coulomb, mass
//! for gravity) are there so that another code can recompute every force from the dump alone.
//! One particle per line in id order; numbers in the shortest decimal form that reads back to
//! the same binary value; nothing that depends on the run (no kernel, thread count, timing or
//! date), so dumps of two runs can be compared with `diff`.
//!
//! Force dump (`validate --dump`), format `nbody-bench forces v2`: the same header style (with
//! the law line), then per particle `id x y [z] strength fx_ref fy_ref [fz_ref]` followed by the
//! force components of each kernel in the order the `# columns:` line names them. `ref` is the
//! naive sum in f64.

use crate::physics::LawParameters;
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

/// The run description of a state dump's second line: what made the state, nothing that
/// depends on how it was computed.
pub fn run_header<T: Real, const D: usize>(
    info: &crate::scenario::SystemInfo,
    n: usize,
    steps: u64,
) -> String {
    format!(
        "scenario {} dim {D} precision {} n {n} seed {} steps {steps} dt {}",
        info.scenario.name(),
        T::NAME,
        info.seed,
        info.dt
    )
}

/// The state dump text. `header` is the run description placed on the second line, `law` the
/// parameters of the force law on the third.
pub fn state_dump<T: Real, const D: usize>(
    header: &str,
    law: &LawParameters,
    state: &State<T, D>,
    forces: &Field<T, D>,
) -> String {
    let mut out = String::with_capacity(state.len() * 16 * (3 * D + 3));
    out.push_str("# nbody-bench state v2\n");
    let _ = writeln!(out, "# {header}");
    let _ = writeln!(out, "# {law}");
    let _ = writeln!(
        out,
        "# columns: id{}{} mass strength{}",
        columns("", "", D),
        columns("v", "", D),
        columns("f", "", D)
    );
    for (id, slot) in state.slots_by_id().into_iter().enumerate() {
        let _ = write!(out, "{id}");
        for field in [&state.pos, &state.vel] {
            for d in 0..D {
                let _ = write!(out, " {:e}", field[d][slot]);
            }
        }
        let _ = write!(out, " {:e} {:e}", state.mass[slot], state.source[slot]);
        for d in 0..D {
            let _ = write!(out, " {:e}", forces[d][slot]);
        }
        out.push('\n');
    }
    out
}

/// The force dump text: positions, the f64 reference and each named kernel's forces, all
/// indexed by slot of `state` (written in id order).
pub(crate) fn force_dump<T: Real, const D: usize>(
    header: &str,
    law: &LawParameters,
    state: &State<T, D>,
    reference: &Field<f64, D>,
    kernels: &[(&str, Field<T, D>)],
) -> String {
    let mut out = String::new();
    out.push_str("# nbody-bench forces v2\n");
    let _ = writeln!(out, "# {header}");
    let _ = writeln!(out, "# {law}");
    let _ = write!(
        out,
        "# columns: id{} strength{}",
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
        let _ = write!(out, " {:e}", state.source[slot]);
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
        s.source = vec![2.0, -1.0];
        let law = LawParameters::Coulomb { quench: 0.5 };
        let text = state_dump("scenario test", &law, &s, &f);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[2],
            "# law coulomb quench 0.5 force q_i q_j (x_i - x_j) / r^3"
        );
        assert_eq!(lines[3], "# columns: id x y vx vy mass strength fx fy");
        // Slot 1 holds id 0 after the permutation, with its strength.
        assert_eq!(lines[4], "0 1e-1 2e-1 0e0 0e0 1e0 -1e0 1.5e0 0e0");
        let x: f32 = lines[5].split(' ').nth(1).unwrap().parse().unwrap();
        assert_eq!(x, 0.7f32);
    }
}
