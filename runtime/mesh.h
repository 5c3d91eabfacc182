/* mesh.h — triangle meshes and point clouds.
 *
 * Vertices have a position, and optionally a normal and an RGBA colour
 * (float, [0, 1]). Triangles index vertices counter-clockwise seen from
 * outside (right-hand rule gives the outward normal). A point cloud is a mesh
 * with no triangles. File formats (PLY, OBJ, STL) live in mesh_io.c.
 */
#ifndef MESH_H
#define MESH_H

#include <stddef.h>
#include <stdint.h>

#include "rt.h"

typedef struct mesh {
    size_t nv, nt;
    size_t cap_v, cap_t;
    float *pos;    /* nv * 3 */
    float *nrm;    /* nv * 3, or NULL */
    float *col;    /* nv * 4, or NULL */
    uint32_t *tri; /* nt * 3 */
    int failed;    /* an allocation failed */
} mesh;

void mesh_init(mesh *m, int with_normals, int with_colours);
void mesh_free(mesh *m);
/* Append a vertex (n and c may be NULL when the mesh has no such attribute
 * or the caller fills it later). Returns its index, or UINT32_MAX if out of
 * memory (m->failed is set). */
uint32_t mesh_add_vertex(mesh *m, const float p[3], const float n[3], const float c[4]);
void mesh_add_tri(mesh *m, uint32_t a, uint32_t b, uint32_t c);
/* Append src's vertices and triangles to dst (its triangles re-indexed past
 * dst's vertices). Where src has no normals a vertex gets (0, 1, 0), where it
 * has no colours `colour`; attributes dst lacks are dropped. The caller keeps
 * dst->nv + src->nv below 2^32 - 1; an allocation failure sets dst->failed. */
void mesh_append(mesh *dst, const mesh *src, const float colour[4]);
/* Grow the box lo..hi to hold every vertex (start from lo = +inf, hi = -inf
 * for the bounding box; NaN coordinates are passed over, as fmin does). */
void mesh_grow_box(const mesh *m, double lo[3], double hi[3]);

/* Topology statistics: edges shared by 1 triangle (boundary), by > 2
 * (non-manifold), Euler characteristic V - E + F (counting only vertices
 * used by triangles), degenerate triangles (repeated index or zero area),
 * total area, and the signed volume Σ a·(b×c)/6 over the triangles (a, b, c
 * their corners): the enclosed volume of a closed mesh wound
 * counter-clockwise from outside, its negative when wound inside out. */
typedef struct mesh_stats {
    size_t vertices, triangles, edges;
    size_t boundary_edges, nonmanifold_edges, degenerate;
    long euler;
    double area;
    double volume;
} mesh_stats;

rt_code mesh_compute_stats(const mesh *m, mesh_stats *st, rt_error *e);

/* Orientation of a polyhedron given by its faces (seed 003's K0): every
 * undirected edge must be used at most once in each direction (else
 * RT_EINVAL naming the edge: two faces disagree about the winding, or an edge
 * has more than two faces). *closed is set when every edge is used exactly
 * once in each direction (a closed, consistently wound surface); a closed
 * mesh of negative signed volume (wound inside out) has every triangle
 * reversed, so closed meshes come out wound counter-clockwise from outside
 * (positive volume). Open meshes are left as given. */
rt_code mesh_orient_outward(mesh *m, int *closed, rt_error *e);

#endif
