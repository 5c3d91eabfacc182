/* isosurf.h — closed triangle meshes of iso-surfaces {f = level}.
 *
 * The solid is the set where f >= level (seed 001: a hypertexture thresholded
 * at density >= 0.3 or >= 0.5 is such a solid); the mesh is its boundary.
 *
 * Method: marching cubes with the asymptotic decider on faces. Each cell's
 * inside corners select a case; the case table is generated in isosurf.c
 * from the cube's topology (each face pairs its crossing edges into
 * segments, the segments close into cycles, each cycle is triangulated), so
 * no table is copied. A face with inside corners on one diagonal and
 * outside corners on the other is ambiguous: its inside corners are joined
 * across it when the saddle of the bilinear interpolant of its four samples
 * is inside (Nielson and Hamann's asymptotic decider, Visualization '91);
 * a face with a padding node or a non-finite sample keeps them apart. The
 * decision depends only on the face's samples, so the two cells sharing a
 * face pair its crossings alike. A surface vertex lives on a lattice edge (node, axis)
 * and is created once and shared by every cell touching that edge (welded,
 * indexed), so every mesh edge is used by exactly two triangles: the mesh
 * is closed, manifold and consistently oriented. Cycles are triangulated
 * without chords lying in a cube face (a neighbour could draw the same
 * chord); the few cycles that cannot be (116 of the 656 table entries, all
 * with ambiguous faces) are fanned around one extra vertex at the mean of
 * the cycle's vertices. The triangle count is that of plain marching cubes
 * except in ambiguous cells (a sphere: equal; a noisy hypertexture: +1.4%).
 *
 * Grid: the samples are those of a `volume` (cell centres, see volume.h).
 * For a callback the field is first sampled at the same cell centres of a
 * res[0] × res[1] × res[2] grid over [lo, hi] (in parallel, in blocks).
 *
 * Padding (closing the surface): the lattice is extended by one layer of
 * virtual samples on every side, which count as outside. Where the solid
 * touches the grid's boundary, the surface vertex on an edge between a real
 * sample and a virtual one is placed at the middle of that edge, which is on
 * the faces of the box [lo, hi]: the solid is clipped by the box and capped
 * by flat faces, and the mesh is closed even where the field is inside at
 * the boundary. Cap vertices get the box's outward normal. The caps lie on
 * the box faces, but along the twelve box edges the cells cut a chamfer with
 * legs of half a cell: a solid filling the whole box loses at most
 * 12 · length · cell² / 8.
 *
 * Vertex position on an edge p–q (both real samples): linear interpolation
 * s = (level - f(p)) / (f(q) - f(p)), clamped to [1e-3, 1 - 1e-3] so that no
 * two surface vertices coincide and no triangle has zero area even where a
 * sample equals the level exactly (departure from plain MC: moves a vertex by
 * at most 0.1% of an edge). NaN samples count as outside; an edge with a
 * non-finite sample gets s = 1/2.
 *
 * Orientation: triangles are counter-clockwise seen from outside (the
 * right-hand normal points from f >= level toward f < level). This requires
 * lo < hi on every axis (checked).
 *
 * Normals (opts->normals): the outward normal -grad f / |grad f|. For a
 * volume, grad f is the central difference of the grid at the edge's two
 * nodes (one-sided at the border), interpolated along the edge. For a
 * callback, grad f is the central difference of the callback itself at the
 * vertex, with offsets of 1/4 cell per axis (6 evaluations per vertex, in
 * blocks). Where the gradient vanishes the edge direction is used.
 *
 * Exact surfaces (opts->sdf, iso_from_field only): a signed distance g of
 * the solid, g <= 0 exactly where f >= level (field.h field_level_sdf
 * derives one for hard shapes and what is built from them). The mesh is
 * then built from g instead of f: a node is inside when g <= 0, and a
 * vertex is the root of g on its lattice edge, found from g at the edge's
 * ends by the Illinois variant of regula falsi (at most 40 steps, to
 * |g| <= 1e-12 of a cell; the same 1e-3 clamp as above). Normals are
 * grad g / |grad g| by central differences of g (offsets of 1/4 cell). f is
 * not sampled at all. A hard shape (a 0/1 density, whose samples would give
 * a voxel staircase) thus meshes as its true surface: every vertex lies on
 * it, and the area and volume converge as cell^2 (a sphere of radius 0.7 at
 * grid 96 over [-1, 1]^3: both within 0.1%). Sharp edges and corners are
 * cut by a chamfer of at most one cell (marching cubes places vertices
 * on lattice edges only), which is the largest area error for boxes and
 * capped cylinders.
 *
 * Colours (optional): ISO_COLOUR_RAMP evaluates colour_fn[0] at each vertex
 * and maps it through colour_ramp; ISO_COLOUR_RGB evaluates colour_fn[0..2]
 * as red, green, blue (clamped to [0, 1], alpha 1).
 *
 * Centre vertices (the extra vertices above) get the mean of their cycle's
 * positions (after root finding, with an sdf) and normals; with a callback,
 * their normal is the callback's gradient like any other vertex.
 *
 * Cost (flying-edges style passes, see isosurf.c): each sample is read once
 * and classified into bits, 64 nodes per word; after that only crossing
 * lattice edges and cells with corners on both sides are visited, found a
 * word at a time, and the vertices and triangles are counted first and
 * written straight into arrays of their final size (no hash, no growing
 * list). Extra memory: (n0 + 2) / 8 bytes per row of the padded grid for the
 * bits and two layers of vertex ids per thread.
 *
 * Determinism: the grid is processed in slabs of 4 cell layers (a fixed
 * decomposition); each slab's edge vertices are numbered in lattice order
 * (z, y, x, axis), then its centre vertices in cell order, and triangles are
 * emitted in cell order, so the mesh is byte-identical for any thread
 * count.
 */
#ifndef ISOSURF_H
#define ISOSURF_H

#include "mesh.h"
#include "ramp.h"
#include "rt.h"
#include "volume.h"

enum { ISO_COLOUR_NONE = 0, ISO_COLOUR_RAMP = 1, ISO_COLOUR_RGB = 2 };

typedef struct iso_opts {
    double level;             /* the solid is f >= level */
    int normals;              /* non-zero: compute vertex normals */
    int colour_mode;          /* ISO_COLOUR_* */
    rt_field_fn colour_fn[3]; /* [0] for RAMP; [0..2] for RGB */
    const void *colour_ctx[3];
    const ramp *colour_ramp;  /* for ISO_COLOUR_RAMP; NULL = grey */
    rt_field_fn sdf;          /* optional (fields only): signed distance, see above */
    const void *sdf_ctx;
} iso_opts;

/* Iso-surface of a volume's samples. *out is initialised here (mesh_free it
 * even on failure). */
rt_code iso_from_volume(const volume *vol, const iso_opts *opts, const rt_run *run, mesh *out,
                        rt_error *e);

/* Iso-surface of a field sampled at the cell centres of a res[0]×res[1]×res[2]
 * grid over the box [lo, hi] (res >= 1 on each axis). */
rt_code iso_from_field(rt_field_fn f, const void *ctx, const double lo[3], const double hi[3],
                       const int res[3], const iso_opts *opts, const rt_run *run, mesh *out,
                       rt_error *e);

/* Sample f at the cell centres of vol (already initialised with its size and
 * bounds), in parallel and in blocks of RT_BLOCK points. Deterministic. */
rt_code iso_sample_field(rt_field_fn f, const void *ctx, volume *vol, const rt_run *run,
                         rt_error *e);

#endif
