/* bind_volume.c — volumes and meshes as language values: summaries, fields,
 * saving by extension, loading, slices and mesh statistics. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "fileio.h"
#include "lang_image.h"
#include "lang_objects.h"
#include "mesh_io.h"
#include "vdb.h"
#include "volume_io.h"

/* ---- cameras ------------------------------------------------------------------------ */

static int camera_record(interp *I, const double eye[3], const double target[3], const double up[3], double fov,
                         value *out)
{
    value r = val_rec(I);
    if (r.k == V_NIL)
        return -1;
    const char *names[3] = {"eye", "target", "up"};
    const double *vals[3] = {eye, target, up};
    for (int i = 0; i < 3; i++) {
        value l = val_list(I, 3);
        if (l.k == V_NIL)
            goto fail;
        for (int j = 0; j < 3; j++)
            if (val_list_push(I, AS_LIST(l), val_num(vals[i][j]))) {
                val_unref(I, l);
                goto fail;
            }
        if (val_rec_set(I, AS_REC(r), interp_intern(I, names[i], strlen(names[i])), l))
            goto fail;
    }
    if (val_rec_set(I, AS_REC(r), interp_intern(I, "fov", 3), val_num(fov)))
        goto fail;
    *out = r;
    return 0;
fail:
    val_unref(I, r);
    return -1;
}

static int b_orbit(interp *I, value *a, int n, value *out)
{
    (void)n;
    double target[3];
    if (builtin_get_vec(I, a[3], target, 3, "orbit: target"))
        return -1;
    camera c;
    camera_orbit(&c, target, a[2].u.n, a[0].u.n, a[1].u.n, a[4].u.n);
    return camera_record(I, c.eye, c.target, c.up, a[4].u.n, out);
}

static int b_look_at(interp *I, value *a, int n, value *out)
{
    (void)n;
    double eye[3], target[3], up[3];
    if (builtin_get_vec(I, a[0], eye, 3, "look_at: eye") || builtin_get_vec(I, a[1], target, 3, "look_at: target") ||
        builtin_get_vec(I, a[2], up, 3, "look_at: up"))
        return -1;
    return camera_record(I, eye, target, up, a[3].u.n, out);
}

/* ---- volumes ------------------------------------------------------------------------ */

typedef struct vol_payload {
    volume v;
} vol_payload;

static void volume_destroy(void *p)
{
    vol_payload *vp = p;
    volume_free(&vp->v);
    rt_free(vp);
}

static void volume_summary(const void *p, bytebuf *out)
{
    const volume *v = &((const vol_payload *)p)->v;
    size_t n = (size_t)v->nx * v->ny * v->nz;
    double mn = INFINITY, mx = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        mn = v->v[i] < mn ? v->v[i] : mn;
        mx = v->v[i] > mx ? v->v[i] : mx;
    }
    bytebuf_printf(out, "volume %d×%d×%d over [%g, %g]×[%g, %g]×[%g, %g], values %g to %g", v->nx, v->ny,
                   v->nz, v->lo[0], v->hi[0], v->lo[1], v->hi[1], v->lo[2], v->hi[2], mn, mx);
}

static int volume_get(interp *I, const void *p, const char *name, value *out)
{
    const volume *v = &((const vol_payload *)p)->v;
    if (strcmp(name, "size") == 0) {
        double s[3] = {v->nx, v->ny, v->nz};
        return lang_num_list_value(I, s, 3, out);
    }
    if (strcmp(name, "lo") == 0)
        return lang_num_list_value(I, v->lo, 3, out);
    if (strcmp(name, "hi") == 0)
        return lang_num_list_value(I, v->hi, 3, out);
    return 1;
}

static int save_type(interp *I, value opts, int vdb, int *type)
{
    double bits = 32;
    /* `grids` (extra named grids) exists only in .vdb files */
    if (contract_check_opts(I, opts, vdb ? "rec{bits: int{8,16,32}, grids: rec}" : "rec{bits: int{8,16,32}}", "save") ||
        lang_opt_num(I, opts, "bits", &bits) < 0)
        return -1;
    if (bits == 8)
        *type = VIO_UCHAR;
    else if (bits == 16)
        *type = VIO_USHORT;
    else if (bits == 32)
        *type = VIO_FLOAT;
    else
        return err_at(I, NULL, ERR_VALUE, "save: bits must be 8, 16 or 32 (float) for a volume, got %g", bits);
    return 0;
}

