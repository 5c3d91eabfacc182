/* chaos.h — the chaos game (random iteration algorithm) for IFS and RIFS.
 *
 * A chaos_sys names one system: an ifs (ifs.h) or a rifs (order 1 or 2).
 * One orbit step draws a map index k — from the IFS's alias table, or from
 * the alias table of the RIFS row of the current state (seed 001 §2: p_ij =
 * probability of ω_j after ω_i; order 2: the row of the last two maps) — and
 * applies ω_k: z_{n+1} = ω_k(z_n). Every point after the burn-in is plotted.
 *
 * Work decomposition (determinism). The opts.points plotted points are cut
 * into chunks of opts.chunk points (default CHAOS_CHUNK = 2^20; the last
 * chunk is shorter). Chunk c runs its own orbit with rng stream
 * rng_init(seed, c), starting at the fixed point of the start state's map
 * (the RIFS start state, or map 1 of an IFS: the fixed point of ω_1 lies on
 * the attractor), in the start state, and skips its first opts.burn points
 * (default CHAOS_BURN = 20; -1 = none): the transient while the start point
 * and state forget their choice (with contraction ≤ 0.5 the start error is
 * below 2^-20 of the attractor's size; raise burn for weakly contracting
 * systems). One 64-bit rng word per step: high 32 bits pick the alias
 * column, low 32 bits the side (ifs.h). Counts are accumulated in per-worker
 * private 32-bit arrays (with exact carry into a 64-bit side array on
 * wrap-around) and summed at the end. With colour a bin is one 16-byte cell
 * of 32-bit (count, r, g, b) — channels quantised to 0..65535 per hit — that
 * is flushed into 64-bit side sums every 65536 hits, so no sum can wrap.
 * Every merge is an exact integer sum: the result is byte-identical for any
 * number of threads. Memory: per worker 4 bytes per bin/voxel (16 with
 * colour); a 2-D histogram without colour is counted into by worker 0
 * directly (hs->count), and a 3-D measure in the volume's own memory
 * (uint32 counts where the floats will be, converted in place), so one
 * thread needs no private array. All the 2-D and 3-D counting loops prefetch
 * the target cell and add each hit 32 points later (a ring of pending
 * indices).
 *
 * Colour (2-D histograms, point clouds, projections):
 *   CHAOS_COLOUR_NONE   counts only.
 *   CHAOS_COLOUR_LAST   a hit has the colour ramp(c_k) of the map k just applied.
 *   CHAOS_COLOUR_BLEND  flam3's colour coordinate: c ← (c + c_k)/2 at every step
 *                       (c starts at c of the start map), the hit has ramp(c)
 *                       (ramp sampled at 1024 points); colours blend over the
 *                       last few maps of the address.
 *   c_k = opts.map_c[k] (in [0, 1]) or k/(n-1) by default (0 for one map);
 *   the ramp is opts.ramp or grey.
 *
 * Window fitting (chaos_fit): a pre-pass of CHAOS_FIT_POINTS points, or
 * opts.fit_points when that is smaller (the interpreter's --max-points), (rng
 * stream 2^63 of the seed, so independent of the chunks); per axis the
 * bounding interval of the points between the 0.1 % and 99.9 % quantiles
 * (a few far-out transients or rare excursions do not blow the window up),
 * widened by a 5 % margin on each side. In 2-D the shorter side is then
 * widened about its centre until the window has the aspect w:h of the
 * output; in 3-D the box is returned as is. A degenerate extent (a point or
 * a line) becomes 1 unit (or 10 % of the other axes' extent) wide.
 *
 * Measures (seed 001 §5, Borel measure of Barnsley): μ(B) ≈ N(B, n)/(n+1),
 * N(B, n) the number of the plotted points z_0..z_n in the cell B.
 *   CHAOS_NORM_TOTAL  count / (number of plotted points, inside the window or not)
 *   CHAOS_NORM_MAX    count / largest count (the densest cell is 1)
 *   CHAOS_NORM_COUNT  the raw count
 *
 * Projection (chaos_project): 3-D points through a camera (camera.h) into an
 * image with a z-buffer: a pixel keeps the nearest point (view depth z; ties
 * broken by the smaller colour so the result is order-free) and is shaded by
 * depth: b = near + (far - near)·(z - zmin)/(zmax - zmin), zmin/zmax over the
 * pixels hit; pixel = colour·b (colour = ramp colour of the point, or white
 * with CHAOS_COLOUR_NONE), alpha 1; pixels without a point get opts.bg.
 */
