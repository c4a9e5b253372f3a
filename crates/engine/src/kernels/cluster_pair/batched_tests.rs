//! The batched loop of every instruction set this machine has against the portable loop, part
//! by part, on the lists of a melt in an open and in a periodic box, f32 and f64: the same
//! forces to within rounding.

use super::tile::run_forces;
use super::*;
use crate::kernels::lanes::{Isa, isas_here};
use crate::physics::LennardJones;
use crate::state::zero_field;
use crate::testing::periodic::{SKIN, law, melt, narrowed};

/// The forces per padded slot of every part of `kernel`'s list: by the batched loop of `isa`
/// (`None` if it has none for `T`), or by the portable loop.
fn slot_forces<T: Real>(
    kernel: &ClusterPair<LennardJones<T>, T, 3>,
    isa: Option<Isa>,
) -> Option<[Vec<T>; 3]> {
    let slots = kernel.layout.clusters() * CLUSTER;
    let mut force: [Vec<T>; 3] = std::array::from_fn(|_| vec![T::zero(); slots]);
    let mut out = Out::whole(force.each_mut().map(|f| f.as_mut_slice()));
    let clusters = Clusters::of(&kernel.layout);
    let images = kernel.periodic.as_ref();
    let terms = kernel.law.lennard_jones().expect("the law is LJ");
    for part in &kernel.parts {
        match isa {
            // SAFETY: `isas_here` lists only instruction sets this CPU has; D is 3.
            Some(isa) => {
                if !unsafe { batched::add_on(isa, &terms, &clusters, part, images, &mut out) } {
                    return None;
                }
            }
            None => {
                run_forces::<T, _, 3, false>(&kernel.law, &clusters, part, images, &mut out);
            }
        }
    }
    Some(force)
}

fn against_portable<T: Real>(periodic: bool, tol: f64) {
    let (state, side) = melt(6, 0.25);
    let state = narrowed::<T, 3>(&state);
    let mut kernel = ClusterPair::new(law::<T>(), SKIN).unwrap();
    if periodic {
        kernel
            .set_periodic([T::zero(); 3], side.map(T::of))
            .unwrap();
    }
    let mut f = zero_field::<T, 3>(state.len());
    kernel.compute(&state, &mut f, false);
    let want = slot_forces(&kernel, None).expect("the portable loop runs everywhere");
    let scale = want
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.as_f64().abs()));
    assert!(scale > 0.0);
    for isa in isas_here() {
        let Some(got) = slot_forces(&kernel, Some(isa)) else {
            assert!(
                T::NAME == "f64" && isa == Isa::Avx2,
                "{isa:?} has a {} loop",
                T::NAME
            );
            continue;
        };
        for d in 0..3 {
            for (s, (a, b)) in got[d].iter().zip(&want[d]).enumerate() {
                let err = (a.as_f64() - b.as_f64()).abs() / scale;
                assert!(
                    err <= tol,
                    "{isa:?} {} slot {s} axis {d}: {a} vs {b}",
                    T::NAME
                );
            }
        }
    }
}

#[test]
fn the_batched_loop_agrees_with_the_portable_one_in_an_open_box() {
    against_portable::<f32>(false, 1e-5);
    against_portable::<f64>(false, 1e-13);
}

#[test]
fn the_batched_loop_agrees_with_the_portable_one_through_images() {
    against_portable::<f32>(true, 1e-5);
    against_portable::<f64>(true, 1e-13);
}
