//! The periodic reference against a sum over every image, the periodic naive kernel against the
//! reference, and the kernels without a periodic form.

use super::*;
use crate::physics::LennardJones;
use crate::testing::periodic::melt;
use crate::testing::{SEED_1, random_state};

/// The force on each particle summed over every image of every other particle in the
/// 3^D boxes around it: no nearest-image arithmetic at all.
fn all_images<const D: usize>(
    law: &LennardJones<f64>,
    state: &State<f64, D>,
    side: [f64; D],
) -> Field<f64, D> {
    let n = state.len();
    let mut forces = zero_field::<f64, D>(n);
    let shifts: Vec<[f64; D]> = (0..3usize.pow(D as u32))
        .map(|k| std::array::from_fn(|d| ((k / 3usize.pow(d as u32)) % 3) as f64 - 1.0))
        .collect();
    for i in 0..n {
        for j in (0..n).filter(|&j| j != i) {
            for s in &shifts {
                let dx: [f64; D] =
                    std::array::from_fn(|d| state.pos[d][j] + s[d] * side[d] - state.pos[d][i]);
                let f = pair_force(law, dx, 1.0, 1.0);
                for d in 0..D {
                    forces[d][i] += f[d];
                }
            }
        }
    }
    forces
}

fn agrees<const D: usize>(state: &State<f64, D>, side: [f64; D]) {
    let law = LennardJones::new(1.0, 1.0, 2.5);
    let (got, _, abs_sum) = periodic_reference_forces(&law, state, side).unwrap();
    let want = all_images(&law, state, side);
    for i in 0..state.len() {
        for d in 0..D {
            let err = (got[d][i] - want[d][i]).abs();
            assert!(
                err <= 1e-12 * abs_sum[i].max(1.0),
                "particle {i} axis {d}: {err}"
            );
        }
    }
    // Newton's third law through the images: the forces sum to zero.
    for d in 0..D {
        let total: f64 = got[d].iter().sum();
        assert!(total.abs() < 1e-9 * abs_sum.iter().sum::<f64>(), "{total}");
    }
}

#[test]
fn nearest_images_give_the_sum_over_every_image_in_2d_and_3d() {
    let side3 = [6.0, 6.5, 7.0];
    let mut s3 = random_state::<f64, 3>(150, 1.0, false, SEED_1);
    for i in 0..150 {
        for d in 0..3 {
            s3.pos[d][i] *= side3[d];
        }
    }
    agrees(&s3, side3);
    let side2 = [5.5, 8.0];
    let mut s2 = random_state::<f64, 2>(60, 1.0, false, SEED_1);
    for i in 0..60 {
        for d in 0..2 {
            s2.pos[d][i] *= side2[d];
        }
    }
    agrees(&s2, side2);
}

#[test]
fn pairs_across_every_face_edge_and_corner_meet_through_the_boundary() {
    // One particle near the lower corner, one near each face, edge and corner opposite:
    // each pair is 1.1 apart through the boundary and 4.9 or more apart inside the box.
    let side = [6.0; 3];
    let mut pos = vec![[0.3, 0.3, 0.3]];
    for k in 1..27usize {
        let shift: [f64; 3] = std::array::from_fn(|d| ((k / 3usize.pow(d as u32)) % 3) as f64);
        if shift.iter().all(|&s| s != 1.0) {
            pos.push(std::array::from_fn(|d| {
                if shift[d] == 2.0 { 6.0 - 0.8 } else { 0.3 }
            }));
        }
    }
    let mut state = State::<f64, 3>::new(pos.len());
    for (i, p) in pos.iter().enumerate() {
        for d in 0..3 {
            state.pos[d][i] = p[d];
        }
    }
    agrees(&state, side);
    let law = LennardJones::new(1.0, 1.0, 2.5);
    let (f, _, _) = periodic_reference_forces(&law, &state, side).unwrap();
    assert!(
        (0..3).all(|d| f[d][0] != 0.0),
        "the corner particle feels its images"
    );
}

