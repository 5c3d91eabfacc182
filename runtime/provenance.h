/* provenance.h — the recipe every file frac writes carries (docs/provenance.md).
 *
 * The interpreter builds the recipe of a run (interp/recipe.h: version,
 * script path, SHA-256 of the script, -D params, args, seed, frame, and the
 * script text) and hands it here once, before the script runs, with
 * prov_set. The writers then embed it:
 *   PNG            tEXt Software = prov->software, and a compressed iTXt
 *                  `frac:recipe` holding prov->recipe (png.c), before IDAT;
 *   PPM/PGM, NRRD, OBJ   `# ` lines with prov->header (prov_put_lines);
 *   PLY            `comment ` lines; SVG, flame XML   one XML comment;
 *   VTK            the title line: prov->oneline (at most 255 bytes);
 *   STL            the 80-byte header: prov->oneline, cut to 80 bytes;
 *   raw, PFM, VDB  nothing (no place for it).
 * Nothing is set (prov_get() == NULL) in C tests and programs that never
 * call prov_set: then every writer writes exactly what it wrote before.
 *
 * Process-wide, like the allocation hook (rt.h explains why): codecs take
 * no context object and a process runs one interpreter. Set it before any
 * worker thread starts; the strings belong to the caller, who keeps them
 * alive until prov_set(NULL). */
#ifndef PROVENANCE_H
#define PROVENANCE_H

#include <stddef.h>

#include "fileio.h"

typedef struct prov {
    const char *software; /* "frac 0.1.0" */
    const char *recipe;   /* the whole recipe: header lines, a blank line, the script */
    size_t recipe_len;
    const char *header;   /* the header lines alone, each ending in '\n', no newline inside a line */
    size_t header_len;
    const char *oneline;  /* one line without newline: version, hash, seed, frame, params */
} prov;

void prov_set(const prov *p); /* copies the struct, not the strings; NULL clears */
const prov *prov_get(void);   /* NULL when nothing is set */

/* Append each header line as PREFIX LINE '\n' (e.g. "# ", "comment ").
 * Nothing when no recipe is set. */
void prov_put_lines(bytebuf *out, const char *prefix);
/* Append the header as one XML comment "<!-- frac recipe\nLINES-->\n",
 * with each "--" inside written as "-\x2d" (the recipe's own escape, so
 * reading it back gives the same text). Nothing when no recipe is set. */
void prov_put_xml_comment(bytebuf *out);

#endif
