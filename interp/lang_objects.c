/* lang_objects.c — the helpers every binding uses (lang_objects.h): colour
 * ramps, option numbers, cameras, how engines run for this session and the
 * one map from runtime codes to script errors. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "builtin.h"
#include "lang_image.h"
#include "lang_objects.h"

/* ---- colour ramps -------------------------------------------------------------- */

int lang_get_ramp(interp *I, value v, ramp *out, const char *what)
{
    if (v.k == V_NIL) {
        *out = ramp_grey();
        return 0;
    }
    if (v.k != V_LIST || AS_LIST(v)->n < 1 || AS_LIST(v)->n > RAMP_MAX_STOPS)
        return err_value(I, v, ERR_TYPE,
                      "%s must be a palette: a list of 1 to %d colours [r, g, b], or rows [t, r, g, b]",
                      what, RAMP_MAX_STOPS);
    vlist *l = AS_LIST(v);
    memset(out, 0, sizeof *out);
    out->n = (int)l->n;
    double prev = -INFINITY;
    for (size_t i = 0; i < l->n; i++) {
        double c[5] = {0, 0, 0, 0, 1};
        value it = l->items[i];
        size_t k = it.k == V_LIST ? AS_LIST(it)->n : 0;
        if (k == 3) {
            if (builtin_get_vec(I, it, c + 1, 3, what))
                return -1;
            c[0] = l->n == 1 ? 0 : (double)i / (double)(l->n - 1);
        } else if (k == 4 || k == 5) {
            if (builtin_get_vec(I, it, c, k, what))
                return -1;
            if (k == 4)
                c[4] = 1;
        } else {
            return err_item(I, v, i, ERR_VALUE,
                            "%s: stop %zu must be [r, g, b] or [t, r, g, b] or [t, r, g, b, a], got %s", what, i + 1,
                            it.k == V_LIST ? "a list of another length" : val_type_name(it));
        }
        if (c[0] < prev)
            return err_item(I, v, i, ERR_VALUE, "%s: stop positions must not decrease (stop %zu at %g after %g)",
                            what, i + 1, c[0], prev);
        prev = c[0];
        out->pos[i] = c[0];
        for (int j = 0; j < 4; j++)
            out->rgba[i][j] = (float)c[j + 1];
    }
    return 0;
}

int lang_opt_num(interp *I, value rec, const char *key, double *out)
{
    if (rec.k != V_REC)
        return 0;
    const char *k = interp_intern(I, key, strlen(key));
    value *v = k ? val_rec_get(AS_REC(rec), k) : NULL;
    if (!v)
        return 0;
    if (v->k == V_NUM) {
        *out = v->u.n;
        return 1;
    }
    if (v->k == V_BOOL) {
        *out = v->u.b;
        return 1;
    }
    return err_at(I, NULL, ERR_TYPE, "option '%s' must be a number, got %s", key, val_type_name(*v));
}

rt_run lang_run(interp *I)
{
    rt_run r;
    r.threads = I->threads > 0 ? I->threads : 1;
    r.cancel = I->interrupt;
    r.progress = I->progress && !I->quiet;
    return r;
}

err_kind lang_rt_kind(rt_code c)
{
    switch (c) {
    case RT_ENOMEM: return ERR_MEMORY;
    case RT_EIO: return ERR_IO;
    case RT_ECANCEL: return ERR_INTERRUPT;
    case RT_ELIMIT: return ERR_LIMIT;
    case RT_OK: /* not a failure; callers never pass it */
    case RT_EFORMAT:
    case RT_EINVAL: break;
    }
    return ERR_VALUE;
}

int lang_rt_error(interp *I, rt_code c, const rt_error *e, const char *what)
{
    err_kind k = lang_rt_kind(c);
    if (c == RT_ENOMEM) /* why the allocation hook refused: limit, --fail-alloc or the system */
        return mem_engine_error(I, what, e->msg);
    if (c == RT_ECANCEL)
        return err_at(I, NULL, k, "%s: interrupted", what);
    return err_at(I, NULL, k, "%s: %s", what, e->msg);
}

/* ---- cameras ------------------------------------------------------------------------ */

/* A camera record as TY_CAMERA declares it (checked before the builtin
 * runs: eye and target present, 3 finite numbers each, fov in (0, 179)). */
static void rec_vec3(interp *I, value rec, const char *key, double out[3])
{
    const char *k = interp_intern(I, key, strlen(key));
    value *v = k ? val_rec_get(AS_REC(rec), k) : NULL;
    if (v)
        for (int i = 0; i < 3; i++)
            out[i] = AS_LIST(*v)->items[i].u.n;
}

int lang_get_camera(interp *I, value v, camera *cam, const char *what)
{
    memset(cam, 0, sizeof *cam);
    cam->up[1] = 1;
    cam->fov = 40;
    rec_vec3(I, v, "eye", cam->eye);
    rec_vec3(I, v, "target", cam->target);
    rec_vec3(I, v, "up", cam->up);
    double fov;
    if (lang_opt_num(I, v, "fov", &fov) == 1)
        cam->fov = fov;
    if (camera_setup(cam))
        return err_item(I, v, SIZE_MAX, ERR_VALUE, "%s: camera eye equals target, or up is parallel to the view",
                        what);
    return 0;
}

int lang_frame_default(interp *I, const double lo[3], const double hi[3], int w, int h, camera *cam,
                       const char *fail)
{
    if (camera_frame_box(cam, lo, hi, w, h, 30, 20, 40))
        return err_at(I, NULL, ERR_VALUE, "%s", fail);
    return 0;
}

int lang_depth_image(interp *I, int w, int h, double bytes_per_px, const char *what, image **out)
{
    char m[96];
    snprintf(m, sizeof m, "%s: the depth buffers", what);
    if (lang_image_new(I, w, h, out))
        return -1;
    if (mem_precheck(I, (double)w * h * bytes_per_px * (I->threads + 1), m)) {
        lang_image_discard(*out);
        *out = NULL;
        return -1;
    }
    return 0;
}

int lang_get_box(interp *I, value lo, value hi, double l[3], double h[3], const char *what)
{
    char w[128];
    snprintf(w, sizeof w, "%s: lo", what);
    if (builtin_get_vec(I, lo, l, 3, w))
        return -1;
    snprintf(w, sizeof w, "%s: hi", what);
    if (builtin_get_vec(I, hi, h, 3, w))
        return -1;
    for (int i = 0; i < 3; i++)
        if (!(h[i] > l[i]))
            return err_at(I, NULL, ERR_VALUE, "%s: the box needs lo < hi on every axis (axis %d: %g, %g)", what, i,
                          l[i], h[i]);
    return 0;
}
