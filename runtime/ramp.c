/* ramp.c — piecewise-linear colour ramps. */
#include "ramp.h"

void ramp_eval(const ramp *r, double t, float out[4])
{
    int i;
    if (!(t > r->pos[0]) || r->n == 1) { /* also NaN */
        for (i = 0; i < 4; i++)
            out[i] = r->rgba[0][i];
        return;
    }
    if (t >= r->pos[r->n - 1]) {
        for (i = 0; i < 4; i++)
            out[i] = r->rgba[r->n - 1][i];
        return;
    }
    int k = 1;
    while (k < r->n - 1 && t >= r->pos[k])
        k++;
    double span = r->pos[k] - r->pos[k - 1];
    double f = span > 0 ? (t - r->pos[k - 1]) / span : 1.0;
    for (i = 0; i < 4; i++)
        out[i] = (float)(r->rgba[k - 1][i] + (r->rgba[k][i] - r->rgba[k - 1][i]) * f);
}

ramp ramp_grey(void)
{
    ramp r = {0};
    r.n = 2;
    r.pos[0] = 0;
    r.pos[1] = 1;
    for (int i = 0; i < 3; i++) {
        r.rgba[0][i] = 0;
        r.rgba[1][i] = 1;
    }
    r.rgba[0][3] = r.rgba[1][3] = 1;
    return r;
}
