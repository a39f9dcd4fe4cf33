/* spectrum.c — a small pounding spectrum in Pi terms swept by the library
 * with a callback per point: Pi1 = umax wp^2 / ap and gamma = umax /
 * umax_free against Pi2 = Tp / T0, for a sine and a cosine pulse at Pi3 =
 * 0.05, eps = 0.6, with the exact event-driven reference.  Prints one row
 * per point.  Exit 0 when every point came, in order, with finite numbers.
 *
 *   cc spectrum.c $(pkg-config --cflags --libs pound) -lm -o spectrum */
#include <math.h>
#include <stdio.h>

#include <pound/pound.h>

/* What the callback checks as it goes. */
typedef struct seen {
    long points; /* so far: the next point is curve * npi2 + j */
    int npi2, bad;
} seen;

/* One point: print its row (return nonzero to stop the sweep). */
static int point(const pd_spec_coords *co, const pd_spec_row *r, void *ctx)
{
    seen *s = ctx;
    if (co->j == 0)
        printf("%-7s %-7s %8s %8s %5s %10s %10s %9s %8s %7s\n", "pulse", "dir", "Pi2", "Pi3", "eps",
               "umax [m]", "free [m]", "Pi1", "gamma", "impacts");
    printf("%-7s %-7s %8.4f %8.4f %5.2f %10.6f %10.6f %9.5f %8.4f %7ld\n",
           pd_pulse_name(r->c.pulse), pd_dir_name(r->c.dir), r->c.Pi2, r->c.Pi3, r->c.eps, r->umax,
           r->umax_free, r->Pi1, r->gamma, r->impacts);
    s->bad |= co->curve * s->npi2 + co->j != s->points || !isfinite(r->Pi1) ||
              !isfinite(r->gamma) || !(r->umax > 0.0);
    s->points++;
    return 0;
}

int main(void)
{
    pd_spectrum sp;
    pd_err err;
    seen s = {0};
    pd_spec_init(&sp); /* one sine pulse, normal, Tp = ap = 1, xi = 0.05 */
    sp.opts.method = PD_METHOD_EVENT;
    sp.npulse = 2;
    sp.pulse[0] = PD_PULSE_SINE;
    sp.pulse[1] = PD_PULSE_COSINE;
    sp.pi2_min = 0.25, sp.pi2_max = 4.0, sp.npi2 = 5; /* log-spaced */
    sp.size[0] = 0.05;                                /* Pi3 */
    sp.eps[0] = 0.6;
    s.npi2 = sp.npi2;
    int rc = pd_spec_sweep(&sp, point, &s, &err);
    if (rc) {
        fprintf(stderr, "spectrum: %s\n", err.msg);
        return 1;
    }
    printf("%ld points (%ld runs with their no-wall twins)\n", s.points, pd_spec_tasks(&sp));
    return !s.bad && s.points == pd_spec_points(&sp) ? 0 : 1;
}