#[test]
fn a_pair_at_exactly_the_cutoff_through_an_image_does_not_interact() {
    let side = [6.0; 3];
    let mut state = State::<f64, 3>::new(2);
    state.pos[0][0] = 0.5;
    state.pos[0][1] = 6.0 - 2.0; // 2.5 from particle 0 through the face at x = 0
    let law = LennardJones::new(1.0, 1.0, 2.5);
    let (f, e, _) = periodic_reference_forces(&law, &state, side).unwrap();
    assert_eq!((f[0][0], e), (0.0, 0.0));
    state.pos[0][1] = 6.0 - 1.9;
    let (f, _, _) = periodic_reference_forces(&law, &state, side).unwrap();
    assert!(f[0][0] != 0.0 && f[0][0] == -f[0][1]);
}

#[test]
fn the_periodic_naive_kernel_gives_the_reference_at_every_thread_count() {
    use crate::kernels::{ForceKernel, Naive};
    use crate::testing::on_threads;
    let law = LennardJones::new(1.0, 1.0, 2.5);
    // 4000 atoms: enough pairs that the kernel forks on two and three threads.
    let (state, side) = melt(10, 0.2);
    let (want, energy, abs_sum) = periodic_reference_forces(&law, &state, side).unwrap();
    let run = |threads, probe| {
        on_threads(threads, || {
            let mut kernel = Naive::new(law);
            ForceKernel::<f64, 3>::set_periodic(&mut kernel, [0.0; 3], side).unwrap();
            let mut f = zero_field::<f64, 3>(state.len());
            let report = kernel.compute(&state, &mut f, probe);
            (f, report)
        })
    };
    let (one, _) = run(1, false);
    for i in 0..state.len() {
        for d in 0..3 {
            let err = (one[d][i] - want[d][i]).abs();
            assert!(err <= 1e-12 * abs_sum[i], "particle {i} axis {d}: {err}");
        }
    }
    for threads in [2, 3] {
        assert_eq!(run(threads, false).0, one, "{threads} threads");
    }
    let (probed, report) = run(1, true);
    assert_eq!(probed, one);
    let e = report.energy.unwrap();
    assert!(
        (e - energy).abs() <= 1e-10 * energy.abs(),
        "{e} vs {energy}"
    );
    // An fcc melt at ρ = 0.8442 has about 4πρ·2.5³/3 ≈ 55 neighbours inside the cutoff.
    let per_atom = 2.0 * report.work.pairs_interacting as f64 / state.len() as f64;
    assert!((45.0..65.0).contains(&per_atom), "{per_atom}");
}

#[test]
fn the_periodic_naive_kernel_in_f32_is_the_reference_to_single_precision() {
    use crate::kernels::{ForceKernel, Naive};
    let wide = LennardJones::new(1.0, 1.0, 2.5);
    let (state, side) = melt(4, 0.2);
    let (want, _, abs_sum) = periodic_reference_forces(&wide, &state, side).unwrap();
    let mut narrow = State::<f32, 3>::new(state.len());
    for d in 0..3 {
        narrow.pos[d] = state.pos[d].iter().map(|&x| x as f32).collect();
    }
    let mut kernel = Naive::new(LennardJones::<f32>::new(1.0, 1.0, 2.5));
    ForceKernel::<f32, 3>::set_periodic(&mut kernel, [0.0; 3], side.map(|s| s as f32)).unwrap();
    let mut f = zero_field::<f32, 3>(state.len());
    kernel.compute(&narrow, &mut f, false);
    for i in 0..state.len() {
        for d in 0..3 {
            let err = (f[d][i] as f64 - want[d][i]).abs();
            assert!(err <= 1e-4 * abs_sum[i], "particle {i} axis {d}: {err}");
        }
    }
}

