use nbody_bench::kernels::*;
use nbody_bench::physics::*;
use nbody_bench::state::*;
use std::time::Instant;
fn main() {
    for n in [500usize, 2000, 8000] {
        let mut s = State::<f32, 2>::new(n);
        let mut x = 12345u64;
        for i in 0..n {
            for d in 0..2 {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                s.pos[d][i] = (x >> 40) as f32 / (1u64 << 24) as f32;
            }
        }
        let law = LennardJones::<f32>::new(1.0, 0.01, 0.025);
        let mut k = KernelKind::Naive
            .build::<f32, _, 2>(law, &KernelParams::default())
            .unwrap();
        let mut f = zero_field::<f32, 2>(n);
        let reps = (2e9 / (n * n) as f64) as usize + 1;
        k.compute(&s, &mut f, false);
        let t = Instant::now();
        for _ in 0..reps {
            k.compute(&s, &mut f, false);
        }
        let dt = t.elapsed().as_secs_f64() / reps as f64;
        println!("lj f32 n={n} {:.3e} pairs/s", (n * (n - 1)) as f64 / dt);
        let mut s3 = State::<f64, 3>::new(n);
        for i in 0..n {
            for d in 0..3 {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                s3.pos[d][i] = (x >> 40) as f64 / (1u64 << 24) as f64;
            }
        }
        let mut k3 = KernelKind::Naive
            .build::<f64, _, 3>(Gravity::<f64>::new(1.0, 0.01), &KernelParams::default())
            .unwrap();
        let mut f3 = zero_field::<f64, 3>(n);
        let t = Instant::now();
        for _ in 0..reps {
            k3.compute(&s3, &mut f3, false);
        }
        let dt = t.elapsed().as_secs_f64() / reps as f64;
        println!("grav f64 n={n} {:.3e} pairs/s", (n * (n - 1)) as f64 / dt);
        let mut k4 = KernelKind::Naive
            .build::<f64, _, 3>(Coulomb::<f64>::new(1e-3), &KernelParams::default())
            .unwrap();
        let t = Instant::now();
        for _ in 0..reps {
            k4.compute(&s3, &mut f3, false);
        }
        let dt = t.elapsed().as_secs_f64() / reps as f64;
        println!("coul f64 n={n} {:.3e} pairs/s", (n * (n - 1)) as f64 / dt);
    }
}