/* save(v, "x.vdb", {grids: {temperature: t, color: [r, g, b]}}): v is the
 * grid "density"; each extra grid is a volume (float grid) or a list of 3
 * (vec3 grid). */
static int volume_save_vdb(interp *I, const volume *v, const char *path, value opts, int type, rt_error *e,
                           rt_code *c)
{
    *c = RT_OK;
    if (type != VIO_FLOAT)
        return err_at(I, NULL, ERR_VALUE, "save: .vdb volumes are written as 32-bit float (drop the bits option)");
    vdb_grid g[16] = {{"density", 1, {v, NULL, NULL}}};
    int n = 1;
    value *gr = NULL;
    const char *k = opts.k == V_REC ? interp_intern(I, "grids", 5) : NULL;
    if (k && (gr = val_rec_get(AS_REC(opts), k)) && gr->k != V_REC)
        return err_at(I, NULL, ERR_TYPE, "save: option 'grids' must be a record {name: volume}, got %s",
                      val_type_name(*gr));
    for (size_t i = 0; gr && i < AS_REC(*gr)->n; i++, n++) {
        value x = AS_REC(*gr)->vals[i];
        if (n == 16)
            return err_at(I, NULL, ERR_VALUE, "save: at most 15 extra grids in a .vdb file");
        g[n] = (vdb_grid){AS_REC(*gr)->keys[i], 1, {lang_as_volume(x), NULL, NULL}};
        if (x.k == V_LIST && AS_LIST(x)->n == 3) {
            g[n].channels = 3;
            for (int j = 0; j < 3; j++)
                g[n].vol[j] = lang_as_volume(AS_LIST(x)->items[j]);
        }
        for (int j = 0; j < g[n].channels; j++)
            if (!g[n].vol[j])
                return err_at(I, NULL, ERR_TYPE,
                              "save: grid '%s' must be a volume or a list of 3 volumes [r, g, b], got %s",
                              g[n].name, val_type_name(x));
    }
    *c = vdb_save(path, g, n, 0, e);
    return 0;
}

static int volume_save(interp *I, const void *p, const char *path, value opts)
{
    const volume *v = &((const vol_payload *)p)->v;
    char ext[16];
    fileio_ext(path, ext, sizeof ext);
    int type = VIO_FLOAT;
    if (save_type(I, opts, strcmp(ext, "vdb") == 0, &type))
        return -1;
    rt_error e;
    rt_code c;
    if (strcmp(ext, "nrrd") == 0) {
        c = vio_save_nrrd(path, v, type, &e);
    } else if (strcmp(ext, "nhdr") == 0 || strcmp(ext, "raw") == 0) {
        /* a raw file with a detached NRRD header beside it */
        char base[4096], nhdr[4200], raw[4200];
        snprintf(base, sizeof base, "%.*s", (int)(strlen(path) - strlen(ext) - 1), path);
        snprintf(nhdr, sizeof nhdr, "%s.nhdr", base);
        snprintf(raw, sizeof raw, "%s.raw", base);
        c = vio_save_nhdr(nhdr, raw, v, type, &e);
    } else if (strcmp(ext, "vtk") == 0) {
        if (type != VIO_FLOAT)
            return err_at(I, NULL, ERR_VALUE, "save: VTK volumes are written as float (drop the bits option)");
        c = vio_save_vtk(path, v, &e);
    } else if (strcmp(ext, "vdb") == 0) {
        if (volume_save_vdb(I, v, path, opts, type, &e, &c))
            return -1;
    } else {
        return err_at(I, NULL, ERR_VALUE,
                      "save: cannot save a volume as '.%s' (use .nrrd, .nhdr/.raw, .vtk or .vdb)", ext);
    }
    if (c)
        return lang_rt_error(I, c, &e, "save");
    return 0;
}

const obj_class lang_volume_class = {
    .name = "volume",
    .destroy = volume_destroy,
    .summary = volume_summary,
    .get = volume_get,
    .save = volume_save,
};

static int volume_checks(interp *I, int nx, int ny, int nz, const double lo[3], const double hi[3])
{
    double voxels = (double)nx * ny * nz;
    if (nx < 1 || ny < 1 || nz < 1)
        return err_at(I, NULL, ERR_VALUE, "volume size %d×%d×%d must be at least 1 on each axis", nx, ny, nz);
    if (voxels > I->lim.max_voxels)
        return err_at(I, NULL, ERR_LIMIT,
                      "volume of %d×%d×%d voxels exceeds the limit of %.0f voxels (raise it with --max-voxels)",
                      nx, ny, nz, I->lim.max_voxels);
    for (int i = 0; i < 3; i++)
        if (!(hi[i] > lo[i]) || !isfinite(lo[i]) || !isfinite(hi[i]))
            return err_at(I, NULL, ERR_VALUE, "volume bounds must have lo < hi on every axis");
    return 0;
}

