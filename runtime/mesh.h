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

/* Topology statistics: edges shared by 1 triangle (boundary), by > 2
 * (non-manifold), Euler characteristic V - E + F (counting only vertices
 * used by triangles), degenerate triangles (repeated index or zero area),
 * total area, and the signed volume sum over triangles of a . (b x c) / 6
 * (positive for a closed mesh wound counter-clockwise seen from outside;
 * meaningful only for a closed mesh). */
typedef struct mesh_stats {
    size_t vertices, triangles, edges;
    size_t boundary_edges, nonmanifold_edges, degenerate;
    long euler;
    double area;
    double volume;
} mesh_stats;

rt_code mesh_compute_stats(const mesh *m, mesh_stats *st, rt_error *e);

#endif
