/* vdb.h — OpenVDB files (.vdb), written and read without the library.
 *
 * What is written. One file holds one or more grids, each a sparse tree of
 * OpenVDB's standard configuration (root → 32³ internal → 16³ internal →
 * 8³ leaf, type names "Tree_float_5_4_3" for a FloatGrid and
 * "Tree_vec3s_5_4_3" for a Vec3SGrid). A grid of 1 channel is a FloatGrid
 * (density, temperature, …, class "fog volume"); a grid of 3 channels is a
 * Vec3SGrid (colour: vol[0..2] are r, g, b; class "unknown"). Background 0
 * (inactive). A voxel is active when its value is non-zero (for a Vec3
 * grid: any component non-zero); only 8³ leaves holding an active voxel are
 * stored, so a sparse volume makes a small file. -0.0 counts as zero and
 * reads back as +0.0. There are no tiles. File format version 224 (the
 * version OpenVDB 10 to 12 write; python3-openvdb 10.0.1 reports
 * FILE_FORMAT_VERSION 224), library version field 10.0.
 *
 * Compression. No zip, no blosc. By default the grids use OpenVDB's
 * "active values" mask compression (flag COMPRESS_ACTIVE_MASK): each node
 * stores only its active values, inactive ones are the background. With
 * VDB_UNCOMPRESSED every node stores all its values (flag COMPRESS_NONE);
 * the files are much larger and read the same.
 *
 * Transform (the convention). Voxel index (i, j, k) of a grid is frac's
 * sample (i, j, k) of the volume (x fastest in frac's array, which does not
 * matter here: OpenVDB addresses voxels by coordinate). Its world position
 * is the sample's cell centre (volume.h):
 *     world = translation + s ⊙ (i, j, k),  s = (hi - lo) / n,
 *     translation = lo + s / 2,
 * a ScaleTranslateMap (UniformScaleTranslateMap when the three voxel sizes
 * are equal). OpenVDB's voxel (i, j, k) covers world index space
 * [i - 0.5, i + 0.5], so the volume's box lo..hi is exactly the union of the
 * voxels. Grid metadata "frac_size" (vec3i: nx, ny, nz), "frac_lo" and
 * "frac_hi" (vec3d) hold the box exactly; other tools ignore them.
 *
 * What is read. The subset frac writes, and OpenVDB's own files of the same
 * kind: format versions 222 to 225, files with grid offsets (io::File, not
 * io::Stream), float or vec3s grids of the 5-4-3 tree, full-precision
 * (not "_HalfFloat"), uncompressed or active-mask compressed (the seven
 * per-node mask modes), no tiles other than inactive background, a
 * ScaleTranslateMap, UniformScaleTranslateMap, ScaleMap, UniformScaleMap,
 * TranslationMap or axis-aligned AffineMap with positive voxel sizes.
 * Anything else is refused with RT_EFORMAT and a message that says what.
 * The volume's box: from frac_size/frac_lo/frac_hi when they are present
 * and agree with the transform; otherwise the bounding box of the active
 * voxels (lo = world position of its lowest voxel minus half a voxel).
 * Values of a stored leaf are read whether active or not; voxels in no
 * stored leaf get the grid's background.
 *
 * Where the facts come from (OpenVDB's sources, read for understanding,
 * tag v10.0.1 of the AcademySoftwareFoundation/openvdb repository):
 *   magic 0x56444220 and format version numbers 222..225:
 *       openvdb/version.h.in (OPENVDB_MAGIC, OPENVDB_FILE_VERSION_*);
 *   header layout (magic as int64, version, library major/minor, the
 *       grid-offsets byte, the 36-character ASCII UUID), file metadata, grid
 *       count: io/Archive.cc Archive::writeHeader / readHeader / write;
 *   grid descriptor (unique name, type, instance parent, three int64
 *       offsets): io/GridDescriptor.cc; per-grid compression word:
 *       Archive::setGridCompression / readGridCompression;
 *   metadata (count, name, type name, uint32 size, bytes; std::map order):
 *       MetaMap.cc, Metadata.h; names "class", "creator", "name",
 *       "file_bbox_min/max", "file_compression", "file_mem_bytes",
 *       "file_voxel_count": Grid.cc; class string "fog volume": Grid.cc;
 *   transform (map type name then its Vec3d members in declaration order):
 *       math/Transform.cc, math/Maps.h;
 *   topology and buffers (buffer count 1; root background, tile and child
 *       counts, child origins; internal node child mask, value mask,
 *       compressed values, children in offset order; leaf value mask, then
 *       in the buffer pass mask again and the values), and the offset
 *       formulas (x major, z minor): tree/Tree.h, tree/RootNode.h,
 *       tree/InternalNode.h, tree/LeafNode.h, util/NodeMasks.h;
 *   per-node value compression (the metadata byte and its seven modes):
 *       io/Compression.h readCompressedValues / writeCompressedValues.
 * Everything is little-endian (OpenVDB writes host order; every platform
 * it ships on is little-endian).
 *
 * Files are built in memory and written through fileio_write_atomic.
 * Memory: malloc/free (the file buffer, one leaf table, one scratch block).
 */
#ifndef VDB_H
#define VDB_H

#include "fileio.h"
#include "rt.h"
#include "volume.h"

enum { VDB_UNCOMPRESSED = 1 }; /* vdb_to_mem flags */

/* One grid to write: a name (unique in the file, 1..255 bytes) and 1
 * volume (FloatGrid) or 3 volumes of equal size and box (Vec3SGrid). */
typedef struct vdb_grid {
    const char *name;
    int channels; /* 1 or 3 */
    const volume *vol[3];
} vdb_grid;

rt_code vdb_to_mem(const vdb_grid *grids, int ngrids, int flags, bytebuf *out, rt_error *e);
rt_code vdb_save(const char *path, const vdb_grid *grids, int ngrids, int flags, rt_error *e);

/* Read the grid called name (NULL: "density" if there is one, else the
 * file's only grid) into out[0] (float grid; *channels = 1) or out[0..2]
 * (vec3s grid; *channels = 3), allocated here. A box of more than
 * max_voxels voxels is refused (RT_EINVAL) before anything is allocated. */
rt_code vdb_from_mem(const unsigned char *d, size_t n, const char *name, double max_voxels,
                     volume out[3], int *channels, rt_error *e);
rt_code vdb_load(const char *path, const char *name, double max_voxels, volume out[3], int *channels,
                 rt_error *e);

#endif
