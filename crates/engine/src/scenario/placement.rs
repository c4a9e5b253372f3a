//! O(n) initial placement for the Lennard-Jones boxes.

use rand::Rng;
use thiserror::Error;

/// The box cannot hold the particles asked at minimum spacing σ (random placement gave up).
#[derive(Debug, Error)]
#[error(
    "could place only {placed} of {requested} particles at minimum spacing {min_dist} in a box of side {side:.4}; \
     lower -n or --density, or pass --allow-fewer to run with {placed}"
)]
pub struct PlacementError {
    /// Particles placed before giving up.
    pub placed: usize,
    /// Particles asked.
    pub requested: usize,
    pub(crate) min_dist: f64,
    /// Side of the box.
    pub side: f64,
}

/// Attempts per particle before giving up on random placement.
const ATTEMPTS: usize = 200;

/// Uniform random positions in `[0, side)²`, no two closer than `min_dist` (in a periodic box,
/// through the faces too: between nearest images).
///
/// Rejection sampling against a grid of cells of side ≥ `min_dist` holding the particles placed
/// so far, so each candidate is checked against its 3×3 neighbourhood only: O(n) overall.
pub(crate) fn spaced_uniform(
    n: usize,
    side: f64,
    min_dist: f64,
    allow_fewer: bool,
    periodic: bool,
    rng: &mut impl Rng,
) -> Result<Vec<[f64; 2]>, PlacementError> {
    let cells = ((side / min_dist).floor() as usize).clamp(1, 1 << 15);
    let cell = side / cells as f64;
    // Each cell of side ≥ min_dist holds at most a few particles; keep up to 4 per cell. Only
    // the cells that hold a particle are stored: a dilute gas in a huge box has far more cells
    // than particles (a dense array of them once took gigabytes for 500 particles).
    const SLOTS: usize = 4;
    let mut grid: std::collections::HashMap<(usize, usize), [u32; SLOTS]> =
        std::collections::HashMap::with_capacity(n.min(cells.saturating_mul(cells)));
    let mut pts: Vec<[f64; 2]> = Vec::with_capacity(n);
    let cell_of = |x: f64| ((x / cell) as usize).min(cells - 1);
    let min2 = min_dist * min_dist;
    'particles: while pts.len() < n {
        for _ in 0..ATTEMPTS {
            let p = [rng.random::<f64>() * side, rng.random::<f64>() * side];
            let (cx, cy) = (cell_of(p[0]), cell_of(p[1]));
            let mut ok = true;
            'check: for gy in neighbours(cy, cells, periodic) {
                for gx in neighbours(cx, cells, periodic) {
                    let Some(slots) = grid.get(&(gx, gy)) else {
                        continue;
                    };
                    for &k in slots {
                        if k == u32::MAX {
                            break;
                        }
                        let q = pts[k as usize];
                        let gap = |d: usize| {
                            let g = p[d] - q[d];
                            if periodic {
                                g - side * (g / side).round()
                            } else {
                                g
                            }
                        };
                        if gap(0).powi(2) + gap(1).powi(2) < min2 {
                            ok = false;
                            break 'check;
                        }
                    }
                }
            }
            if !ok {
                continue;
            }
            let slots = grid.entry((cx, cy)).or_insert([u32::MAX; SLOTS]);
            if let Some(slot) = slots.iter_mut().find(|s| **s == u32::MAX) {
                *slot = pts.len() as u32;
                pts.push(p);
                continue 'particles;
            }
        }
        break;
    }
    if pts.len() < n && !allow_fewer {
        return Err(PlacementError {
            placed: pts.len(),
            requested: n,
            min_dist,
            side,
        });
    }
    Ok(pts)
}

/// The cells next to cell `c` of `cells` along an axis, and `c` itself: each once, through the
/// faces when `periodic`.
fn neighbours(c: usize, cells: usize, periodic: bool) -> impl Iterator<Item = usize> {
    let (lo, hi) = if periodic && cells >= 3 {
        (c + cells - 1, c + cells + 1)
    } else if periodic {
        (0, cells - 1)
    } else {
        (c.saturating_sub(1), (c + 1).min(cells - 1))
    };
    (lo..=hi).map(move |k| k % cells)
}

