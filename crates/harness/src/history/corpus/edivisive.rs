//! Apache Otava's change-point detection, which the corpus scores the chosen model against.

/// Apache Otava's change-point detection (Fleming et al., ICPE 2023), here on the logarithms:
/// E-divisive means finds the split of a window that maximises the energy statistic q̂; a
/// Student's t-test between the two sides keeps it if p ≤ 10 × `max_pvalue`, and splitting
/// goes on in the pieces; windows of `window` points slide by half a window; then the merge
/// step drops, weakest first, the change points whose t-test between their neighbours' segments
/// fails `max_pvalue`. `min_segment` 1 is Otava's; more keeps q̂ and the merge off shorter
/// segments (Otava issue #150's proposal).
#[derive(Clone, Copy, Debug)]
pub struct EDivisive {
    pub window: usize,
    pub max_pvalue: f64,
    pub min_segment: usize,
}

impl EDivisive {
    /// The change points of `x` (logarithms), ascending.
    pub fn change_points(&self, x: &[f64]) -> Vec<usize> {
        let m = self.min_segment.max(1);
        // Otava's first pass: a p-value ten times as loose (for max_pvalue below 0.05).
        let weak_p = self.max_pvalue * 10.0;
        let step = (self.window / 2).max(1);
        let (mut start, mut found) = (0, Vec::new());
        while start < x.len() {
            let end = (start + self.window).min(x.len());
            let new: Vec<usize> = split(&x[start..end], weak_p, m)
                .into_iter()
                .map(|i| i + start)
                .collect();
            let last = new.last().copied().unwrap_or(0);
            for i in new {
                if !found.contains(&i) {
                    found.push(i);
                }
            }
            start = last.max(start + step);
        }
        found.sort_unstable();
        // The merge step.
        loop {
            let p: Vec<f64> = (0..found.len())
                .map(|i| {
                    let a = if i == 0 { 0 } else { found[i - 1] };
                    let b = found.get(i + 1).copied().unwrap_or(x.len());
                    if found[i] - a < m || b - found[i] < m {
                        1.0
                    } else {
                        t_test(&x[a..found[i]], &x[found[i]..b])
                    }
                })
                .collect();
            let weakest = (0..p.len()).fold(None, |w: Option<usize>, i| match w {
                Some(j) if p[j] >= p[i] => Some(j),
                _ => Some(i),
            });
            match weakest {
                Some(i) if p[i] >= self.max_pvalue => {
                    found.remove(i);
                }
                _ => return found,
            }
        }
    }
}

/// E-divisive within one window `z`: the best split by q̂ over the current pieces, kept while
/// its t-test passes `p`.
fn split(z: &[f64], p: f64, m: usize) -> Vec<usize> {
    let sums = PairSums::new(z);
    let mut cps: Vec<usize> = Vec::new();
    loop {
        let mut bounds = vec![0];
        bounds.extend_from_slice(&cps);
        bounds.push(z.len());
        let mut best: Option<(f64, usize, usize, usize)> = None;
        for w in bounds.windows(2) {
            if let Some((q, tau)) = candidate(&sums, w[0], w[1], m)
                && best.is_none_or(|b| q > b.0)
            {
                best = Some((q, tau, w[0], w[1]));
            }
        }
        match best {
            Some((_, tau, a, b)) if t_test(&z[a..tau], &z[tau..b]) <= p => {
                cps.push(tau);
                cps.sort_unstable();
            }
            _ => return cps,
        }
    }
}

/// Sums of |z_i − z_j| over the pairs i < j of [u, v), for every u ≤ v.
struct PairSums {
    width: usize,
    sums: Vec<f64>,
}

impl PairSums {
    fn new(z: &[f64]) -> Self {
        let width = z.len() + 1;
        let mut sums = vec![0.0; width * width];
        for v in 1..z.len() {
            let mut column = 0.0;
            for u in (0..v).rev() {
                column += (z[u] - z[v]).abs();
                sums[u * width + v + 1] = sums[u * width + v] + column;
            }
        }
        PairSums { width, sums }
    }

    fn get(&self, u: usize, v: usize) -> f64 {
        self.sums[u * self.width + v]
    }
}

/// The split τ of [a, b) maximising q̂ of [a, τ) against [τ, κ) over κ ≤ b (Otava's
/// candidate), each side at least `m` points.
fn candidate(s: &PairSums, a: usize, b: usize, m: usize) -> Option<(f64, usize)> {
    let mut best: Option<(f64, usize)> = None;
    if b < a + 2 * m {
        return None;
    }
    for tau in a + m..=b - m {
        for kappa in tau + m..=b {
            let (n, k, total) = ((tau - a) as f64, (kappa - tau) as f64, (kappa - a) as f64);
            let (left, right) = (s.get(a, tau), s.get(tau, kappa));
            let cross = s.get(a, kappa) - left - right;
            let mut q = 2.0 / total * cross;
            if n > 1.0 {
                q -= 2.0 * k / (total * (n - 1.0)) * left;
            }
            if k > 1.0 {
                q -= 2.0 * n / (total * (k - 1.0)) * right;
            }
            if best.is_none_or(|b| q > b.0) {
                best = Some((q, tau));
            }
        }
    }
    best
}

/// The two-sided p-value of Student's t-test (pooled variance) between `a` and `b`.
pub(super) fn t_test(a: &[f64], b: &[f64]) -> f64 {
    let (na, nb) = (a.len() as f64, b.len() as f64);
    let df = na + nb - 2.0;
    if df <= 0.0 {
        return 1.0;
    }
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
    let (ma, mb) = (mean(a), mean(b));
    let ss = |x: &[f64], m: f64| x.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
    let pooled = (ss(a, ma) + ss(b, mb)) / df;
    let se = (pooled * (1.0 / na + 1.0 / nb)).sqrt();
    if se == 0.0 {
        return if ma == mb { 1.0 } else { 0.0 };
    }
    let t = (ma - mb) / se;
    beta_regularized(df / 2.0, 0.5, df / (df + t * t))
}

/// The regularized incomplete beta function I_x(a, b): the gate's, which its Clopper-Pearson
/// intervals use.
pub(super) fn beta_regularized(a: f64, b: f64, x: f64) -> f64 {
    crate::gate::family::incomplete_beta(x, a, b)
}
