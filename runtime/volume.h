/* volume.h — scalar voxel grids.
 *
 * A volume is nx × ny × nz float samples, x fastest (index
 * x + nx*(y + ny*z)), covering the axis-aligned box [lo, hi]. Sample
 * (i, j, k) sits at lo + (hi - lo) * (i + 0.5) / n on each axis (cell
 * centres), so a volume of the measure of an IFS holds the measure of each
 * cell. volume_sample interpolates trilinearly between sample centres and
 * clamps to the edge samples outside. File formats live in volume_io.c.
 */
#ifndef VOLUME_H
#define VOLUME_H

#include <stddef.h>

#include "rt.h"

typedef struct volume {
    int nx, ny, nz;
    double lo[3], hi[3];
    float *v;
} volume;

rt_code volume_init(volume *vol, int nx, int ny, int nz, const double lo[3], const double hi[3],
                    rt_error *e);
void volume_free(volume *vol);

static inline float *volume_at(const volume *vol, int x, int y, int z)
{
    return vol->v + (size_t)x + (size_t)vol->nx * ((size_t)y + (size_t)vol->ny * (size_t)z);
}

/* Trilinear interpolation at world point p. */
float volume_sample(const volume *vol, double x, double y, double z);

#endif
