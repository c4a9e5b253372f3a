//! The cell list in a periodic box against the periodic reference (every image summed in f64):
//! particles across every face, edge and corner, a pair at exactly the cutoff through a corner,
//! 2-D and 3-D, f64 and f32; slots wrapped by the integrator; the same bits at 1, 2 and 3
//! threads, and for a range of targets; a box too narrow for one image per pair refused.

use super::*;
use crate::physics::LennardJones;
use crate::state::zero_field;
use crate::testing::on_threads;
use crate::testing::periodic::{
    RC, a_pair_through_the_corner_meets_inside_the_cutoff_only, agrees, law, melt, narrowed,
    slots_wrapped_after_the_build_keep_the_list_and_their_images, square,
};

fn kernel<T: Real, const D: usize>(side: [f64; D]) -> CellList<LennardJones<T>, T, D> {
    let mut k = CellList::new(law::<T>()).unwrap();
    k.set_periodic([T::zero(); D], side.map(T::of)).unwrap();
    k
}

#[test]
fn particles_across_every_face_edge_and_corner_meet_their_nearest_images() {
    let (state, side) = square(0.3);
    agrees(&mut kernel::<f64, 2>(side), &state, side, 1e-10);
    agrees(&mut kernel::<f32, 2>(side), &state, side, 1e-4);
    // Three cells: a side just over twice the cutoff, so most atoms have ghosts, many several.
    for cells in [3, 5] {
        let (state, side) = melt(cells, 0.25);
        agrees(&mut kernel::<f64, 3>(side), &state, side, 1e-10);
        agrees(&mut kernel::<f32, 3>(side), &state, side, 1e-4);
    }
}

#[test]
fn a_pair_at_exactly_the_cutoff_through_a_corner_does_not_interact() {
    a_pair_through_the_corner_meets_inside_the_cutoff_only(|side| Box::new(kernel::<f64, 3>(side)));
}

#[test]
fn slots_wrapped_by_the_integrator_meet_the_right_images() {
    slots_wrapped_after_the_build_keep_the_list_and_their_images(|side| {
        Box::new(kernel::<f64, 3>(side))
    });
}

#[test]
fn the_forces_are_the_same_bits_at_one_two_and_three_threads_and_for_a_range_of_targets() {
    let (state, side) = melt(10, 0.2);
    let narrow = narrowed::<f32, 3>(&state);
    let run = |threads| {
        on_threads(threads, || {
            let mut k = kernel::<f32, 3>(side);
            let mut f = zero_field::<f32, 3>(state.len());
            k.compute(&narrow, &mut f, false);
            let mut targets = zero_field::<f32, 3>(1000);
            let out = targets.each_mut().map(|t| t.as_mut_slice());
            k.compute_targets(&narrow, 1500..2500, out);
            (f, targets)
        })
    };
    let (one, targets) = run(1);
    for d in 0..3 {
        assert!(
            targets[d] == one[d][1500..2500],
            "the targets' forces, axis {d}"
        );
    }
    for threads in [2, 3] {
        assert!(
            run(threads) == (one.clone(), targets.clone()),
            "{threads} threads"
        );
    }
    let probed = agrees(&mut kernel::<f32, 3>(side), &state, side, 1e-4);
    assert!(
        probed == one,
        "the probe and the timed loop add the same terms"
    );
}

#[test]
fn a_side_not_over_twice_the_cutoff_is_refused_with_what_to_change() {
    let mut k = CellList::<_, f64, 3>::new(law::<f64>()).unwrap();
    let e = k
        .set_periodic([0.0; 3], [9.0, 2.0 * RC, 9.0])
        .expect_err("a pair would meet two images");
    assert!(matches!(e, KernelError::PeriodicBoxTooSmall(_)), "{e}");
    assert!(e.to_string().contains("side 1"), "{e}");
    assert!(k.set_periodic([0.0; 3], [9.0, 2.1 * RC, 9.0]).is_ok());
}
