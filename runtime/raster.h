/* raster.h — Z-buffer rasterisation of a triangle mesh through a perspective
 * camera (seed 002 §5.2 renders wrinkly surfaces "with a Z-buffer").
 *
 *     raster_opts o; raster_opts_default(&o);
 *     image im; image_init(&im, 640, 480, &e);
 *     raster_render(&mesh, &cam, &o, &run, &im, &e);   // overwrites every pixel
 *
 * Pipeline:
 *  1. Set-up (parallel over fixed chunks of triangles): vertices are
 *     projected with camera_project; screen coordinates are snapped to 1/256
 *     pixel and held as 64-bit integers, so edge functions are exact and a
 *     shared edge gives exactly opposite values in its two triangles.
 *     A triangle with a vertex at or behind the near plane (view depth <=
 *     near, at least 1e-6) or beyond a ±2^20 pixel guard band is clipped in
 *     view space (Sutherland–Hodgman) against the near plane and the planes
 *     where the screen x or y is ±2^19, attributes interpolated linearly
 *     along the cut edges, and the convex polygon left is drawn as a fan of
 *     up to 6 triangles, listed right after their mesh triangle; the camera
 *     may be close to or inside a surface. A shared edge is cut at the same
 *     points in both its triangles, so the top-left rule below still holds.
 *     Triangles that need no clipping are set up exactly as before. Both
 *     windings are drawn (two-sided).
 *  2. Shading per vertex (Gouraud): colour = vertex colour (or o.colour when
 *     the mesh has none) × (ambient + diffuse·|n·l|), n the vertex normal, or
 *     the face normal when the mesh has no normals or o.flat is set; l points
 *     toward the light (o.light; all zero = a headlight from the camera,
 *     slightly up and left). o.unlit keeps colours as they are. Alpha is
 *     not lit.
 *  3. Binning: every triangle is listed, in mesh order, in each fixed
 *     tile (o.tile pixels square) its bounding box touches.
 *  4. Tiles in parallel (par_for over tiles): a local Z-buffer (1/z,
 *     perspective-correct) and colour buffer. Opaque triangles (all three
 *     alphas >= 1) first, in mesh order, depth test "strictly nearer"
 *     (ties keep the earlier triangle). Then the transparent ones, sorted
 *     back to front by their mean view depth (at equal depth the later
 *     triangle first, so the earlier one is in front as for the opaque
 *     ones; a clipped piece has the mean of its own corners), blended "over"
 *     in premultiplied colour where they are in front of the opaque depth,
 *     without writing depth. The tile is composited over o.background and
 *     written out un-premultiplied.
 * Coverage: a pixel is covered when its centre (x+0.5, y+0.5) is inside;
 * on an edge it belongs to the triangle for which that edge is a top or a
 * left edge (D3D/OpenGL top-left rule), so two triangles sharing an edge
 * draw every pixel on it exactly once.
 * Colours are interpolated perspective-correctly. Everything is
 * deterministic: output is byte-identical for any rt_run.threads.
 */
#ifndef RASTER_H
#define RASTER_H

#include "camera.h"
#include "image.h"
#include "mesh.h"
#include "rt.h"

typedef struct raster_opts {
    float background[4]; /* straight RGBA; default opaque black */
    float colour[4];     /* colour of a mesh without colours; default white */
    double light[3];     /* direction toward the light (world); zero: headlight */
    double ambient;      /* default 0.2 */
    double diffuse;      /* default 0.8 */
    double near;         /* near plane view depth, default 1e-3 */
    int flat;            /* 1: face normals */
    int unlit;           /* 1: no lighting */
    int tile;            /* tile size in pixels, default 32 */
} raster_opts;

void raster_opts_default(raster_opts *o);

/* Render m into im (already initialised, any size). cam must be set up
 * (camera_setup / camera_orbit). */
rt_code raster_render(const mesh *m, const camera *cam, const raster_opts *o, const rt_run *run,
                      image *im, rt_error *e);

#endif
