//! Fixtures of the periodic lists' tests: the states (a shaken fcc melt, a shaken square
//! lattice, both with sites on every face, edge and corner) and the comparison with the
//! periodic reference, every image summed in f64.

use super::{SEED_1, SEED_2, random_state};
use crate::kernels::ForceKernel;
use crate::physics::LennardJones;
use crate::real::Real;
use crate::state::{Field, State, zero_field};
use crate::validate::periodic::periodic_reference_forces;

/// The melt's cutoff and list skin.
pub(crate) const RC: f64 = 2.5;
pub(crate) const SKIN: f64 = 0.3;

/// The melt's Lennard-Jones law in `T`.
pub(crate) fn law<T: Real>() -> LennardJones<T> {
    LennardJones::new(1.0, 1.0, RC)
}

/// A melt of `cells`³ fcc cells, each atom moved off its site by up to `jitter`, in f64
/// (also the periodic lists' test state).
pub(crate) fn melt(cells: usize, jitter: f64) -> (State<f64, 3>, [f64; 3]) {
    use crate::scenario::melt::{MELT_DENSITY, fcc_lattice};
    let (side, sites) = fcc_lattice(cells, MELT_DENSITY);
    let shake = random_state::<f64, 3>(sites.len(), 1.0, false, SEED_1);
    let mut state = State::<f64, 3>::new(sites.len());
    for (i, p) in sites.iter().enumerate() {
        for d in 0..3 {
            let x = p[d] + jitter * (2.0 * shake.pos[d][i] - 1.0);
            state.pos[d][i] = x.rem_euclid(side);
        }
    }
    (state, [side; 3])
}

/// A jittered square lattice of spacing 1 filling the 2-D box of side 9: sites on every face,
/// edge and corner, shaken across them.
pub(crate) fn square(jitter: f64) -> (State<f64, 2>, [f64; 2]) {
    let side = 9.0;
    let shake = random_state::<f64, 2>(81, 1.0, false, SEED_2);
    let mut state = State::<f64, 2>::new(81);
    for i in 0..81 {
        let site = [(i % 9) as f64, (i / 9) as f64];
        for d in 0..2 {
            let x = site[d] + jitter * (2.0 * shake.pos[d][i] - 1.0);
            state.pos[d][i] = x.rem_euclid(side);
        }
    }
    (state, [side; 2])
}

/// `state` in precision `T`.
pub(crate) fn narrowed<T: Real, const D: usize>(state: &State<f64, D>) -> State<T, D> {
    let mut out = State::<T, D>::new(state.len());
    for d in 0..D {
        out.pos[d] = state.pos[d].iter().map(|&x| T::of(x)).collect();
    }
    out
}

/// Forces of `kernel` (in a periodic box of `side`) on `state` (in `T`) against the reference,
/// within `tol` of each particle's sum of absolute pair forces, and the probed energy within
/// ten times that; the forces.
pub(crate) fn agrees<T: Real, const D: usize>(
    kernel: &mut dyn ForceKernel<T, D>,
    state: &State<f64, D>,
    side: [f64; D],
    tol: f64,
) -> Field<T, D> {
    let (want, energy, abs_sum) = periodic_reference_forces(&law::<f64>(), state, side).unwrap();
    let narrow = narrowed::<T, D>(state);
    let mut f = zero_field::<T, D>(state.len());
    let report = kernel.compute(&narrow, &mut f, true);
    for i in 0..state.len() {
        for d in 0..D {
            let err = (f[d][i].as_f64() - want[d][i]).abs();
            assert!(
                err <= tol * abs_sum[i].max(1e-300),
                "{} D={D} particle {i} axis {d}: {} against {} ({err:e})",
                T::NAME,
                f[d][i],
                want[d][i]
            );
        }
    }
    let e = report.energy.unwrap();
    assert!(
        (e - energy).abs() <= tol * 10.0 * energy.abs().max(1.0),
        "{e} vs {energy}"
    );
    f
}

/// Every slot of `state` moved by up to `step` along a random direction and wrapped into the
/// box as the integrator does; the coordinates that wrapped.
pub(crate) fn shove<const D: usize>(state: &mut State<f64, D>, side: [f64; D], step: f64) -> usize {
    let push = random_state::<f64, D>(state.len(), 1.0, false, SEED_2);
    let mut wrapped = 0;
    for i in 0..state.len() {
        for d in 0..D {
            let x = state.pos[d][i] + step * (2.0 * push.pos[d][i] - 1.0) / (D as f64).sqrt();
            wrapped += usize::from(!(0.0..side[d]).contains(&x));
            state.pos[d][i] = x.rem_euclid(side[d]);
        }
    }
    wrapped
}

/// Two atoms a pair at exactly the cutoff, then just inside it, through the corner image of a
/// cube of side 9 (along the box's diagonal), forces of the kernel `make` builds for that box
/// against the reference: none at the cutoff, equal and opposite inside it.
pub(crate) fn a_pair_through_the_corner_meets_inside_the_cutoff_only(
    make: impl Fn([f64; 3]) -> Box<dyn ForceKernel<f64, 3>>,
) {
    for (gap, meets) in [(RC, false), (RC - 0.1, true)] {
        let side = [9.0; 3];
        let mut state = State::<f64, 3>::new(2);
        let h = gap / 3f64.sqrt();
        for d in 0..3 {
            state.pos[d][0] = 0.25 * h;
            state.pos[d][1] = 9.0 - 0.75 * h;
        }
        let f = agrees(make(side).as_mut(), &state, side, 1e-12);
        assert_eq!(f[0][0] != 0.0, meets, "gap {gap}");
        assert_eq!(f[0][0], -f[0][1]);
    }
}

/// A melt whose atoms all move up to a third of the skin after the build, those leaving the
/// box wrapped as the integrator does: the kernel `make` builds keeps its list (a wrap is not
/// a move) and meets every partner through the right image.
pub(crate) fn slots_wrapped_after_the_build_keep_the_list_and_their_images(
    make: impl Fn([f64; 3]) -> Box<dyn ForceKernel<f64, 3>>,
) {
    let (mut state, side) = melt(6, 0.2);
    let mut k = make(side);
    agrees(k.as_mut(), &state, side, 1e-10);
    let wrapped = shove(&mut state, side, SKIN / 3.0);
    assert!(wrapped > 10, "{wrapped} coordinates wrapped");
    let (want, _, abs_sum) = periodic_reference_forces(&law::<f64>(), &state, side).unwrap();
    let mut f = zero_field::<f64, 3>(state.len());
    let report = k.compute(&state, &mut f, false);
    assert_eq!(report.work.rebuilds, 0, "a wrap is not a move");
    for i in 0..state.len() {
        for d in 0..3 {
            assert!(
                (f[d][i] - want[d][i]).abs() <= 1e-10 * abs_sum[i],
                "particle {i}"
            );
        }
    }
}
