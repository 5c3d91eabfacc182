/* fern.h — Barnsley's fern for the chaos-game unit tests: the four maps of
 * seed 001 with p = 0.01, 0.85, 0.07, 0.07, built into f (ifs_free it).
 * Include after check.h. */
#ifndef FERN_H
#define FERN_H

#include "ifs.h"

static void fern_build(ifs *f)
{
    rt_error e;
    affine fern[4] = {affine_from_2d(0, 0, 0, 0.16, 0, 0), affine_from_2d(0.85, 0.04, -0.04, 0.85, 0, 1.6),
                      affine_from_2d(0.2, -0.26, 0.23, 0.22, 0, 1.6),
                      affine_from_2d(-0.15, 0.28, 0.26, 0.24, 0, 0.44)};
    double p[4] = {0.01, 0.85, 0.07, 0.07};
    CHECK(ifs_build(f, fern, 4, p, 0, &e) == RT_OK, "fern: %s", e.msg);
}

#endif
