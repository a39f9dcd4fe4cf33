/* excitation.c — the pulses of SPEC §1 in the paper's units. */
#include <math.h>
#include <string.h>

#include "osc_priv.h"
#include "pd_problems.h"

const char *pd_pulse_name(pd_pulse pulse)
{
    switch (pulse) {
    case PD_PULSE_SINE:
        return "sine";
    case PD_PULSE_COSINE:
        return "cosine";
    case PD_PULSE_HARMONIC:
        return "harmonic";
    }
    return "?";
}

int pd_pulse_parse(const char *name, pd_pulse *pulse)
{
    static const pd_pulse all[] = {PD_PULSE_SINE, PD_PULSE_COSINE, PD_PULSE_HARMONIC};
    if (!name || !pulse)
        return PD_EINVAL;
    for (int i = 0; i < 3; i++)
        if (!strcmp(name, pd_pulse_name(all[i]))) {
            *pulse = all[i];
            return PD_OK;
        }
    return PD_EINVAL;
}

const char *pd_dir_name(int dir)
{
    return dir > 0 ? "normal" : "reverse";
}

int pd_dir_parse(const char *name, int *dir)
{
    if (!name || !dir)
        return PD_EINVAL;
    if (!strcmp(name, "normal"))
        *dir = 1;
    else if (!strcmp(name, "reverse"))
        *dir = -1;
    else
        return PD_EINVAL;
    return PD_OK;
}

double pd_shape_cut(double end, int side)
{
    return pd_shape_cut_inline(end, side);
}

/* 1 when tau lies past the pulse end on the requested side. */
static int after_pulse(pd_pulse pulse, double tau, int side)
{
    double cut = pd_shape_cut(PD_TWO_PI, side);
    return pulse != PD_PULSE_HARMONIC && (side < 0 ? tau > cut : tau >= cut);
}

/* s phi(tau). */
double pd_pulse_shape(pd_pulse pulse, int dir, double tau, int side)
{
    return pd_pulse_shape_inline(pulse, dir, tau, side);
}

/* d/dtau of s phi(tau). */
double pd_pulse_shape_rate(pd_pulse pulse, int dir, double tau, int side)
{
    if (after_pulse(pulse, tau, side))
        return 0.0;
    return dir * (pulse == PD_PULSE_COSINE ? -sin(tau) : cos(tau));
}
