/* deflate.h — our own DEFLATE (RFC 1951) compressor and decompressor, the
 * zlib wrapper (RFC 1950) with Adler-32, and CRC-32 (for PNG chunks).
 *
 * Compression (deflate.c): LZ77 over a 32 KiB window with hash chains and
 * zlib-style lazy matching, then per block (about 16K symbols) the smallest
 * of a dynamic Huffman block (length-limited canonical codes: 15 bits for
 * literal/length and distance codes, 7 bits for the code-length code), a
 * fixed Huffman block or stored blocks. The output depends only on the input
 * bytes and the level: the same input always gives the same bytes.
 *
 *   level 0      stored blocks only (no compression; fastest)
 *   level 1      greedy matching, chains of 4, 4-byte hash
 *   level 2..5   lazy matching, chains of 16..64, 4-byte hash (2 is PNG's
 *                default: about zlib level 2's speed, zlib level 6's size
 *                on image data)
 *   level 6..9   lazy matching, longer chains, 3-byte hash: zlib's
 *                parameters for these levels (6 is the usual default)
 *
 * deflate_zlib appends a complete zlib stream (2-byte header, deflate data,
 * Adler-32 of the input, big-endian) to out; deflate_raw appends bare deflate
 * data. Both return RT_ENOMEM if an allocation fails (out is then left with
 * out->failed set or partially filled) and RT_EINVAL for a bad level.
 *
 * Decompression (inflate.c): inflate_zlib decodes a complete zlib stream
 * (stored, fixed and dynamic blocks), checks the header and the Adler-32 and
 * appends the decompressed bytes to out. It never reads outside in[0..n-1]
 * and never loops without consuming input: every malformed stream gives
 * RT_EFORMAT with a one-line message saying what is wrong ("truncated
 * stream", "invalid distance 40000 (only 12 bytes written)", "Adler-32
 * mismatch", ...). If the decompressed data would exceed max_out bytes the
 * stream is refused with RT_EFORMAT (protection against decompression
 * bombs); pass the exact expected size when it is known (PNG). Bytes after
 * the Adler-32 trailer are ignored. inflate_raw decodes bare deflate data and
 * reports how many input bytes it used (*used, may be NULL).
 *
 * Checksums follow zlib's calling convention: start with the value of an
 * empty input (crc 0, adler 1) and feed pieces in order:
 *   uint32_t c = deflate_crc32(0, a, na); c = deflate_crc32(c, b, nb);
 */
#ifndef DEFLATE_H
#define DEFLATE_H

#include <stddef.h>
#include <stdint.h>

#include "fileio.h"
#include "rt.h"

#define DEFLATE_DEFAULT_LEVEL 6

uint32_t deflate_crc32(uint32_t crc, const void *p, size_t n);
uint32_t deflate_adler32(uint32_t adler, const void *p, size_t n);

rt_code deflate_raw(const unsigned char *in, size_t n, int level, bytebuf *out, rt_error *e);
rt_code deflate_zlib(const unsigned char *in, size_t n, int level, bytebuf *out, rt_error *e);

rt_code inflate_raw(const unsigned char *in, size_t n, size_t max_out, bytebuf *out,
                    size_t *used, rt_error *e);
rt_code inflate_zlib(const unsigned char *in, size_t n, size_t max_out, bytebuf *out,
                     rt_error *e);

#endif