#ifndef CHAOS_H
#define CHAOS_H

#include <stddef.h>
#include <stdint.h>

#include "camera.h"
#include "hist.h"
#include "ifs.h"
#include "image.h"
#include "mesh.h"
#include "ramp.h"
#include "rt.h"
#include "volume.h"

#define CHAOS_CHUNK (1u << 20)
#define CHAOS_BURN 20
#define CHAOS_FIT_POINTS 65536
#define CHAOS_PALETTE 1024

typedef struct chaos_sys {
    const ifs *ifs;   /* exactly one of the two is set */
    const rifs *rifs;
} chaos_sys;

typedef enum chaos_colour { CHAOS_COLOUR_NONE, CHAOS_COLOUR_LAST, CHAOS_COLOUR_BLEND } chaos_colour;
typedef enum chaos_norm { CHAOS_NORM_TOTAL, CHAOS_NORM_MAX, CHAOS_NORM_COUNT } chaos_norm;

typedef struct chaos_opts {
    uint64_t points;     /* plotted points in total */
    uint64_t seed;
    uint32_t chunk;      /* points per chunk, 0 = CHAOS_CHUNK */
    int burn;            /* skipped points per chunk, 0 = CHAOS_BURN, -1 = none */
    chaos_colour colour;
    const double *map_c; /* n colour coordinates, or NULL */
    const ramp *ramp;    /* or NULL: grey */
    uint64_t fit_points; /* chaos_fit: at most this many pre-pass points; 0 = CHAOS_FIT_POINTS */
    /* projection only */
    double near_b, far_b; /* depth shading brightness, both 0 = 1 and 0.25 */
    float bg[4];          /* background of empty pixels */
} chaos_opts;

typedef struct chaos_stats {
    uint64_t plotted; /* points plotted (= opts.points unless cancelled) */
    uint64_t inside;  /* of those, inside the histogram/volume/image */
} chaos_stats;

/* Fit a window: lo/hi get 2 (2-D system) or 3 (3-D) values. w, h give the
 * aspect for 2-D (ignored for 3-D). */
rt_code chaos_fit(const chaos_sys *s, const chaos_opts *o, int w, int h, double *lo, double *hi,
                  rt_error *e);

/* 2-D chaos game into hs (2-D maps). Counts are ADDED to hs's counts (64-
 * or 32-bit, hist.h; 32-bit needs o->points < 2^32, and the caller keeps the
 * sum of its calls' points below that); with a colour mode hs->csum must
 * exist and colour sums are added to it. */
rt_code chaos_hist2(const chaos_sys *s, const chaos_opts *o, hist2 *hs, chaos_stats *st,
                    const rt_run *run, rt_error *e);

/* 3-D chaos game into vol (initialised by the caller with its size and box):
 * vol->v is overwritten with the normalised measure of each voxel. */
rt_code chaos_volume(const chaos_sys *s, const chaos_opts *o, chaos_norm norm, volume *vol,
                     chaos_stats *st, const rt_run *run, rt_error *e);

/* 3-D chaos game as a point cloud: appends o->points vertices to m (with
 * colours if m was initialised with colours and o->colour is set). */
rt_code chaos_points(const chaos_sys *s, const chaos_opts *o, mesh *m, const rt_run *run,
                     rt_error *e);

/* 3-D chaos game projected through cam (camera_setup done) into im
 * (initialised, overwritten), nearest point per pixel, depth shading. */
rt_code chaos_project(const chaos_sys *s, const chaos_opts *o, const camera *cam, image *im,
                      chaos_stats *st, const rt_run *run, rt_error *e);

/* 2-D measure of a histogram into an image of the same size (grey in RGB,
 * alpha 1). total = number of plotted points (chaos_stats.plotted) for
 * CHAOS_NORM_TOTAL. */
rt_code chaos_measure2(const hist2 *hs, chaos_norm norm, uint64_t total, image *im, rt_error *e);

#endif
