/* volume_io.h — volume files (NRRD, raw + detached NRRD header, legacy VTK)
 * and planar slices of volumes into images.
 *
 * Geometry. A volume's sample (i, j, k) sits at the cell centre
 * lo + (hi - lo) (i + 0.5) / n (volume.h). Files store the position of the
 * first sample and the spacing, so:
 *   NRRD: `space directions: (sx,0,0) (0,sy,0) (0,0,sz)`, `space origin:
 *         (lo + s/2)`, `centers: cell cell cell`; plus the key/value pairs
 *         `frac lo:=` and `frac hi:=` holding lo and hi exactly (17
 *         significant digits at most), which our reader prefers, so bounds
 *         round-trip bit-exactly. Without them the reader uses lo = origin -
 *         s/2, hi = lo + n s; `spacings:` (no space) is accepted too; with
 *         neither, spacing 1 and lo = 0.
 *   VTK:  `ORIGIN lo + s/2`, `SPACING s` (point data at the cell centres).
 * Numbers are written in the shortest of %.15g / %.17g that reads back
 * exactly.
 *
 * Sample types written: VIO_FLOAT (32-bit IEEE), VIO_USHORT, VIO_UCHAR.
 * Quantisation: v is clamped to [0, 1] (NaN -> 0) and mapped to
 * round(v · 255) or round(v · 65535); reading maps uchar back by / 255 and
 * ushort by / 65535, so the round-trip error is at most 1/510 or 1/131070.
 * Other integer types read (short, int) keep their numeric value.
 *
 * NRRD (teem's format, NRRD0001..NRRD0005 read, NRRD0004 written): header
 * lines, a blank line, then raw data (x fastest). Multi-byte data carries
 * `endian: little` (ParaView needs it). Reading: `encoding: raw` only;
 * types uchar/short/ushort/int/float/double (and their teem synonyms);
 * little or big endian; dimension 3; `data file:` (detached data, relative
 * to the header's directory) and `byte skip:`.
 *
 * VTK legacy (`# vtk DataFile Version 3.0`, BINARY, DATASET
 * STRUCTURED_POINTS, SCALARS float): the binary data is big-endian always
 * (the VTK format says so). The reader reads what the writer writes.
 *
 * Every file is written through fileio_write_atomic.
 */
#ifndef VOLUME_IO_H
#define VOLUME_IO_H

#include "fileio.h"
#include "image.h"
#include "ramp.h"
#include "rt.h"
#include "volume.h"

enum { VIO_FLOAT = 0, VIO_USHORT = 1, VIO_UCHAR = 2 };

/* NRRD file in memory. data_file NULL: header + attached data; otherwise
 * a detached header naming data_file (no data appended). */
rt_code vio_nrrd_to_mem(const volume *v, int type, const char *data_file, bytebuf *out, rt_error *e);
/* The raw samples alone (little-endian for multi-byte types). */
rt_code vio_raw_to_mem(const volume *v, int type, bytebuf *out, rt_error *e);
/* Write an attached .nrrd. */
rt_code vio_save_nrrd(const char *path, const volume *v, int type, rt_error *e);
/* Write raw data to raw_path and a detached header naming it to nhdr_path
 * ("raw with a header"). The header names the raw file by its path relative
 * to the header's directory when both are in the same directory, otherwise
 * by raw_path as given. */
rt_code vio_save_nhdr(const char *nhdr_path, const char *raw_path, const volume *v, int type,
                      rt_error *e);
/* Legacy VTK STRUCTURED_POINTS, BINARY, big-endian float. */
rt_code vio_vtk_to_mem(const volume *v, bytebuf *out, rt_error *e);
rt_code vio_save_vtk(const char *path, const volume *v, rt_error *e);

/* Parse a NRRD from memory. dir: directory for a detached `data file`
 * (NULL: detached headers are refused). *v is allocated here. */
rt_code vio_nrrd_from_mem(const unsigned char *d, size_t n, const char *dir, volume *v, rt_error *e);
/* Read a .nrrd or a .nhdr (with its data file). */
rt_code vio_load_nrrd(const char *path, volume *v, rt_error *e);
rt_code vio_vtk_from_mem(const unsigned char *d, size_t n, volume *v, rt_error *e);
rt_code vio_load_vtk(const char *path, volume *v, rt_error *e);

/* The slice of samples at `index` along `axis` (0 = x, 1 = y, 2 = z) as an
 * image allocated here: axis 2 gives w = nx, h = ny; axis 1 gives w = nx,
 * h = nz; axis 0 gives w = ny, h = nz; the second image axis points up (the
 * top row is the highest y or z index). A sample v maps to
 * t = (v - vmin) / (vmax - vmin) and then through the ramp r (NULL: grey,
 * t clamped to [0, 1], alpha 1). Requires vmin < vmax. */
rt_code volume_slice_axis(const volume *v, int axis, int index, const ramp *r, double vmin,
                          double vmax, image *out, rt_error *e);

#endif
