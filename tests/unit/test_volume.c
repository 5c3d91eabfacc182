/* test_volume.c — volume_sample (volume.h): trilinear between sample
 * centres reproduces a linear function of the position exactly, and clamps
 * to the border samples outside the centres. */
#include <math.h>

#include "check.h"
#include "volume.h"

/* the linear function of the continuous sample index (i, j, k) */
static double lin(double i, double j, double k) { return 1 + 2 * i + 3 * j + 5 * k; }

int main(void)
{
    rt_error e;
    volume v;
    double lo[3] = {-1, 0, 2}, hi[3] = {3, 1, 5};
    int n[3] = {8, 5, 6};
    CHECK(volume_init(&v, n[0], n[1], n[2], lo, hi, &e) == RT_OK, "volume");
    for (int k = 0; k < n[2]; k++)
        for (int j = 0; j < n[1]; j++)
            for (int i = 0; i < n[0]; i++)
                *volume_at(&v, i, j, k) = (float)lin(i, j, k);
    /* sample centre i sits at lo + (i + 1/2)(hi - lo)/n */
    double q[4][3] = {{1.2, 0.37, 3.1}, {-0.7, 0.12, 2.3}, {2.6, 0.83, 4.6}, {0.25, 0.5, 3.5}};
    for (int p = 0; p < 4; p++) {
        double f[3];
        for (int a = 0; a < 3; a++)
            f[a] = (q[p][a] - lo[a]) / (hi[a] - lo[a]) * n[a] - 0.5;
        double want = lin(f[0], f[1], f[2]);
        float got = volume_sample(&v, q[p][0], q[p][1], q[p][2]);
        CHECK(fabs(got - want) < 1e-5 * fabs(want), "point %d: %.7g, the linear function gives %.7g", p, got, want);
    }
    /* below the first centre and above the last: the border samples */
    CHECK(volume_sample(&v, -1, 0, 2) == (float)lin(0, 0, 0), "the corner below the first centres");
    CHECK(volume_sample(&v, 3, 1, 5) == (float)lin(7, 4, 5), "the corner above the last centres");
    volume_free(&v);
    return check_done("test_volume");
}