#[test]
fn a_kernel_without_a_periodic_form_says_so_and_the_list_knows_which() {
    use crate::kernels::{KernelError, KernelKind, KernelParams};
    use crate::physics::PairLaw;
    let law = LennardJones::new(1.0, 1.0, 2.5);
    for kind in KernelKind::ALL
        .into_iter()
        .filter(|k| k.supports(law.kind()))
    {
        let mut kernel = kind
            .build::<f64, _, 2>(law, &KernelParams::default())
            .unwrap();
        let set = kernel.set_periodic([0.0, 0.0], [8.0, 8.0]);
        assert_eq!(set.is_ok(), kind.periodic_form(), "{kind:?}");
        let Err(e) = set else { continue };
        assert!(
            matches!(e, KernelError::NotPeriodic { kernel } if kernel == kind.name()),
            "{e}"
        );
        assert!(e.to_string().contains("naive"), "{e}");
    }
}

#[test]
fn a_box_too_small_for_nearest_images_or_a_law_without_cutoff_is_refused() {
    let law = LennardJones::new(1.0, 1.0, 2.5);
    let state = State::<f64, 3>::new(2);
    assert_eq!(
        periodic_reference_forces(&law, &state, [6.0, 5.0, 6.0]).unwrap_err(),
        PeriodicReferenceError::BoxTooSmall { side: 5.0, rc: 2.5 }
    );
    let gravity = crate::physics::Gravity::new(1.0, 0.01);
    assert_eq!(
        periodic_reference_forces(&gravity, &state, [6.0; 3]).unwrap_err(),
        PeriodicReferenceError::NoCutoff
    );
}

#[test]
fn a_pair_through_a_face_of_a_wide_f32_box_differs_between_kernels_within_the_image_rounding() {
    use crate::kernels::{KernelKind, KernelParams};
    // A pair 0.9σ apart through the face of a box 400σ wide: in f32 the partner's image (near
    // 400) keeps about 3e-5 of a σ; the steep repulsion turns that into a relative force change
    // far above the summation's 1000 ε.
    let (side, lo, hi) = ([400.0f64; 2], [0.0f32; 2], [400.0f32; 2]);
    let law = LennardJones::<f32>::new(1.0, 1.0, 2.5);
    let mut state = State::<f32, 2>::new(2);
    state.pos[0] = vec![0.3137, 399.4137 + 0.0011];
    state.pos[1] = vec![200.125, 200.125];
    let forces = |kind: KernelKind| {
        let mut k = kind
            .build::<f32, _, 2>(law, &KernelParams::default())
            .unwrap();
        k.set_periodic(lo, hi).unwrap();
        let mut f = zero_field::<f32, 2>(2);
        k.compute(&state, &mut f, false);
        f[0][0] as f64
    };
    let naive = forces(KernelKind::Naive);
    let delta = image_rounding_delta(f32::EPSILON as f64, [0.0; 2], [400.0; 2]);
    let wide = state.convert::<f64>();
    let wide_law = LennardJones::<f64>::new(1.0, 1.0, 2.5);
    let allowed = image_rounding(&wide_law, &wide, side, delta);
    let (_, _, abs_sum) = periodic_reference_forces(&wide_law, &wide, side).unwrap();
    assert!(allowed[0] > 1000.0 * f32::EPSILON as f64 * abs_sum[0]);
    assert_eq!(allowed[0], allowed[1]);
    for kind in [
        KernelKind::CellList,
        KernelKind::Verlet,
        KernelKind::ClusterPair,
    ] {
        let got = forces(kind);
        assert!(
            (got - naive).abs() <= 2.0 * allowed[0],
            "{kind:?}: {got} vs naive {naive}, allowed {}",
            2.0 * allowed[0]
        );
    }
    // Beyond the cutoff and the rounding, nothing.
    state.pos[0] = vec![1.0, 396.0];
    let far = image_rounding(&wide_law, &state.convert::<f64>(), side, delta);
    assert_eq!(far, vec![0.0, 0.0]);
}