int lang_volume_new(interp *I, int nx, int ny, int nz, const double lo[3], const double hi[3], volume **out)
{
    *out = NULL;
    if (volume_checks(I, nx, ny, nz, lo, hi) ||
        mem_precheck(I, (double)nx * ny * nz * sizeof(float), "the volume"))
        return -1;
    vol_payload *vp = mem_calloc(I, 1, sizeof *vp);
    rt_error e;
    if (!vp || volume_init(&vp->v, nx, ny, nz, lo, hi, &e)) {
        mem_free(I, vp);
        return err_at(I, NULL, ERR_MEMORY, "out of memory for a %d×%d×%d volume", nx, ny, nz);
    }
    *out = &vp->v;
    return 0;
}

/* A volume value that takes over tmp's samples (a loader's result: no
 * second copy); tmp is emptied either way. */
static int volume_adopt(interp *I, volume *tmp, value *out)
{
    vol_payload *vp = NULL;
    if (!volume_checks(I, tmp->nx, tmp->ny, tmp->nz, tmp->lo, tmp->hi) && !(vp = mem_calloc(I, 1, sizeof *vp)) &&
        !I->err.active)
        err_at(I, NULL, ERR_MEMORY, "out of memory");
    if (!vp) {
        volume_free(tmp);
        return -1;
    }
    vp->v = *tmp;
    tmp->v = NULL;
    return lang_volume_value(I, &vp->v, out);
}

int lang_volume_value(interp *I, volume *v, value *out)
{
    /* v is the first member of its payload */
    *out = val_obj(I, &lang_volume_class, v);
    return out->k == V_NIL ? -1 : 0;
}

volume *lang_as_volume(value v)
{
    return v.k == V_OBJ && AS_OBJ(v)->cls == &lang_volume_class ? &((vol_payload *)AS_OBJ(v)->payload)->v : NULL;
}

/* ---- meshes --------------------------------------------------------------------------- */

static void mesh_destroy(void *p)
{
    mesh_free(p);
    rt_free(p);
}

static void mesh_summary(const void *p, bytebuf *out)
{
    const mesh *m = p;
    if (m->nt == 0)
        bytebuf_printf(out, "point cloud: %zu points", m->nv);
    else
        bytebuf_printf(out, "mesh: %zu vertices, %zu triangles%s%s", m->nv, m->nt, m->nrm ? ", normals" : "",
                       m->col ? ", colours" : "");
}

static int mesh_get(interp *I, const void *p, const char *name, value *out)
{
    const mesh *m = p;
    if (strcmp(name, "vertices") == 0)
        *out = val_num((double)m->nv);
    else if (strcmp(name, "triangles") == 0)
        *out = val_num((double)m->nt);
    else if (strcmp(name, "lo") == 0 || strcmp(name, "hi") == 0) {
        /* the bounding box corners (nil for an empty mesh) */
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        mesh_grow_box(m, lo, hi);
        if (m->nv == 0)
            *out = val_nil();
        else
            return lang_num_list_value(I, name[0] == 'h' ? hi : lo, 3, out);
    } else
        return 1;
    return 0;
}

static int mesh_save_hook(interp *I, const void *p, const char *path, value opts)
{
    const mesh *m = p;
    char ext[16];
    fileio_ext(path, ext, sizeof ext);
    double ascii = 0;
    if (contract_check_opts(I, opts, "rec{ascii: bool}", "save") || lang_opt_num(I, opts, "ascii", &ascii) < 0)
        return -1;
    rt_error e;
    rt_code c;
    if (strcmp(ext, "ply") == 0)
        c = mio_save_ply(path, m, ascii != 0, &e);
    else if (strcmp(ext, "obj") == 0 || strcmp(ext, "stl") == 0)
        c = mio_save(path, m, &e);
    else
        return err_at(I, NULL, ERR_VALUE, "save: cannot save a mesh as '.%s' (use .ply, .obj or .stl)", ext);
    if (c)
        return lang_rt_error(I, c, &e, "save");
    return 0;
}

const obj_class lang_mesh_class = {
    .name = "mesh",
    .destroy = mesh_destroy,
    .summary = mesh_summary,
    .get = mesh_get,
    .save = mesh_save_hook,
};