/// `n` positions on a square lattice filling `[0, side)²`, each displaced by up to ±5% of
/// `min_dist`, visited in a seeded random order so that which sites stay empty is random too.
pub(crate) fn jittered_lattice(
    n: usize,
    side: f64,
    min_dist: f64,
    rng: &mut impl Rng,
) -> Vec<[f64; 2]> {
    let per_row = (n as f64).sqrt().ceil() as usize;
    let spacing = side / per_row as f64;
    let jitter = 0.05 * min_dist.min(spacing);
    let mut sites: Vec<usize> = (0..per_row * per_row).collect();
    // Partial Fisher-Yates: the first n entries are a uniform random subset, in random order.
    for k in 0..n {
        let j = rng.random_range(k..sites.len());
        sites.swap(k, j);
    }
    sites[..n]
        .iter()
        .map(|&s| {
            let (ix, iy) = (s % per_row, s / per_row);
            [
                (ix as f64 + 0.5) * spacing + jitter * (2.0 * rng.random::<f64>() - 1.0),
                (iy as f64 + 0.5) * spacing + jitter * (2.0 * rng.random::<f64>() - 1.0),
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    fn min_distance(p: &[[f64; 2]]) -> f64 {
        let mut m = f64::INFINITY;
        for i in 0..p.len() {
            for j in 0..i {
                m = m.min(((p[i][0] - p[j][0]).powi(2) + (p[i][1] - p[j][1]).powi(2)).sqrt());
            }
        }
        m
    }

    #[test]
    fn uniform_placement_respects_spacing_and_box() {
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let p = spaced_uniform(2000, 2.0, 0.01, false, false, &mut rng).unwrap();
        assert_eq!(p.len(), 2000);
        assert!(min_distance(&p) >= 0.01);
        assert!(p.iter().all(|q| q.iter().all(|&x| (0.0..2.0).contains(&x))));
    }

    #[test]
    fn periodic_placement_keeps_the_spacing_through_the_faces() {
        let (side, min) = (1.0, 0.02);
        let nearest = |p: &[[f64; 2]]| {
            let mut m = f64::INFINITY;
            for i in 0..p.len() {
                for j in 0..i {
                    let gap = |d: usize| {
                        let g = p[i][d] - p[j][d];
                        g - side * (g / side).round()
                    };
                    m = m.min((gap(0).powi(2) + gap(1).powi(2)).sqrt());
                }
            }
            m
        };
        // Dense enough that the open placement puts pairs closer than `min` across a face.
        let open = spaced_uniform(
            1000,
            side,
            min,
            false,
            false,
            &mut Pcg64Mcg::seed_from_u64(5),
        );
        assert!(nearest(&open.unwrap()) < min);
        let p = spaced_uniform(
            1000,
            side,
            min,
            false,
            true,
            &mut Pcg64Mcg::seed_from_u64(5),
        );
        assert!(nearest(&p.unwrap()) >= min);
        // Fewer than three cells along a side: each neighbour cell is checked once.
        let p = spaced_uniform(3, 0.05, min, false, true, &mut Pcg64Mcg::seed_from_u64(5));
        assert!(nearest(&p.unwrap()) >= min);
    }

    #[test]
    fn overfull_box_reports_how_many_were_placed() {
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let err = spaced_uniform(20_000, 1.0, 0.01, false, false, &mut rng).unwrap_err();
        assert!(err.placed > 3000 && err.placed < 20_000, "{}", err.placed);
        assert!(err.to_string().contains("--allow-fewer"));
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let p = spaced_uniform(20_000, 1.0, 0.01, true, false, &mut rng).unwrap();
        assert_eq!(p.len(), err.placed);
    }

    #[test]
    fn lattice_keeps_spacing_at_liquid_density() {
        let mut rng = Pcg64Mcg::seed_from_u64(4);
        let n = 1000;
        let side = (n as f64 / 8000.0).sqrt();
        let p = jittered_lattice(n, side, 0.01, &mut rng);
        assert_eq!(p.len(), n);
        assert!(min_distance(&p) > 0.0099, "{}", min_distance(&p));
        assert!(
            p.iter()
                .all(|q| q.iter().all(|&x| (0.0..side).contains(&x)))
        );
    }
}
