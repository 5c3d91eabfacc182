/* texobj.h — objects cut out of a solid texture (seed 000: "textures are
 * sampled only on the surface of an object cut out of the solid"), field
 * volumes and planar slices.
 *
 * texobj_render casts one ray per (sub)pixel through the camera, intersects
 * it with one shape, and evaluates the colour source ONLY at the visible
 * hit points: the image is split into bands of TEXOBJ_BAND rows (the
 * par_for chunks); a band first collects all hit points, then calls the
 * colour source in blocks of at most RT_BLOCK points, then shades. So the
 * number of texture evaluations equals the number of hit samples
 * (reported in texobj_stats) and the cost grows with the visible area, not
 * with the volume of the solid.
 *
 * Shapes (world space, +y up):
 *   sphere    centre, radius
 *   cube      axis-aligned, centre, half side `radius`
 *   cylinder  axis parallel to +y through centre, radius, total height
 *             `height`, closed by two flat caps
 *   plane     through centre with normal `normal` (infinite)
 * The colour source is either a scalar rt_field_fn mapped through a ramp,
 * or an RGB(A) callback writing 4 floats per point. Shading: one
 * directional light, colour * (ambient + diffuse * max(0, N.L)) on RGB,
 * alpha from the source; N is turned to face the camera (so a plane or the
 * inside of a shape seen from within is lit the same from both sides).
 * Supersampling: samples x samples stratified sub-pixel rays per pixel
 * (1 .. 8), averaged with the background for the rays that miss.
 * Every pixel depends only on its own rays, so the image is identical for
 * any thread count.
 *
 * texobj_sample_volume fills an initialised volume with a field at its
 * sample centres (volume.h convention: lo + (hi - lo)(i + 0.5)/n).
 * texobj_slice renders the plane through `origin` spanned by u (image right)
 * and v (image up): pixel (px, py) shows the field at
 * origin + a u + b v, a = 2(px + 0.5)/w - 1, b = 1 - 2(py + 0.5)/h,
 * coloured through a ramp (origin is the image centre, u and v half sides).
 */
#ifndef TEXOBJ_H
#define TEXOBJ_H

#include <stdint.h>

#include "camera.h"
#include "image.h"
#include "ramp.h"
#include "rt.h"
#include "volume.h"

#define TEXOBJ_BAND 8

enum { TEXOBJ_SPHERE = 0, TEXOBJ_CUBE = 1, TEXOBJ_CYLINDER = 2, TEXOBJ_PLANE = 3 };

typedef struct texobj_shape {
    int kind;
    double center[3];
    double radius; /* sphere, cylinder; cube: half side */
    double height; /* cylinder */
    double normal[3]; /* plane */
} texobj_shape;

/* RGBA colour source: write 4 floats per point. Reentrant. */
typedef void (*texobj_rgb_fn)(const void *ctx, size_t n, const double *x, const double *y,
                              const double *z, float *rgba);

typedef struct texobj_source {
    rt_field_fn field;       /* scalar source ... */
    const void *field_ctx;
    const ramp *ramp;        /* ... through this ramp (NULL: grey) */
    texobj_rgb_fn rgb;       /* or an RGBA source (used if set) */
    const void *rgb_ctx;
} texobj_source;

typedef struct texobj_opts {
    float background[4];
    double light[3];   /* direction towards the light, need not be unit */
    double ambient;    /* 0 .. 1 */
    double diffuse;    /* 0 .. 1 */
    int samples;       /* per axis, 1 .. 8 */
} texobj_opts;

typedef struct texobj_stats {
    uint64_t rays;     /* rays cast */
    uint64_t hits;     /* rays that hit = texture evaluations */
} texobj_stats;

/* Background transparent black, light from (1, 1, 1), ambient 0.2,
 * diffuse 0.8, 1 sample. */
void texobj_opts_default(texobj_opts *o);
rt_code texobj_shape_check(const texobj_shape *s, rt_error *e);

/* Ray–shape intersection: nearest t > 1e-9 along unit dir from o, with the
 * outward surface normal; returns 1 on a hit. */
int texobj_intersect(const texobj_shape *s, const double o[3], const double dir[3], double *t,
                     double normal[3]);

/* Render into an initialised image (its w, h give the size). */
rt_code texobj_render(const texobj_shape *s, const camera *cam, const texobj_source *src,
                      const texobj_opts *o, const rt_run *run, image *im, texobj_stats *st,
                      rt_error *e);

rt_code texobj_sample_volume(rt_field_fn f, const void *ctx, volume *vol, const rt_run *run,
                             rt_error *e);

rt_code texobj_slice(rt_field_fn f, const void *ctx, const ramp *r, const double origin[3],
                     const double u[3], const double v[3], const rt_run *run, image *im, rt_error *e);

#endif
