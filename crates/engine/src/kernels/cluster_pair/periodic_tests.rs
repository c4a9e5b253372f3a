//! The cluster list in a periodic box against the periodic reference (every image summed in
//! f64): particles across every face, edge and corner, a pair at exactly the cutoff through a
//! corner, a box only twice the list radius wide (a cluster meets its own images), 2-D and
//! 3-D, f64 and f32; the same bits at 1, 2 and 3 threads, on the team step too; slots wrapped
//! after the build, which must neither force a rebuild nor meet the wrong image.

use super::*;
use crate::physics::LennardJones;
use crate::state::zero_field;
use crate::testing::on_threads;
use crate::testing::periodic::{
    SKIN, a_pair_through_the_corner_meets_inside_the_cutoff_only, agrees, law, melt, narrowed,
    slots_wrapped_after_the_build_keep_the_list_and_their_images, square,
};

fn kernel<T: Real, const D: usize>(side: [f64; D]) -> ClusterPair<LennardJones<T>, T, D> {
    let mut k = ClusterPair::new(law::<T>(), SKIN).unwrap();
    k.set_periodic([T::zero(); D], side.map(T::of)).unwrap();
    k
}

#[test]
fn particles_across_every_face_edge_and_corner_meet_their_nearest_images() {
    let (state, side) = square(0.3);
    agrees(&mut kernel::<f64, 2>(side), &state, side, 1e-10);
    agrees(&mut kernel::<f32, 2>(side), &state, side, 1e-4);
    for cells in [4, 7] {
        let (state, side) = melt(cells, 0.25);
        agrees(&mut kernel::<f64, 3>(side), &state, side, 1e-10);
        agrees(&mut kernel::<f32, 3>(side), &state, side, 1e-4);
    }
}

#[test]
fn a_box_twice_the_list_radius_wide_counts_each_image_once() {
    // Side 5.6 = 2 (rc + skin): few columns, and clusters near their own images.
    let side = [5.6; 3];
    let (mut state, _) = melt(4, 0.2);
    let scale = 5.6 / melt(4, 0.0).1[0];
    for d in 0..3 {
        for x in state.pos[d].iter_mut() {
            *x *= scale;
        }
    }
    let state = {
        // A quarter of the atoms: a density where clusters span much of a column.
        let mut s = State::<f64, 3>::new(state.len() / 4);
        for d in 0..3 {
            s.pos[d] = state.pos[d].iter().step_by(4).copied().collect();
        }
        s
    };
    agrees(&mut kernel::<f64, 3>(side), &state, side, 1e-10);
}

#[test]
fn a_pair_at_exactly_the_cutoff_through_a_corner_does_not_interact() {
    a_pair_through_the_corner_meets_inside_the_cutoff_only(|side| Box::new(kernel::<f64, 3>(side)));
}

#[test]
fn the_forces_are_the_same_bits_at_one_two_and_three_threads() {
    // 16384 atoms: a list of four parts in the cluster order the kernel asks for, whose
    // parts of a colour touch disjoint slots though the first reaches across the faces.
    let (mut state, side) = melt(16, 0.2);
    let order = kernel::<f64, 3>(side).spatial_order(&state).unwrap();
    state.permute(&order, &mut []);
    let narrow = narrowed::<f32, 3>(&state);
    let run = |threads| {
        on_threads(threads, || {
            let mut k = kernel::<f32, 3>(side);
            let mut f = zero_field::<f32, 3>(state.len());
            k.compute(&narrow, &mut f, false);
            assert_eq!(k.parts.len(), 4);
            assert!(k.colors.disjoint(), "the parts' colours overlap");
            assert!(
                k.parts.iter().any(|p| !p.far.is_empty()),
                "no part reaches across the faces apart from its own span"
            );
            f
        })
    };
    let one = run(1);
    for threads in [2, 3] {
        assert!(run(threads) == one, "{threads} threads");
    }
    let probed = agrees(&mut kernel::<f32, 3>(side), &state, side, 1e-4);
    assert!(
        probed == one,
        "the probe and the timed loop add the same terms"
    );
}

#[test]
fn a_slot_wrapped_across_a_face_keeps_the_list_and_meets_the_right_image() {
    slots_wrapped_after_the_build_keep_the_list_and_their_images(|side| {
        Box::new(kernel::<f64, 3>(side))
    });
}

#[test]
fn a_box_narrower_than_twice_the_list_radius_is_refused_with_the_reason() {
    let mut k = ClusterPair::<_, f64, 3>::new(law::<f64>(), SKIN).unwrap();
    let e = k.set_periodic([0.0; 3], [9.0, 5.5, 9.0]).unwrap_err();
    let message = e.to_string();
    assert!(message.contains("side 1 is 5.500000"), "{message}");
    assert!(message.contains("naive"), "{message}");
}
