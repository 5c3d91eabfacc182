/* textline.h — the next line of a text header in memory, the one line
 * reader of the file readers with text headers (PLY and OBJ in mesh_io.c,
 * NRRD and VTK in volume_io.c).
 *
 * A line ends at '\n' or at the end of the data; a '\r' before the '\n' is
 * not part of it (CRLF files read like LF files). textline_next copies the
 * line from d + *pos into buf as a C string, cut to bn - 1 bytes if longer,
 * moves *pos past the '\n' and returns the line's full length (before any
 * cut, so a reader can refuse a long line); -1 when *pos is at the end. The
 * bytes are copied as they are (a NUL byte ends the C string early).
 */
#ifndef TEXTLINE_H
#define TEXTLINE_H

#include <stddef.h>

long textline_next(const unsigned char *d, size_t n, size_t *pos, char *buf, size_t bn);

#endif
