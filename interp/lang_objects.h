/* lang_objects.h — engine objects shared by several bindings: volumes,
 * meshes, colour ramps. Each binding file (bind_*.c) wraps runtime objects
 * with these helpers so every engine's output can be saved, sliced and
 * printed the same way. */
#ifndef LANG_OBJECTS_H
#define LANG_OBJECTS_H

#include "camera.h"
#include "mesh.h"
#include "rt.h"
#include "ramp.h"
#include "state.h"
#include "volume.h"

extern const obj_class lang_volume_class;
extern const obj_class lang_mesh_class;

/* Check the voxel limit and the memory budget, then allocate. */
int lang_volume_new(interp *I, int nx, int ny, int nz, const double lo[3], const double hi[3], volume **out);
int lang_volume_value(interp *I, volume *v, value *out); /* takes ownership */
volume *lang_as_volume(value v);

int lang_mesh_value(interp *I, mesh *m, value *out); /* takes ownership (m malloc'd) */
/* An engine's mesh m (mem_alloc'd) as the builtin's result if c is RT_OK,
 * else m freed with what the engine built and the error reported as `what`
 * (lang_rt_error). Takes m. */
int lang_mesh_finish(interp *I, mesh *m, rt_code c, const rt_error *e, const char *what, value *out);
mesh *lang_as_mesh(value v);

/* A colour ramp from a list of colours (evenly spaced stops) or a table of
 * rows [t, r, g, b] / [t, r, g, b, a]; nil gives grey. */
int lang_get_ramp(interp *I, value v, ramp *out, const char *what);

/* Fields (bind_field.c). lang_field_value wraps a new node (consumes it);
 * lang_to_field gives a new reference to the node of a field, number or
 * volume value (NULL after an error); lang_field_fn compiles a value into
 * a program usable as rt_field_fn (field_prog_fn, ctx = *prog), with
 * lang_field_fn_done(tmp, own) to release what it made. */
struct field;
struct field_prog;
extern const obj_class lang_field_class;
int lang_field_value(interp *I, struct field *f, value *out);
struct field *lang_to_field(interp *I, value v, const char *what);
int lang_field_fn(interp *I, value v, struct field **tmp, struct field_prog **own,
                  const struct field_prog **prog, const char *what);
void lang_field_fn_done(struct field *tmp, struct field_prog *own);

/* Read an optional number/int/bool field of an options record: 1 found,
 * 0 absent, -1 error. */
int lang_opt_num(interp *I, value rec, const char *key, double *out);

/* A camera from a record {eye: [x,y,z], target: [x,y,z], up: [0,1,0],
 * fov: 40} (what orbit() and look_at() return), an argument declared
 * TY_CAMERA (so its keys are already checked). */
int lang_get_camera(interp *I, value v, camera *cam, const char *what);

/* The one default framing (camera_frame_box: azimuth 30°, elevation 20°,
 * fov 40°) of the box lo..hi for a w × h picture; -1 with the error
 * message `fail` (ERR_VALUE) when a corner is not finite. */
int lang_frame_default(interp *I, const double lo[3], const double hi[3], int w, int h, camera *cam,
                       const char *fail);

/* A box lo..hi from two vec3 arguments (messages "WHAT: lo", "WHAT: hi"),
 * lo < hi on every axis. */
int lang_get_box(interp *I, value lo, value hi, double l[3], double h[3], const char *what);

/* A w×h image (lang_image_new) for an engine that also keeps a depth buffer
 * of bytes_per_px per pixel for each worker and one more: the buffers'
 * memory is checked too ("WHAT: the depth buffers needs …"). */
struct image;
int lang_depth_image(interp *I, int w, int h, double bytes_per_px, const char *what, struct image **out);

/* How engines run for this session: threads, Ctrl-C flag, progress bar. */
rt_run lang_run(interp *I);
/* The one map from runtime codes to error kinds (lang_objects.c): RT_ENOMEM ->
 * ERR_MEMORY (exit 70), RT_EIO -> ERR_IO (74), RT_ECANCEL -> ERR_INTERRUPT
 * (130), RT_ELIMIT -> ERR_LIMIT (65), RT_EFORMAT and RT_EINVAL -> ERR_VALUE (65). */
err_kind lang_rt_kind(rt_code c);
/* Turn a runtime failure into a script error of kind lang_rt_kind(c); for
 * RT_ENOMEM the kind says why the allocation hook refused (mem_engine_error:
 * ERR_LIMIT for the memory limit, ERR_MEMORY otherwise). The message is
 * "WHAT: e->msg" ("WHAT: interrupted" for RT_ECANCEL). Returns -1. */
int lang_rt_error(interp *I, rt_code c, const rt_error *e, const char *what);

#endif
