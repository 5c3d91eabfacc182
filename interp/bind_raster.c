/* bind_raster.c — the Z-buffer rasteriser in the language: rasterize(scene,
 * camera, …) draws meshes and wrinkly surfaces (tessellated for the view)
 * into an image. The engine is runtime/raster.h. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "lang_wrinkly.h"
#include "raster.h"
#include "wrinkly.h"
#include "report.h"

/* ---- rasterising ------------------------------------------------------------------- */

/* Bounding box of a scene item: a mesh's vertices, or a surface's control
 * points widened by the largest |height|. */
static void item_box(value v, double lo[3], double hi[3])
{
    mesh *m = lang_as_mesh(v);
    surf_obj *s = lang_as_surf(v);
    if (m) {
        mesh_grow_box(m, lo, hi);
    } else if (s) {
        double hm = 0;
        for (size_t i = 0; i < (size_t)s->nu * (size_t)s->nv; i++) {
            hm = fmax(hm, fabs(s->pts[i].h));
            for (int d = 0; d < 3; d++) {
                lo[d] = fmin(lo[d], s->pts[i].pos[d] - hm);
                hi[d] = fmax(hi[d], s->pts[i].pos[d] + hm);
            }
        }
        for (int d = 0; d < 3; d++) {
            lo[d] -= hm;
            hi[d] += hm;
        }
    }
}

/* rasterize(scene, camera, size, background, light, ambient, diffuse, flat, unlit, colour, pixel, kmax) */
static int b_rasterize(interp *I, value *a, int n, value *out)
{
    (void)n;
    const char *W = "rasterize";
    value scene = a[0];
    size_t nitems = scene.k == V_LIST ? AS_LIST(scene)->n : 1;
    if (nitems == 0)
        return err_arg(I, 0, ERR_VALUE, "rasterize: the scene list is empty");
    for (size_t i = 0; i < nitems; i++) {
        value it = scene.k == V_LIST ? AS_LIST(scene)->items[i] : scene;
        if (!lang_as_mesh(it) && !lang_as_surf(it))
            return err_item(I, scene, i, ERR_TYPE,
                            "rasterize: the scene must be a mesh, a wrinkly_surface or a list of them, but item %zu is %s",
                            i, val_type_name(it));
    }
    int w, h;
    if (lang_arg_size2(I, a[2], &w, &h, "rasterize: size"))
        return -1;
    raster_opts ro;
    raster_opts_default(&ro);
    if (lang_get_colour(I, a[3], ro.background, "rasterize: background") ||
        lang_get_colour(I, a[9], ro.colour, "rasterize: colour"))
        return -1;
    if (a[4].k != V_NIL) {
        if (builtin_get_vec(I, a[4], ro.light, 3, "rasterize: light"))
            return -1;
        if (ro.light[0] == 0 && ro.light[1] == 0 && ro.light[2] == 0)
            return err_arg(I, 4, ERR_VALUE, "rasterize: light must be a direction toward the light, not [0, 0, 0]");
    }
    ro.ambient = a[5].u.n;
    ro.diffuse = a[6].u.n;
    ro.flat = a[7].u.b;
    ro.unlit = a[8].u.b;
    lod l;
    if (lang_get_lod(I, val_nil(), val_nil(), a[11], -1, &l, W))
        return -1;
    camera cam;
    if (a[1].k != V_NIL) {
        if (lang_get_camera(I, a[1], &cam, W))
            return -1;
    } else {
        /* frame the scene's box: the one default framing (camera.h) */
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < nitems; i++)
            item_box(scene.k == V_LIST ? AS_LIST(scene)->items[i] : scene, lo, hi);
        for (int d = 0; d < 3; d++)
            if (!(hi[d] >= lo[d]))
                lo[d] = hi[d] = 0;
        if (lang_frame_default(I, lo, hi, w, h, &cam, "rasterize: cannot frame the scene"))
            return -1;
    }
    /* one mesh to draw: a mesh as given, or the tessellations (LOD from this
     * camera) and meshes merged in order */
    mesh *single = nitems == 1 ? lang_as_mesh(scene.k == V_LIST ? AS_LIST(scene)->items[0] : scene) : NULL;
    mesh *merged = NULL;
    int rc = -1;
    image *im = NULL;
    if (!single) {
        int normals = 1;
        double tv = 0;
        for (size_t i = 0; i < nitems; i++) {
            mesh *m = lang_as_mesh(scene.k == V_LIST ? AS_LIST(scene)->items[i] : scene);
            if (m && !m->nrm && m->nt)
                normals = 0;
            tv += m ? (double)m->nv : 0;
        }
        merged = mem_alloc(I, sizeof *merged);
        if (!merged)
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        mesh_init(merged, normals, 1);
        for (size_t i = 0; i < nitems; i++) {
            value it = scene.k == V_LIST ? AS_LIST(scene)->items[i] : scene;
            mesh *m = lang_as_mesh(it), *t = NULL;
            if (!m) {
                if (lang_surf_mesh(I, lang_as_surf(it), &cam, w, h, a[10].u.n, &l, &t, W))
                    goto done;
                m = t;
            }
            tv += t ? (double)t->nv : 0;
            if (tv >= 4294967295.0 || tv > I->lim.max_points) {
                if (t) {
                    mesh_free(t);
                    mem_free(I, t);
                }
                err_at(I, NULL, ERR_LIMIT,
                       "rasterize: the scene has more than %.0f vertices (raise it with --max-points)",
                       fmin(I->lim.max_points, 4294967294.0));
                goto done;
            }
            mesh_append(merged, m, ro.colour);
            if (t) {
                mesh_free(t);
                mem_free(I, t);
            }
            if (merged->failed) {
                err_at(I, NULL, ERR_MEMORY, "out of memory merging the scene");
                goto done;
            }
        }
        single = merged;
    }
    if (lang_image_new(I, w, h, &im))
        goto done;
    rt_run run = lang_run(I);
    rt_error e;
    double t0 = report_clock();
    rt_code c = raster_render(single, &cam, &ro, &run, im, &e);
    if (!c)
        report_work(I, "rasterize", "pixels", (double)w * h, t0);
    if (c) {
        lang_rt_error(I, c, &e, W);
        goto done;
    }
    rc = lang_image_value(I, im, out);
    im = NULL;
