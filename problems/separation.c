/* separation.c — how wide a gap must be (docs/scenes.md, "Separation"):
 * the exact answer for linear structures, the largest closing of the two
 * sides' free motions (the contact-free twin's approach), beside the codes'
 * rules from each side's own peak displacement at the contact's level:
 * the absolute sum (ABS), the square root of the sum of squares (SRSS) and
 * the double difference combination (DDC, Penzien; Jeng, Kasai and Maison),
 * whose correlation of the two sides is Der Kiureghian's coefficient of two
 * oscillators under one white noise. */
#include <math.h>

#include "scene_priv.h"

double pd_ddc_correlation(double Ta, double Tb, double xia, double xib)
{
    if (!(Ta > 0.0) || !(Tb > 0.0) || !(xia >= 0.0) || !(xib >= 0.0) || !isfinite(Ta) ||
        !isfinite(Tb))
        return NAN;
    double r = Ta / Tb;
    if (r == 1.0 && xia == xib) /* one oscillator twice (the limit at zero damping too) */
        return 1.0;
    double num = 8.0 * sqrt(xia * xib) * (xia + r * xib) * r * sqrt(r);
    double den = (1.0 - r * r) * (1.0 - r * r) + 4.0 * xia * xib * r * (1.0 + r * r) +
                 4.0 * (xia * xia + xib * xib) * r * r;
    return num / den;
}

/* The peak |x| of the twin at a contact's side (0 at a wall), its
 * structure's T0 and damping ratio. */
static double side_peak(const pd_scene *sc, const pd_scene_summary *s, int st, int level,
                        double *T0, double *xi)
{
    if (st == PD_WALL) {
        *T0 = *xi = NAN;
        return 0.0;
    }
    *T0 = sc->st[st].T0;
    *xi = sc->st[st].xi;
    return s->free.umax[sc->st[st].dof + level - 1];
}

void pd_scene_separation(const pd_scene *sc, pd_scene_summary *s)
{
    for (int a = 0; a < sc->ncontact; a++) {
        const pd_contact *ct = &sc->ct[a];
        double Ta, Tb, xa, xb;
        double ua = side_peak(sc, s, ct->a, ct->level_a, &Ta, &xa),
               ub = side_peak(sc, s, ct->b, ct->level_b, &Tb, &xb);
        /* the free motions' largest closing: the gap that is never closed */
        s->required_gap[a] = fmax(s->free.approach[a], 0.0);
        s->rule_abs[a] = ua + ub;
        s->rule_srss[a] = hypot(ua, ub);
        /* a wall's side moves not: every rule is the other side's peak */
        double rho =
            ct->a == PD_WALL || ct->b == PD_WALL ? 0.0 : pd_ddc_correlation(Ta, Tb, xa, xb);
        s->rule_ddc[a] = sqrt(fmax(ua * ua + ub * ub - 2.0 * rho * ua * ub, 0.0));
    }
}
