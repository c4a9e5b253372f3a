/*
 * lj_omp.c: the LJ-box assignment's OpenMP code, written anew for nbody-bench.
 *
 * The same system and pair loop as lj_serial.c (each pair once, Newton's third law), with the
 * rows of the triangular loop shared among the threads. Two threads may add to the same
 * particle's force, so each thread accumulates into a buffer of its own; the buffers are then
 * summed, in parallel over particles, into the force array. The kicks, drift and walls are
 * parallel loops over particles.
 *
 * Two defects of the assignment's OpenMP code are not repeated here:
 * - its `schedule(static)` on the triangular loop gives the first thread the longest rows;
 *   here rows are dealt round-robin (schedule(static, 1)), so each thread gets about the same
 *   number of pairs, and the split is the same at every run (a reproducible sum);
 * - its reduction ran under `omp critical`, one thread at a time, so it cost more with more
 *   threads; here each thread sums a slice of the particles over all buffers.
 *
 * Scenario parameters: nbody-bench's `lj-box` (crates/engine/src/scenario/mod.rs, Setup::lj and
 * ScenarioKind::defaults; placement.rs; physics/lj.rs): epsilon 1, sigma 0.01, force truncated
 * at rc = 2.5 sigma, box [0, L]^2 with L = sqrt(n / 500), reflecting walls, gravity g = 1 along
 * -y, velocity components N(0, T0 = 1), unit mass, dt = 1e-4, float32, positions uniform at least
 * sigma apart. The top of course.h says where each one is defined.
 *
 * Build: cc -O2 -Wall -Wextra -fopenmp lj_omp.c -o lj_omp -lm
 * Run:   OMP_NUM_THREADS=2 ./lj_omp -n 1000 -F 1 -f 100
 */
#include "course.h"
#include <omp.h>

/* Per-thread pair forces: thread t adds into buf + t * 2n. Zeroing the buffer is part of the
 * force phase (it is work the per-thread scheme adds); the barrier at the end of the loop is
 * where the time of an unbalanced split would show. */
static void pair_forces(const lj_law_t *law, long n, const float *restrict x, float *buf)
{
#pragma omp parallel
    {
        float *restrict ft = buf + (size_t)omp_get_thread_num() * 2 * (size_t)n;
        memset(ft, 0, 2 * (size_t)n * sizeof *ft);
#pragma omp for schedule(static, 1)
        for (long i = 0; i < n; ++i) {
            const float xi = x[2 * i], yi = x[2 * i + 1];
            float fxi = 0.0f, fyi = 0.0f;
            for (long j = i + 1; j < n; ++j) {
                float dx = x[2 * j] - xi, dy = x[2 * j + 1] - yi;
                float c = lj_coeff(law, dx * dx + dy * dy);
                fxi += c * dx;
                fyi += c * dy;
                ft[2 * j] -= c * dx;
                ft[2 * j + 1] -= c * dy;
            }
            ft[2 * i] += fxi;
            ft[2 * i + 1] += fyi;
        }
    }
}

/* f = sum over threads of the buffers, each thread summing a slice of the 2n values. The order
 * of the sum (thread 0 first) is fixed, so the result does not depend on timing. */
static void reduce_forces(long n, int nthreads, const float *restrict buf, float *restrict f)
{
    const size_t len = 2 * (size_t)n;
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < len; ++k) {
        float s = buf[k];
        for (int t = 1; t < nthreads; ++t)
            s += buf[(size_t)t * len + k];
        f[k] = s;
    }
}

int main(int argc, char **argv)
{
    lj_params_t p;
    int rc = lj_parse(argc, argv, &p, 0);
    if (rc)
        return rc > 0 ? 0 : 2;
    const long n = p.n;
    const long long steps = (long long)p.frames * p.steps_per_frame;
    const lj_law_t law = lj_law(&p);
    /* Every parallel region below runs on this many threads (no dynamic adjustment), so the
     * buffers allocated here are the ones used. */
    omp_set_dynamic(0);
    const int nthreads = omp_get_max_threads();

    float *x = malloc(2 * (size_t)n * sizeof *x);
    float *v = malloc(2 * (size_t)n * sizeof *v);
    float *f = malloc(2 * (size_t)n * sizeof *f);
    float *buf = malloc((size_t)nthreads * 2 * (size_t)n * sizeof *buf);
    if (!x || !v || !f || !buf) {
        fprintf(stderr, "out of memory for %ld particles on %d threads\n", n, nthreads);
        return 2;
    }
    if (lj_init_state(&p, x, v) != 0)
        return 2;
    const double e0 = lj_energy(&p, x, v);
    nbview_t out;
    if (p.out && nbview_open(&out, p.out, n, law.side) != 0)
        return 2;

    /* Set-up, not timed: the forces of the initial positions (also starts the thread pool). */
    pair_forces(&law, n, x, buf);
    reduce_forces(n, nthreads, buf, f);

    phases_t ph = {0};
    double t_start = omp_get_wtime(), t0, t1;
    if (p.out) {
        t0 = omp_get_wtime();
        if (nbview_frame(&out, x) != 0)
            goto write_error;
        ph.output += omp_get_wtime() - t0;
    }
    for (long frame = 0; frame < p.frames; ++frame) {
        for (long s = 0; s < p.steps_per_frame; ++s) {
            t0 = omp_get_wtime();
            int bad = 0;
#pragma omp parallel for schedule(static) reduction(| : bad)
            for (long i = 0; i < n; ++i)
                bad |= lj_kick_drift_reflect(&law, x + 2 * i, v + 2 * i, f + 2 * i);
            t1 = omp_get_wtime();
            ph.integrate += t1 - t0;
            if (bad) {
                fprintf(stderr,
                        "step %lld: a particle is still outside the box after one reflection "
                        "(or not a number); reduce -t\n",
                        (long long)frame * p.steps_per_frame + s + 1);
                return 1;
            }
            pair_forces(&law, n, x, buf);
            t0 = omp_get_wtime();
            ph.force += t0 - t1;
            reduce_forces(n, nthreads, buf, f);
            t1 = omp_get_wtime();
            ph.reduce += t1 - t0;
#pragma omp parallel for schedule(static)
            for (long i = 0; i < n; ++i)
                lj_kick(&law, v + 2 * i, f + 2 * i);
            ph.integrate += omp_get_wtime() - t1;
        }
        if (p.out) {
            t0 = omp_get_wtime();
            if (nbview_frame(&out, x) != 0)
                goto write_error;
            ph.output += omp_get_wtime() - t0;
        }
    }
    if (p.out) {
        t0 = omp_get_wtime();
        if (nbview_close(&out) != 0)
            goto write_error;
        ph.output += omp_get_wtime() - t0;
    }
    ph.total = omp_get_wtime() - t_start;

    const double e1 = lj_energy(&p, x, v);
    print_report("lj_omp", n, steps, nthreads, 1, &ph, e0, e1);
    fprintf(stderr, "lj_omp: %llu pair evaluations\n",
            (unsigned long long)steps * ((unsigned long long)n * (n - 1) / 2));
    free(x), free(v), free(f), free(buf);
    return isfinite(e1) ? 0 : 1;

write_error:
    fprintf(stderr, "error writing %s: %s\n", p.out, strerror(errno));
    return 2;
}