done:
    lang_image_discard(im);
    if (merged) {
        mesh_free(merged);
        mem_free(I, merged);
    }
    return rc;
}

/* ---- the default framing as a camera record ------------------------------------------- */

/* framing(lo, hi, size, azimuth, elevation, fov): the camera every default
 * view uses (camera_frame_box), as a record {eye, target, up, fov} */
static int b_framing(interp *I, value *a, int n, value *out)
{
    (void)n;
    double lo[3], hi[3];
    int w, h;
    if (builtin_get_vec(I, a[0], lo, 3, "framing: lo") || builtin_get_vec(I, a[1], hi, 3, "framing: hi") ||
        lang_arg_size2(I, a[2], &w, &h, "framing: size"))
        return -1;
    for (int d = 0; d < 3; d++)
        if (hi[d] < lo[d])
            return err_arg(I, 1, ERR_VALUE, "framing: hi must not be below lo, but on axis %c %g < %g", "xyz"[d], hi[d],
                           lo[d]);
    camera cam;
    if (camera_frame_box(&cam, lo, hi, w, h, a[3].u.n, a[4].u.n, a[5].u.n))
        return err_arg(I, 4, ERR_VALUE, "framing: elevation %g looks straight along the up axis [0, 1, 0]", a[4].u.n);
    value r = val_rec(I);
    if (r.k == V_NIL)
        return -1;
    const char *keys[3] = {"eye", "target", "up"};
    const double *vals[3] = {cam.eye, cam.target, cam.up};
    for (int i = 0; i < 4; i++) {
        const char *k = interp_intern(I, i < 3 ? keys[i] : "fov", i < 3 ? strlen(keys[i]) : 3);
        value v = val_num(cam.fov);
        if (!k || (i < 3 && lang_num_list_value(I, vals[i], 3, &v)) || val_rec_set(I, AS_REC(r), k, v)) {
            val_unref(I, r);
            return -1;
        }
    }
    *out = r;
    return 0;
}

/* ---- registration ---------------------------------------------------------------------- */

static const bparam p_raster[] = {{"scene", "mesh|wrinkly_surface|list", NULL},
                                  {"camera", TY_CAMERA, "nil"},
                                  {"size", TY_SIZE, "[256, 256]"},
                                  {"background", TY_COLOUR, "0"},
                                  {"light", "vec3", "nil"},
                                  {"ambient", "num>=0", "0.2"},
                                  {"diffuse", "num>=0", "0.8"},
                                  {"flat", "bool", "false"},
                                  {"unlit", "bool", "false"},
                                  {"colour", TY_COLOUR, "1"},
                                  {"pixel", "num>0", "1"},
                                  {"kmax", TY_LOD_K, "8"}};

static const bparam p_framing[] = {{"lo", "vec3", NULL},
                                 {"hi", "vec3", NULL},
                                 {"size", TY_SIZE, "[256, 256]"},
                                 {"azimuth", "num", "30"},
                                 {"elevation", "num[-89.9,89.9]", "20"},
                                 {"fov", "num(0,179)", "40"}};

static const builtin raster_builtins[] = {
    BUILTIN("rasterize", b_rasterize, p_raster,
            "Render a mesh, a wrinkly surface or a list of them with a Z-buffer into an image: camera (default: framing the scene), lights, background; surfaces are tessellated for this camera."),
    BUILTIN("framing", b_framing, p_framing,
            "The default camera of view, rasterize and chaos_fset in 3-D for the box [lo, hi] and an image of size: looking at the box's centre from azimuth/elevation (degrees, as orbit) and far enough that the box's bounding sphere plus 5 % fits the field of view. Returns a record {eye, target, up, fov}."),
};

int bind_raster_init(interp *I)
{
    return BUILTIN_REGISTER(I, raster_builtins);
}
