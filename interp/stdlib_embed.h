/* stdlib_embed.h — the stdlib/ modules (.frac files) compiled into the binary. */
#ifndef STDLIB_EMBED_H
#define STDLIB_EMBED_H

typedef struct stdlib_module {
    const char *name;   /* "fern" for stdlib/fern.frac */
    const char *source; /* NUL-terminated text */
} stdlib_module;

extern const stdlib_module stdlib_modules[]; /* ends with {NULL, NULL} */

#endif
