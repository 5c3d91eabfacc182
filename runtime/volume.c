/* volume.c — voxel grid allocation and trilinear sampling. */
#include "volume.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>

rt_code volume_init(volume *vol, int nx, int ny, int nz, const double lo[3], const double hi[3],
                    rt_error *e)
{
    vol->v = NULL;
    vol->nx = vol->ny = vol->nz = 0;
    if (nx < 1 || ny < 1 || nz < 1)
        return rt_fail(e, RT_EINVAL, "volume size %d×%d×%d is empty", nx, ny, nz);
    size_t n = rt_mul_size(rt_mul_size(rt_mul_size((size_t)nx, (size_t)ny), (size_t)nz), sizeof(float));
    if (n == 0)
        return rt_fail(e, RT_ENOMEM, "volume size %d×%d×%d is too large", nx, ny, nz);
    vol->v = rt_calloc(1, n);
    if (!vol->v)
        return rt_fail(e, RT_ENOMEM, "out of memory for a %d×%d×%d volume", nx, ny, nz);
    vol->nx = nx;
    vol->ny = ny;
    vol->nz = nz;
    for (int i = 0; i < 3; i++) {
        vol->lo[i] = lo[i];
        vol->hi[i] = hi[i];
    }
    return RT_OK;
}

void volume_free(volume *vol)
{
    rt_free(vol->v);
    vol->v = NULL;
}

static void locate(double p, double lo, double hi, int n, int *i0, double *t)
{
    double f = (p - lo) / (hi - lo) * n - 0.5;
    if (!(f > 0)) { /* also catches NaN */
        *i0 = 0;
        *t = 0;
        return;
    }
    if (f >= n - 1) {
        *i0 = n > 1 ? n - 2 : 0;
        *t = n > 1 ? 1 : 0;
        return;
    }
    double fl = floor(f);
    *i0 = (int)fl;
    *t = f - fl;
}

float volume_sample(const volume *vol, double x, double y, double z)
{
    int i, j, k;
    double tx, ty, tz;
    locate(x, vol->lo[0], vol->hi[0], vol->nx, &i, &tx);
    locate(y, vol->lo[1], vol->hi[1], vol->ny, &j, &ty);
    locate(z, vol->lo[2], vol->hi[2], vol->nz, &k, &tz);
    int i1 = i + 1 < vol->nx ? i + 1 : i;
    int j1 = j + 1 < vol->ny ? j + 1 : j;
    int k1 = k + 1 < vol->nz ? k + 1 : k;
    double c00 = *volume_at(vol, i, j, k) * (1 - tx) + *volume_at(vol, i1, j, k) * tx;
    double c10 = *volume_at(vol, i, j1, k) * (1 - tx) + *volume_at(vol, i1, j1, k) * tx;
    double c01 = *volume_at(vol, i, j, k1) * (1 - tx) + *volume_at(vol, i1, j, k1) * tx;
    double c11 = *volume_at(vol, i, j1, k1) * (1 - tx) + *volume_at(vol, i1, j1, k1) * tx;
    double c0 = c00 * (1 - ty) + c10 * ty;
    double c1 = c01 * (1 - ty) + c11 * ty;
    return (float)(c0 * (1 - tz) + c1 * tz);
}
