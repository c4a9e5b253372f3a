/*
 * lj_serial.c: the LJ-box assignment's serial code, written anew for nbody-bench.
 *
 * 2-D Lennard-Jones gas in a box with reflecting walls and downward gravity, float32,
 * velocity Verlet ("leapfrog"). The force loop visits each pair once and applies Newton's third
 * law, n(n-1)/2 pair evaluations per step.
 *
 * What the assignment's serial code got wrong and this one does not (course.h has the code):
 * both velocity components are drawn (it set x twice and never y), with variance T0 (not T0^2),
 * and they are not zeroed before the run (so -T has its effect); the defaults live in one
 * place that the usage text prints (its text said 200 x 100, its defaults were 400 x 50); the
 * monitored energy is shifted at the cutoff like the force is truncated; a particle still
 * outside after one reflection stops the run; frame writes are timed as their own phase.
 *
 * Scenario parameters: nbody-bench's `lj-box` (crates/engine/src/scenario/mod.rs, Setup::lj and
 * ScenarioKind::defaults; placement.rs; physics/lj.rs): epsilon 1, sigma 0.01, force truncated
 * at rc = 2.5 sigma, box [0, L]^2 with L = sqrt(n / 500), reflecting walls, gravity g = 1 along
 * -y, velocity components N(0, T0 = 1), unit mass, dt = 1e-4, float32, positions uniform at least
 * sigma apart. The top of course.h says where each one is defined.
 *
 * Build: cc -O2 -Wall -Wextra lj_serial.c -o lj_serial -lm
 * Run:   ./lj_serial -n 1000 -F 1 -f 100        (100 steps, no output; -h for every option)
 */
#include "course.h"

/* Lennard-Jones forces, each pair once: what i gets from j, j gets with the opposite sign. */
static void compute_forces(const lj_law_t *law, long n, const float *restrict x,
                           float *restrict f)
{
    memset(f, 0, 2 * (size_t)n * sizeof *f);
    for (long i = 0; i < n; ++i) {
        const float xi = x[2 * i], yi = x[2 * i + 1];
        float fxi = 0.0f, fyi = 0.0f; /* kept in registers, stored once per row */
        for (long j = i + 1; j < n; ++j) {
            float dx = x[2 * j] - xi, dy = x[2 * j + 1] - yi;
            float c = lj_coeff(law, dx * dx + dy * dy);
            fxi += c * dx;
            fyi += c * dy;
            f[2 * j] -= c * dx;
            f[2 * j + 1] -= c * dy;
        }
        f[2 * i] += fxi;
        f[2 * i + 1] += fyi;
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

    float *x = malloc(2 * (size_t)n * sizeof *x);
    float *v = malloc(2 * (size_t)n * sizeof *v);
    float *f = malloc(2 * (size_t)n * sizeof *f);
    if (!x || !v || !f) {
        fprintf(stderr, "out of memory for %ld particles\n", n);
        return 2;
    }
    if (lj_init_state(&p, x, v) != 0)
        return 2;
    const double e0 = lj_energy(&p, x, v);
    nbview_t out;
    if (p.out && nbview_open(&out, p.out, n, law.side) != 0)
        return 2;

    /* Set-up, not timed: the forces of the initial positions, for the first half kick. */
    compute_forces(&law, n, x, f);

    phases_t ph = {0};
    double t_start = wall_seconds(), t0, t1;
    if (p.out) {
        t0 = wall_seconds();
        if (nbview_frame(&out, x) != 0)
            goto write_error;
        ph.output += wall_seconds() - t0;
    }
    for (long frame = 0; frame < p.frames; ++frame) {
        for (long s = 0; s < p.steps_per_frame; ++s) {
            t0 = wall_seconds();
            int bad = 0;
            for (long i = 0; i < n; ++i)
                bad |= lj_kick_drift_reflect(&law, x + 2 * i, v + 2 * i, f + 2 * i);
            t1 = wall_seconds();
            ph.integrate += t1 - t0;
            if (bad) {
                fprintf(stderr,
                        "step %lld: a particle is still outside the box after one reflection "
                        "(or not a number); reduce -t\n",
                        (long long)frame * p.steps_per_frame + s + 1);
                return 1;
            }
            compute_forces(&law, n, x, f);
            t0 = wall_seconds();
            ph.force += t0 - t1;
            for (long i = 0; i < n; ++i)
                lj_kick(&law, v + 2 * i, f + 2 * i);
            ph.integrate += wall_seconds() - t0;
        }
        if (p.out) {
            t0 = wall_seconds();
            if (nbview_frame(&out, x) != 0)
                goto write_error;
            ph.output += wall_seconds() - t0;
        }
    }
    if (p.out) {
        t0 = wall_seconds();
        if (nbview_close(&out) != 0)
            goto write_error;
        ph.output += wall_seconds() - t0;
    }
    ph.total = wall_seconds() - t_start;

    const double e1 = lj_energy(&p, x, v);
    print_report("lj_serial", n, steps, 1, 1, &ph, e0, e1);
    fprintf(stderr, "lj_serial: %llu pair evaluations\n",
            (unsigned long long)steps * ((unsigned long long)n * (n - 1) / 2));
    free(x), free(v), free(f);
    return isfinite(e1) ? 0 : 1;

write_error:
    fprintf(stderr, "error writing %s: %s\n", p.out, strerror(errno));
    return 2;
}
