//! The Verlet list in a periodic box against the periodic reference (every image summed in
//! f64): particles across every face, edge and corner, a pair at exactly the cutoff through a
//! face, 2-D and 3-D, f64 and f32; the same bits at 1, 2 and 3 threads; slots wrapped by the
//! integrator after the build, which must neither force a rebuild nor meet the wrong image.

use super::*;
use crate::kernels::ForceKernel;
use crate::physics::LennardJones;
use crate::state::zero_field;
use crate::testing::on_threads;
use crate::testing::periodic::{
    SKIN, a_pair_through_the_corner_meets_inside_the_cutoff_only, agrees, law, melt, narrowed,
    slots_wrapped_after_the_build_keep_the_list_and_their_images, square,
};

fn kernel<T: Real, const D: usize>(side: [f64; D]) -> Verlet<LennardJones<T>, T, D> {
    let mut k = Verlet::new(law::<T>(), SKIN).unwrap();
    k.set_periodic([T::zero(); D], side.map(T::of)).unwrap();
    k
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
fn a_pair_at_exactly_the_cutoff_through_a_corner_does_not_interact() {
    a_pair_through_the_corner_meets_inside_the_cutoff_only(|side| Box::new(kernel::<f64, 3>(side)));
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
    slots_wrapped_after_the_build_keep_the_list_and_their_images(|side| {
        Box::new(kernel::<f64, 3>(side))
    });
}

#[test]
fn a_box_with_fewer_than_three_bins_along_a_side_is_refused_with_the_reason() {
    let mut k = Verlet::<_, f64, 3>::new(law::<f64>(), SKIN).unwrap();
    let e = k.set_periodic([0.0; 3], [9.0, 9.0, 8.0]).unwrap_err();
    let message = e.to_string();
    assert!(message.contains("side 2 is 8.000000"), "{message}");
    assert!(message.contains("naive"), "{message}");
}
