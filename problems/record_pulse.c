/* record_pulse.c — a record's fitted pulse as a function of time: the
 * Mavroeidis–Papageorgiou (2003) velocity pulse and its acceleration, and
 * the paper's one-cycle acceleration pulse (docs/records.md). */
#include <math.h>

#include "pd_problems.h"

/* v = vp/2 [1 + cos(2 pi fp s / gamma)] cos(2 pi fp s + nu), s = t - t0,
 * |s| <= gamma / (2 fp); a = dv/dt. */
void pd_record_pulse_eval(const pd_record_pulse *p, double t, double *acc, double *vel)
{
    if (!p || !acc || !vel)
        return;
    double s = t - p->t0, w = PD_TWO_PI * p->fp;
    *acc = *vel = 0.0;
    if (!(p->fp > 0.0) || !(p->gamma > 0.0) || fabs(s) > p->gamma / (2.0 * p->fp))
        return;
    double env = 1.0 + cos(w * s / p->gamma), denv = -(w / p->gamma) * sin(w * s / p->gamma);
    double car = cos(w * s + p->nu), dcar = -w * sin(w * s + p->nu);
    *vel = 0.5 * p->vp * env * car;
    *acc = 0.5 * p->vp * (denv * car + env * dcar);
}

/* ap pd_pulse_shape(shape, polarity, wp (t - t_start)) over one cycle, 0
 * elsewhere: the ground acceleration the one-cycle pulse stands for. */
double pd_record_one_cycle(const pd_record_pulse *p, double t)
{
    if (!p)
        return NAN;
    double x = PD_TWO_PI * (t - p->t_start) / p->Tp;
    if (!(p->Tp > 0.0) || x < 0.0 || x > PD_TWO_PI)
        return 0.0;
    return p->ap * pd_pulse_shape(p->shape, p->polarity, x, 1);
}
