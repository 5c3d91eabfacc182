/* show.c — previews in the terminal: show(x) and the REPL's :show.
 *
 * Anything with a picture can be shown: images as they are, volumes by
 * their middle z slice, meshes as a shaded view from an orbit camera, and
 * any class with a preview hook (fields show their z = 0 slice, IFS their
 * attractor). The picture is drawn with 24-bit colour half blocks sized to
 * the terminal width, or greyscale characters under NO_COLOR / TERM=dumb;
 * when stdout is not a terminal nothing is drawn and a one-line note is
 * printed instead.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "builtin.h"
#include "fileio.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "lineedit.h"
#include "raster.h"
#include "termview.h"
#include "volume_io.h"

static int mesh_preview(interp *I, const mesh *m, image **out)
{
    /* frame the mesh: centre of its bounding box, distance from its size */
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < m->nv; i++)
        for (int k = 0; k < 3; k++) {
            double v = m->pos[3 * i + k];
            lo[k] = v < lo[k] ? v : lo[k];
            hi[k] = v > hi[k] ? v : hi[k];
        }
    if (!m->nv)
        lo[0] = lo[1] = lo[2] = hi[0] = hi[1] = hi[2] = 0;
    camera cam;
    camera_frame_box(&cam, lo, hi, 256, 256, 30, 20, 40); /* the one default framing */
    image *im;
    if (lang_image_new(I, 256, 256, &im))
        return -1;
    raster_opts o;
    raster_opts_default(&o);
    rt_run run = lang_run(I);
    rt_error e;
    rt_code rc = raster_render(m, &cam, &o, &run, im, &e);
    if (rc) {
        lang_image_discard(im);
        return lang_rt_error(I, rc, &e, "show");
    }
    *out = im;
    return 0;
}

/* A picture of v (a new image), or -1 with an error. */
static int preview_of(interp *I, value v, image **out, int *owned)
{
    *owned = 0;
    image *im = lang_as_image(v);
    if (im) {
        *out = im;
        return 0;
    }
    *owned = 1;
    volume *vol = lang_as_volume(v);
    if (vol) {
        image *s = mem_alloc(I, sizeof *s);
        if (!s)
            return err_at(I, NULL, ERR_MEMORY, "out of memory");
        size_t n = (size_t)vol->nx * vol->ny * vol->nz;
        double mn = INFINITY, mx = -INFINITY;
        for (size_t i = 0; i < n; i++) {
            mn = vol->v[i] < mn ? vol->v[i] : mn;
            mx = vol->v[i] > mx ? vol->v[i] : mx;
        }
        ramp g = ramp_grey();
        rt_error e;
        if (volume_slice_axis(vol, 2, vol->nz / 2, &g, mn, mx > mn ? mx : mn + 1, s, &e)) {
            mem_free(I, s);
            return lang_rt_error(I, e.code, &e, "show");
        }
        *out = s;
        return 0;
    }
    mesh *m = lang_as_mesh(v);
    if (m)
        return mesh_preview(I, m, out);
    if (v.k == V_OBJ && AS_OBJ(v)->cls->preview)
        return AS_OBJ(v)->cls->preview(I, AS_OBJ(v)->payload, out);
    return err_at(I, NULL, ERR_TYPE, "show: cannot show %s (images, volumes, meshes, fields and IFS can be shown)",
                  val_type_name(v));
}

static int b_show(interp *I, value *a, int n, value *out)
{
    (void)n;
    *out = val_nil();
    image *im;
    int owned;
    if (!isatty(1)) {
        /* not a terminal: say what would have been shown, draw nothing */
        bytebuf b;
        bytebuf_init(&b);
        val_print(I, a[0], &b, 1);
        fprintf(stderr, "show: not a terminal; not drawing %.*s\n", (int)b.len, b.data ? (char *)b.data : "");
        bytebuf_free(&b);
        return 0;
    }
    if (preview_of(I, a[0], &im, &owned))
        return -1;
    termview_opts o;
    memset(&o, 0, sizeof o);
    int width = lineedit_term_width(1);
    long cols = width > 2 ? width - 1 : 1;
    if (a[1].k == V_NUM && builtin_get_int(I, a[1], 1, 10000, &cols, "show: width")) {
        if (owned) {
            lang_image_discard(im);
        }
        return -1;
    }
    o.cols = (int)cols;
    o.max_rows = 60;
    o.color = termview_env_color(getenv("NO_COLOR"), getenv("TERM"));
    fflush(stdout);
    rt_error e;
    rt_code rc = termview_write(1, im, &o, &e);
    if (owned) {
        lang_image_discard(im);
    }
    if (rc)
        return lang_rt_error(I, rc, &e, "show");
    return 0;
}

static const bparam p_show[] = {{"value", "any", NULL}, {"width", "int", "nil"}};
static const builtin show_builtins[] = {
    BUILTIN("show", b_show, p_show,
            "Preview an image, volume (middle slice), mesh (shaded view), field or IFS in the terminal, in 24-bit colour half blocks sized to the terminal (greyscale with NO_COLOR). Does nothing but print a note when stdout is not a terminal."),
};

int bind_show_init(interp *I)
{
    return builtin_register(I, show_builtins, 1);
}
