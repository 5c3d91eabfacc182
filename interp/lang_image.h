/* lang_image.h — images as language values (shared by engine bindings). */
#ifndef LANG_IMAGE_H
#define LANG_IMAGE_H

#include "image.h"
#include "state.h"

extern const obj_class lang_image_class;

/* Allocate an image after checking the pixel limit. */
int lang_image_new(interp *I, int w, int h, image **out);
/* Wrap (takes ownership). */
int lang_image_value(interp *I, image *im, value *out);
image *lang_as_image(value v);
/* A colour from a grey number, [r,g,b], [r,g,b,a] or "#rrggbb[aa]". */
int lang_get_colour(interp *I, value v, float rgba[4], const char *what);
/* Free an image made by lang_image_new that was not wrapped (NULL: nothing). */
void lang_image_discard(image *im);
/* The usual end of a builtin that rendered into im: on failure (c != RT_OK)
 * discard im and report "WHAT: message"; otherwise wrap im into *out. */
int lang_image_finish(interp *I, image *im, rt_code c, const rt_error *e, const char *what, value *out);
/* Join a relative output path with --out-dir. */
int lang_output_path(interp *I, value path, char *buf, size_t size);

#endif
