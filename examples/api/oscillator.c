/* oscillator.c — the paper's pounding oscillator (Fig. 9: T0 = 3 s, a 4 mm
 * gap, a Tp = 0.3 s sine pulse of 4 m/s^2, eps = 0.6) run with Moreau-Jean
 * and with the exact event-driven reference; prints umax of both and their
 * relative difference.  Exit 0 when they agree to 1 %.
 *
 *   cc oscillator.c $(pkg-config --cflags --libs pound) -lm -o oscillator */
#include <math.h>
#include <stdio.h>

#include <pound/pound.h>

/* Run the case with one method into *res: 0, or 1 after printing why not. */
static int run(const pd_osc *c, pd_method method, pd_osc_result *res)
{
    pd_run_opts opts = pd_run_default_opts(); /* dt and tend derived from the case */
    pd_err err;
    opts.method = method;
    if (pd_osc_run(c, &opts, NULL, NULL, res, &err)) {
        fprintf(stderr, "oscillator: %s: %s\n", pd_method_name(method), err.msg);
        return 1;
    }
    return 0;
}

int main(void)
{
    pd_osc c = pd_osc_default();
    pd_osc_result mj, ref;
    pd_err err;
    c.pulse = PD_PULSE_SINE;
    c.dir = 1;  /* normal: the wall is driven toward the oscillator */
    c.ap = 4.0; /* m/s^2 */
    c.Tp = 0.3; /* s */
    c.eps = 0.6;
    pd_osc_set_T0(&c, 3.0);    /* Pi2 = Tp / T0 (ap and Tp first) */
    pd_osc_set_gap(&c, 0.004); /* Pi3 = gap / Le */
    if (pd_osc_check(&c, &err)) {
        fprintf(stderr, "oscillator: %s\n", err.msg);
        return 1;
    }
    if (run(&c, PD_METHOD_MOREAU, &mj) || run(&c, PD_METHOD_EVENT, &ref))
        return 1;
    double rel = fabs(mj.umax - ref.umax) / ref.umax;
    printf("libpound %s: Pi2 = %g, Pi3 = %g, eps = %g\n", pd_version(), c.Pi2, c.Pi3, c.eps);
    printf("moreau  umax = %.6f m  (%ld steps of %g s, %ld impacts)\n", mj.umax, mj.steps, mj.dt,
           mj.impacts);
    printf("event   umax = %.6f m  (%ld events, %ld impacts)\n", ref.umax, ref.steps, ref.impacts);
    printf("relative difference %.3g\n", rel);
    return ref.umax > 0.0 && rel < 1e-2 ? 0 : 1;
}
