/* interp.c — Hermite interpolation on a step. */
#include "pd_core.h"
#include <math.h>

/* Quintic Hermite basis in r = s / h: H3, H4, H5 carry the end point, H1,
 * H2 the start's rate and acceleration (the start value enters as 1 - H3). */
void pd_hermite5(const double p0[3], const double p1[3], double h, double r, double *f, double *fd)
{
    if (!p0 || !p1 || !f)
        return;
    double r2 = r * r, r3 = r2 * r, r4 = r3 * r, r5 = r4 * r;
    double H1 = r - 6 * r3 + 8 * r4 - 3 * r5, H2 = 0.5 * (r2 - 3 * r3 + 3 * r4 - r5);
    double H3 = 10 * r3 - 15 * r4 + 6 * r5, H4 = -4 * r3 + 7 * r4 - 3 * r5;
    double H5 = 0.5 * (r3 - 2 * r4 + r5);
    double D1 = 1 - 18 * r2 + 32 * r3 - 15 * r4, D2 = 0.5 * (2 * r - 9 * r2 + 12 * r3 - 5 * r4);
    double D3 = 30 * r2 - 60 * r3 + 30 * r4, D4 = -12 * r2 + 28 * r3 - 15 * r4;
    double D5 = 0.5 * (3 * r2 - 8 * r3 + 5 * r4);
    *f = p0[0] + (p1[0] - p0[0]) * H3 + h * (p0[1] * H1 + p1[1] * H4) +
         h * h * (p0[2] * H2 + p1[2] * H5);
    if (fd)
        *fd = (p1[0] - p0[0]) * D3 / h + p0[1] * D1 + p1[1] * D4 + h * (p0[2] * D2 + p1[2] * D5);
}

double pd_hermite3(const double p0[2], const double p1[2], double h, double r)
{
    if (!p0 || !p1)
        return NAN;
    double r2 = r * r, r3 = r2 * r;
    return p0[0] + (p1[0] - p0[0]) * (3 * r2 - 2 * r3) +
           h * (p0[1] * (r - 2 * r2 + r3) + p1[1] * (r3 - r2));
}
