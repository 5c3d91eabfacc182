/* raymarch.h — ray marching a scalar field inside a box (seed 001).
 *
 * Seed 001 renders hypertextures D(x) "with density as transparency, and as
 * solids thresholded at density >= 0.3 and >= 0.5" (Figs. 5–8). Both modes:
 *
 * RM_EMISSION — emission–absorption. Each ray is clipped to the box [lo, hi]
 * (entry t0 = max(near, 0), exit t1); [t0, t1] is cut into N = ceil((t1 -
 * t0) / step) equal steps of length Δ <= step (so a box face is never
 * straddled) and the field is sampled at each step's midpoint. A sample of
 * density ρ (negative or NaN counts as 0) has opacity α = 1 - exp(-σ ρ Δ)
 * and colour C (ramp(ρ), or the constant `emission`), composited front to
 * back: L += T α C, T *= 1 - α, stopping early once T < min_transmittance.
 * The pixel is L + T · background (alpha: 1 - T + T · background alpha). A
 * uniform medium of thickness d thus transmits exactly exp(-σ ρ d) of the
 * background. With `lighting`, C is multiplied by ambient + (1 - ambient) ·
 * max(0, n · light), n = -grad ρ / |grad ρ| (central differences).
 *
 * RM_SOLID — the solid is {ρ >= threshold}. The ray is sampled at t0 + kΔ,
 * k = 0..N; at the first sample inside, the crossing is refined by
 * `refine` bisection steps between it and the previous sample, and shaded
 * surface · (ambient + (1 - ambient) · max(0, n · light)) with the gradient
 * normal n as above (alpha 1). A ray that starts inside shows the entry
 * point. Misses show the background. Thin features under a step can be
 * missed: choose step below the feature size.
 *
 * Exact hard boundaries (optional distances, fields only; field.h derives
 * them, and each is 1-Lipschitz: |g(p) - g(q)| <= |p - q|):
 *
 * `support` (emission mode): g with f = 0 wherever g > 0 — a hard region
 * such as a hard shape, or a product of one with anything. Each step is
 * then split at the region's boundary: a step whose end values prove it
 * wholly outside (g_a + g_b >= Δ) or wholly inside (g_a + g_b <= -Δ) is
 * taken whole; any other is halved (down to Δ/64, with g at the midpoint),
 * and a piece whose ends differ in sign holds a root of g found by the
 * Illinois method (to 1e-12 of a step). The opacity of the step is
 * 1 - exp(-σ ρ ℓ) with ℓ the summed inside length and ρ = f at the middle
 * of the longest inside piece. For a region of constant density this is
 * exact: a hard slab of thickness d transmits exp(-σ ρ d) to rounding.
 * What is not exact: a density varying inside the region is sampled once
 * per step (the midpoint rule, as without `support`), and a feature that
 * enters and leaves within one Δ/64 piece is missed or counted whole (a
 * length error below Δ/64 per such feature).
 *
 * `sdf` (solid mode): g <= 0 exactly where f >= threshold. The march then
 * samples -g against 0 instead of f against threshold (the same first
 * crossing and bisection), and the normal is grad g / |grad g| by central
 * differences of g: the true surface normal of a hard shape instead of the
 * difference of its 0/1 samples (which would shade it in flat patches).
 *
 * Evaluation: one image row is one par_for chunk; its rays march in
 * lock-step in blocks of up to RT_BLOCK rays, and every field call
 * evaluates one block of points (the active rays' samples, gathered). Each
 * pixel depends only on its own ray, so the image is identical for any
 * thread count. Progress label "raymarch".
 *
 * The image must be initialised by the caller (its w × h is the render
 * size); every pixel is written.
 */
#ifndef RAYMARCH_H
#define RAYMARCH_H

#include "camera.h"
#include "image.h"
#include "ramp.h"
#include "rt.h"
#include "volume.h"

enum { RM_EMISSION = 0, RM_SOLID = 1 };

typedef struct rm_opts {
    int mode;                  /* RM_EMISSION or RM_SOLID */
    double lo[3], hi[3];       /* bounding box of the field, lo < hi */
    double step;               /* maximal step length, > 0 */
    double sigma;              /* extinction per unit density and length (emission) */
    const ramp *emission_ramp; /* emission colour = ramp(density); NULL: `emission` */
    float emission[4];         /* constant emission colour (rgb used) */
    float background[4];
    int lighting;              /* emission mode: shade with gradient normals */
    double light[3];           /* direction toward the light (normalised here) */
    double ambient;            /* in [0, 1] */
    double threshold;          /* solid mode: inside when density >= threshold */
    float surface[4];          /* solid mode: surface colour (rgb used) */
    int refine;                /* bisection steps in solid mode, 0..60 */
    double min_transmittance;  /* early termination, in [0, 1) */
    double grad_h;             /* central-difference offset; 0 = step / 2 */
    rt_field_fn sdf;           /* solid mode: optional distance, see above */
    const void *sdf_ctx;
    rt_field_fn support;       /* emission mode: optional hard support, see above */
    const void *support_ctx;
} rm_opts;

/* Defaults: emission mode, box [-1, 1]³, step 1/128, σ = 8, white
 * emission, black opaque background, light (0.4, 0.8, 0.45), ambient 0.25,
 * threshold 0.5, surface white, 10 bisection steps, min_transmittance 1e-4. */
void rm_defaults(rm_opts *o);

rt_code rm_render(rt_field_fn f, const void *ctx, const camera *cam, const rm_opts *o,
                  const rt_run *run, image *im, rt_error *e);

/* Adapter: ctx is a `const volume *`; values by volume_sample (trilinear,
 * clamped to the edge samples). Set the box to the volume's lo/hi. */
void rm_volume_field(const void *ctx, size_t n, const double *x, const double *y, const double *z,
                     double *out);

#endif