int lang_mesh_value(interp *I, mesh *m, value *out)
{
    if (m->failed) {
        mesh_destroy(m);
        return err_at(I, NULL, ERR_MEMORY, "out of memory building a mesh");
    }
    *out = val_obj(I, &lang_mesh_class, m);
    return out->k == V_NIL ? -1 : 0;
}

int lang_mesh_finish(interp *I, mesh *m, rt_code c, const rt_error *e, const char *what, value *out)
{
    if (c) {
        mesh_destroy(m);
        return lang_rt_error(I, c, e, what);
    }
    return lang_mesh_value(I, m, out);
}

mesh *lang_as_mesh(value v)
{
    return v.k == V_OBJ && AS_OBJ(v)->cls == &lang_mesh_class ? AS_OBJ(v)->payload : NULL;
}

/* ---- builtins ----------------------------------------------------------------------------- */

/* A float grid as a volume, a vec3 grid as a list of 3 volumes [r, g, b]. */
static int load_vdb(interp *I, const char *path, value grid, value *out)
{
    volume tmp[3];
    int ch = 0;
    rt_error e;
    rt_code c = vdb_load(path, grid.k == V_STR ? AS_STR(grid)->s : NULL, I->lim.max_voxels, tmp, &ch, &e);
    if (c)
        return lang_rt_error(I, c, &e, "load_volume"); /* the one map of runtime codes to error kinds */
    value l = ch == 3 ? val_list(I, 3) : val_nil();
    int rc = ch == 3 && l.k == V_NIL ? -1 : 0;
    for (int i = 0; i < ch && !rc; i++) {
        value x;
        rc = volume_adopt(I, &tmp[i], ch == 3 ? &x : out) || (ch == 3 && val_list_push(I, AS_LIST(l), x));
    }
    for (int i = 0; i < ch; i++)
        volume_free(&tmp[i]);
    if (ch == 3) {
        if (rc)
            val_unref(I, l);
        else
            *out = l;
    }
    return rc ? -1 : 0;
}

static int b_load_volume(interp *I, value *a, int n, value *out)
{
    (void)n;
    char path[4096], ext[16];
    if (lang_script_path(I, a[0], path, sizeof path, "load_volume"))
        return -1;
    fileio_ext(path, ext, sizeof ext);
    if (strcmp(ext, "vdb") == 0)
        return load_vdb(I, path, a[1], out);
    if (a[1].k != V_NIL)
        return err_at(I, NULL, ERR_VALUE, "load_volume: only .vdb files have named grids (drop grid:)");
    volume tmp;
    rt_error e;
    rt_code c = strcmp(ext, "vtk") == 0 ? vio_load_vtk(path, &tmp, &e) : vio_load_nrrd(path, &tmp, &e);
    if (c)
        return lang_rt_error(I, c, &e, "load_volume");
    return volume_adopt(I, &tmp, out);
}

static int b_load_mesh(interp *I, value *a, int n, value *out)
{
    (void)n;
    char path[4096];
    if (lang_script_path(I, a[0], path, sizeof path, "load_mesh"))
        return -1;
    mesh *m = mem_alloc(I, sizeof *m);
    if (!m)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    rt_error e;
    rt_code c = mio_load(path, m, &e);
    if (c) {
        mesh_free(m); /* what the reader built before it failed (mesh_io.h) */
        mem_free(I, m);
        return lang_rt_error(I, c, &e, "load_mesh");
    }
    return lang_mesh_value(I, m, out);
}

static int b_mesh_stats(interp *I, value *a, int n, value *out)
{
    (void)n;
    mesh_stats st;
    rt_error e;
    if (mesh_compute_stats(lang_as_mesh(a[0]), &st, &e))
        return err_at(I, NULL, ERR_MEMORY, "%s", e.msg);
    value r = val_rec(I);
    if (r.k == V_NIL)
        return -1;
    const struct {
        const char *k;
        double v;
    } f[] = {{"vertices", (double)st.vertices},
             {"triangles", (double)st.triangles},
             {"edges", (double)st.edges},
             {"boundary_edges", (double)st.boundary_edges},
             {"nonmanifold_edges", (double)st.nonmanifold_edges},
             {"degenerate", (double)st.degenerate},
             {"euler", (double)st.euler},
             {"area", st.area},
             {"volume", st.volume},
             {"watertight", st.boundary_edges == 0 && st.nonmanifold_edges == 0 && st.triangles > 0}};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; i++) {
        const char *k = interp_intern(I, f[i].k, strlen(f[i].k));
        value v = i == 9 ? val_bool(f[i].v != 0) : val_num(f[i].v);
        if (!k || val_rec_set(I, AS_REC(r), k, v)) {
            val_unref(I, r);
            return -1;
        }
    }
    *out = r;
    return 0;
}

