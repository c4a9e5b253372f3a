//! The Verlet list in a periodic box against the periodic reference (every image summed in
//! f64): particles across every face, edge and corner, a pair at exactly the cutoff through a
//! face, 2-D and 3-D, f64 and f32; the same bits at 1, 2 and 3 threads; slots wrapped by the
//! integrator after the build, which must neither force a rebuild nor meet the wrong image.

use super::*;
use crate::kernels::ForceKernel;
use crate::physics::LennardJones;
use crate::state::zero_field;
use crate::testing::{SEED_2, on_threads, random_state};
use crate::validate::periodic::periodic_reference_forces;
use crate::validate::periodic::tests::melt;

const RC: f64 = 2.5;
const SKIN: f64 = 0.3;

fn law<T: Real>() -> LennardJones<T> {
    LennardJones::new(1.0, 1.0, RC)
}

fn kernel<T: Real, const D: usize>(side: [f64; D]) -> Verlet<LennardJones<T>, T, D> {
    let mut k = Verlet::new(law::<T>(), SKIN).unwrap();
    k.set_periodic([T::zero(); D], side.map(T::of)).unwrap();
    k
}

/// `state` in precision `T`.
fn narrowed<T: Real, const D: usize>(state: &State<f64, D>) -> State<T, D> {
    let mut out = State::<T, D>::new(state.len());
    for d in 0..D {
        out.pos[d] = state.pos[d].iter().map(|&x| T::of(x)).collect();
    }
    out
}

/// Forces of the periodic list on `state` (in `T`) against the reference, within `tol` of
/// each particle's sum of absolute pair forces; the forces.
fn agrees<T: Real, const D: usize>(
    kernel: &mut Verlet<LennardJones<T>, T, D>,
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

/// A jittered square lattice of spacing 1 filling the 2-D box of side 9: sites on every face,
/// edge and corner, shaken across them.
fn square(jitter: f64) -> (State<f64, 2>, [f64; 2]) {
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

#[test]
fn particles_across_every_face_edge_and_corner_meet_their_nearest_images() {
    let (state, side) = square(0.3);
    agrees(&mut kernel::<f64, 2>(side), &state, side, 1e-10);
    agrees(&mut kernel::<f32, 2>(side), &state, side, 1e-4);
    // Six cells: the smallest melt with three bins of rc + skin along a side.
    let (state, side) = melt(6, 0.25);
    agrees(&mut kernel::<f64, 3>(side), &state, side, 1e-10);
    agrees(&mut kernel::<f32, 3>(side), &state, side, 1e-4);
}

#[test]
fn a_pair_at_exactly_the_cutoff_through_a_face_does_not_interact() {
    for (gap, meets) in [(RC, false), (RC - 0.1, true)] {
        let side = [9.0; 3];
        let mut state = State::<f64, 3>::new(2);
        // Through the corner: the two are `gap` apart along the box's diagonal image.
        let h = gap / 3f64.sqrt();
        for d in 0..3 {
            state.pos[d][0] = 0.25 * h;
            state.pos[d][1] = 9.0 - 0.75 * h;
        }
        let f = agrees(&mut kernel::<f64, 3>(side), &state, side, 1e-12);
        assert_eq!(f[0][0] != 0.0, meets, "gap {gap}");
        assert_eq!(f[0][0], -f[0][1]);
    }
}

#[test]
fn the_forces_are_the_same_bits_at_one_two_and_three_threads() {
    // 4000 atoms: a list of several parts, which the threads share, in the bin order the
    // kernel asks the engine for (whose parts touch disjoint slots per colour).
    let (mut state, side) = melt(10, 0.2);
    let order = kernel::<f64, 3>(side).spatial_order(&state).unwrap();
    state.permute(&order, &mut []);
    let narrow = narrowed::<f32, 3>(&state);
    let run = |threads| {
        on_threads(threads, || {
            let mut k = kernel::<f32, 3>(side);
            let mut f = zero_field::<f32, 3>(state.len());
            k.compute(&narrow, &mut f, false);
            assert!(k.parts.len() > 1, "{} parts", k.parts.len());
            assert!(k.colors.disjoint(), "the parts' colours overlap");
            let mut targets = zero_field::<f32, 3>(1000);
            let out = targets.each_mut().map(|t| t.as_mut_slice());
            k.compute_targets(&narrow, 1500..2500, out);
            (f, targets)
        })
    };
    let (one, targets) = run(1);
    // The targets' full lists add each force in another order than the half list.
    for d in 0..3 {
        for (t, h) in targets[d].iter().zip(&one[d][1500..2500]) {
            assert!(
                (t - h).abs() <= 1e-4 * (h.abs() + 1.0),
                "the full lists: {t} vs {h}"
            );
        }
    }
    for threads in [2, 3] {
        assert!(
            run(threads) == (one.clone(), targets.clone()),
            "{threads} threads"
        );
    }
    let mut reference = kernel::<f32, 3>(side);
    let probed = agrees(&mut reference, &state, side, 1e-4);
    let close = (0..3).all(|d| (0..state.len()).all(|i| (probed[d][i] - one[d][i]).abs() <= 1e-3));
    assert!(close, "the probe and the timed loop agree");
}

#[test]
fn a_slot_wrapped_across_a_face_keeps_the_list_and_meets_the_right_image() {
    let (mut state, side) = melt(6, 0.2);
    let mut k = kernel::<f64, 3>(side);
    agrees(&mut k, &state, side, 1e-10);
    // Move every atom by up to a third of the skin, and wrap those that leave the box, as
    // the integrator does.
    let shove = random_state::<f64, 3>(state.len(), 1.0, false, SEED_2);
    let mut wrapped = 0;
    for i in 0..state.len() {
        for d in 0..3 {
            let x = state.pos[d][i] + SKIN / 3.0 * (2.0 * shove.pos[d][i] - 1.0) / 3f64.sqrt();
            wrapped += usize::from(!(0.0..side[d]).contains(&x));
            state.pos[d][i] = x.rem_euclid(side[d]);
        }
    }
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

#[test]
fn a_box_with_fewer_than_three_bins_along_a_side_is_refused_with_the_reason() {
    let mut k = Verlet::<_, f64, 3>::new(law::<f64>(), SKIN).unwrap();
    let e = k.set_periodic([0.0; 3], [9.0, 9.0, 8.0]).unwrap_err();
    let message = e.to_string();
    assert!(message.contains("side 2 is 8.000000"), "{message}");
    assert!(message.contains("naive"), "{message}");
}
