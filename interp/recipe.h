/* recipe.h — the recipe of a run: what every output file carries so that
 * `frac info` can say how it was made and `frac rerun` can make it again
 * (docs/provenance.md has the format and what each file format holds).
 *
 * A recipe is line-based UTF-8 text:
 *
 *   frac-recipe 1
 *   version: 0.1.0
 *   script-path: examples/tour.frac      (as given on the command line)
 *   script-sha256: 64 hex digits         (of the script text)
 *   seed: 1
 *   frame: none | N
 *   frames: A..B:STEP                    (with a frame: the --frames range, for clock)
 *   apng-output: NAME                    (an APNG that `frac apng` assembled from
 *   apng-delay: MS                        frames of this run: the output's file name,
 *   apng-loop: N                          the options, and for each input in order
 *   apng-frame: F NAME                    its frame (a number or none) and file name)
 *   param NAME=TEXT                      (each -D, in the order given)
 *   arg TEXT                             (each of the script's args)
 *   script: N | omitted                  (its length in bytes, or --no-recipe)
 *                                        (a blank line)
 *   the script text, N bytes             (when not omitted)
 *
 * Values are escaped so each stays on its line: `\\` for a backslash,
 * `\n`, `\t`, `\r`, and `\xHH` for the other control bytes. Everything up to
 * and including the `script:` line is the header, which the formats with
 * comments carry. There are no times or host names in it: the same run gives
 * the same recipe, so outputs stay byte-identical.
 *
 * recipe_text builds the text; recipe_install hands it to the runtime's
 * writers (runtime/provenance.h); recipe_parse reads one back, and
 * recipe_find extracts it from a file frac wrote (PNG chunk or comment
 * lines). */
#ifndef RECIPE_H
#define RECIPE_H

#include <stddef.h>
#include <stdint.h>

#include "fileio.h"

typedef struct recipe {
    char *version;
    char *script_path;
    char sha256[65];   /* "" when absent (no script text was hashed) */
    uint64_t seed;
    int frame_given;
    long frame;
    int frames_range;  /* the frames: line was there (frame_given) */
    long frames_a, frames_b, frames_step;
    char *apng_output; /* non-NULL: the recipe of a `frac apng` file */
    long apng_delay, apng_loop;
    int napng;
    long *apng_frame;   /* each input's frame; apng_framed[i] 0: none */
    char *apng_framed;
    char **apng_name;   /* each input's file name, as given to frac apng */
    int nparams;
    char **params;     /* "NAME=TEXT", unescaped */
    int nargs;
    char **args;
    int has_script;    /* 1: script text follows; 0: omitted */
    size_t script_len; /* as the header says (also for header-only copies) */
    char *script;      /* NULL unless the text is present */
} recipe;

/* The recipe text of a run into out; *header_len is where the header ends.
 * With has_script 0 the text is left out (--no-recipe); with script NULL
 * only the header is written (`frac info` of a header-only copy). sha256 ""
 * leaves its line out (a REPL session has no script). oneline (n bytes) receives the one-line form for VTK titles
 * and STL headers: "frac VERSION seed=S sha256=HEX [frame=F] [NAME=TEXT]…". */
void recipe_text(const recipe *r, bytebuf *out, size_t *header_len, char *oneline, size_t n);

/* 1 when a and b are recipes of one run's files (script, its text,
 * version, seed, params, args and the frames range alike; the frame may
 * differ), else 0 with what differs in why. */
int recipe_same_run(const recipe *a, const recipe *b, char *why, size_t whyn);

/* Parse a recipe (header alone or whole). 0, or -1 with a message in err. */
int recipe_parse(const char *text, size_t len, recipe *r, char *err, size_t errn);
void recipe_free(recipe *r);

/* Find the recipe in a file's bytes: PNG (the frac:recipe chunk), or the
 * header in comment lines (`# `, `comment `, an XML comment). *text (rt_malloc'd)
 * gets the recipe text; returns 0 found, 1 none found, -1 error (message in err).
 * A file with only the one-line form (VTK, STL) gives 1 and copies that line
 * into oneline (empty otherwise). */
int recipe_find(const unsigned char *d, size_t n, char **text, size_t *len, char *oneline, size_t on,
                char *err, size_t errn);


/* What recipe_install keeps alive for the writers until recipe_uninstall. */
typedef struct recipe_store {
    bytebuf text;
    char software[64];
    char oneline[256];
} recipe_store;

/* Build r's text and hand it to the runtime's writers (provenance.h):
 * every file written from now on carries it. 0, or -1 out of memory. */
int recipe_install(const recipe *r, recipe_store *st);
void recipe_uninstall(recipe_store *st);

#endif