static int b_slice(interp *I, value *a, int n, value *out)
{
    (void)n;
    volume *v = lang_as_volume(a[0]);
    int axis = AS_STR(a[1])->s[0] - 'x'; /* declared str{x,y,z} */
    int len = axis == 0 ? v->nx : axis == 1 ? v->ny : v->nz;
    long index = len / 2;
    if (a[2].k != V_NIL && builtin_get_int(I, a[2], 0, len - 1, &index, "slice: index"))
        return -1;
    ramp r;
    if (lang_get_ramp(I, a[3], &r, "slice: palette"))
        return -1;
    double lo = a[4].u.n, hi = a[5].u.n;
    if (a[4].k == V_NIL || a[5].k == V_NIL) {
        /* default: the volume's own range */
        size_t cnt = (size_t)v->nx * v->ny * v->nz;
        double mn = INFINITY, mx = -INFINITY;
        for (size_t i = 0; i < cnt; i++) {
            mn = v->v[i] < mn ? v->v[i] : mn;
            mx = v->v[i] > mx ? v->v[i] : mx;
        }
        if (a[4].k == V_NIL)
            lo = mn;
        if (a[5].k == V_NIL)
            hi = mx > lo ? mx : lo + 1;
    }
    image *im = mem_alloc(I, sizeof *im);
    if (!im)
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    rt_error e;
    rt_code c = volume_slice_axis(v, axis, (int)index, &r, lo, hi, im, &e);
    if (c) {
        mem_free(I, im);
        return lang_rt_error(I, c, &e, "slice"); /* out of memory is 70, not a bad value */
    }
    return lang_image_value(I, im, out);
}

static const bparam p_path[] = {{"path", "str", NULL}};
static const bparam p_load_volume[] = {{"path", "str", NULL}, {"grid", "str", "nil"}};
static const bparam p_mesh[] = {{"mesh", "mesh", NULL}};
static const bparam p_slice[] = {{"volume", "volume", NULL}, {"axis", "str{x,y,z}", "\"z\""}, {"index", "int", "nil"},
                                 {"palette", "list", "nil"},  {"lo", "num", "nil"},    {"hi", "num", "nil"}};

static const bparam p_orbit[] = {{"azimuth", "num", "30"}, {"elevation", "num(-90,90)", "20"}, {"distance", "num>0", "3"},
                                 {"target", "vec3", "[0, 0, 0]"}, {"fov", "num(0,179)", "40"}};
static const bparam p_look_at[] = {{"eye", "vec3", NULL}, {"target", "vec3", "[0, 0, 0]"}, {"up", "vec3", "[0, 1, 0]"},
                                   {"fov", "num(0,179)", "40"}};

static const builtin volume_builtins[] = {
    BUILTIN("orbit", b_orbit, p_orbit,
            "A camera looking at `target` from `distance`, turned `azimuth` degrees around +y (0: from +z) and raised `elevation` degrees; fov is the vertical field of view. Returns a record {eye, target, up, fov}."),
    BUILTIN("look_at", b_look_at, p_look_at, "A camera at `eye` looking at `target` (a record {eye, target, up, fov})."),
    BUILTIN("load_volume", b_load_volume, p_load_volume,
            "Load a volume from .nrrd, .nhdr, .vtk or .vdb (relative to the script); grid: the .vdb grid (default \"density\")."),
    BUILTIN("load_mesh", b_load_mesh, p_path, "Load a mesh from .ply, .obj or .stl (relative to the script)."),
    BUILTIN("mesh_stats", b_mesh_stats, p_mesh,
            "Topology of a mesh: {vertices, triangles, edges, boundary_edges, nonmanifold_edges, degenerate, euler, area, volume, watertight}; volume is signed: Σ a·(b×c)/6 over the triangles, negative for a closed mesh wound inside out."),
    BUILTIN("slice", b_slice, p_slice,
            "An axis-aligned slice of a volume as an image: axis \"x\", \"y\" or \"z\", index (default: the middle), values lo..hi (default: the volume's range) through a palette."),
};

int bind_volume_init(interp *I)
{
    return BUILTIN_REGISTER(I, volume_builtins);
}
