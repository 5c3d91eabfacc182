/* mesh_io.h — mesh files: PLY (binary little-endian and ASCII), OBJ, binary
 * STL; writers and readers (the readers exist for round trips and for
 * importing simple meshes).
 *
 * PLY (Turk's format as read by MeshLab / Blender / ParaView):
 *   element vertex N: float x y z, [float nx ny nz], [uchar red green blue
 *   alpha]; element face M: list uchar int vertex_indices. Colours are
 *   round(clamp(c, 0, 1) · 255). A point cloud (no triangles) has no face
 *   element. ASCII floats are written with 9 significant digits (exact for
 *   float). The reader takes ascii / binary_little_endian /
 *   binary_big_endian, any scalar property types, skips unknown elements and
 *   properties, and fan-triangulates polygons.
 * OBJ: `v x y z` (`v x y z r g b` when the mesh has colours, the common
 *   extension), `vn` per vertex when it has normals, and `f a//a b//b c//c`
 *   (or `f a b c`) with 1-based indices. The reader takes v / vn / f with
 *   v, v/t, v//n, v/t/n and negative (relative) indices; a vertex's normal
 *   is the last one a face corner gives it; polygons are fan-triangulated.
 * STL (binary): 80-byte header "frac mesh" padded with zero bytes (no
 *   timestamp), uint32 count, then per triangle the unit facet normal
 *   (right-hand rule; zero for a degenerate triangle), three vertices and a
 *   zero uint16. The reader welds bit-identical positions back into shared
 *   vertices, so a closed mesh stays closed, then gives each edge-connected
 *   piece its own vertices again (closed pieces that touch at an edge, a
 *   face or a corner, like a function set's K_n, come back apart: at an edge
 *   of more than two triangles each triangle pairs with the next one met
 *   turning about the edge into its inside); ASCII STL is refused.
 *
 * Every file is written through fileio_write_atomic.
 */
#ifndef MESH_IO_H
#define MESH_IO_H

#include "fileio.h"
#include "mesh.h"
#include "rt.h"

rt_code mio_ply_to_mem(const mesh *m, int ascii, bytebuf *out, rt_error *e);
rt_code mio_obj_to_mem(const mesh *m, bytebuf *out, rt_error *e);
rt_code mio_stl_to_mem(const mesh *m, bytebuf *out, rt_error *e);

/* Write by extension: .ply (binary), .obj, .stl. */
rt_code mio_save(const char *path, const mesh *m, rt_error *e);
rt_code mio_save_ply(const char *path, const mesh *m, int ascii, rt_error *e);

/* Readers; *m is initialised here (mesh_free it afterwards, also on failure). */
rt_code mio_ply_from_mem(const unsigned char *d, size_t n, mesh *m, rt_error *e);
rt_code mio_obj_from_mem(const unsigned char *d, size_t n, mesh *m, rt_error *e);
rt_code mio_stl_from_mem(const unsigned char *d, size_t n, mesh *m, rt_error *e);
/* Read by extension: .ply, .obj, .stl. */
rt_code mio_load(const char *path, mesh *m, rt_error *e);

#endif
