/* mpd.c — 3-D random fractal by midpoint displacement, Types I–IV (seed 000).
 * See mpd.h for the lattice, the node keys and the four strategies. */
#include "mpd.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "par.h"
#include "rng.h"

/* ---- the node random -------------------------------------------------- */

/* Inverse normal CDF, P. J. Acklam's rational approximation (2003):
 * central region |p - 0.5| <= 0.47575 a rational function in (p-0.5)^2,
 * tails a rational function in sqrt(-2 log p). Relative error < 1.15e-9.
 * Coefficients as published by Acklam. */
static const double ack_a[6] = {-3.969683028665376e+01, 2.209460984245205e+02,
                                -2.759285104469687e+02, 1.383577518672690e+02,
                                -3.066479806614716e+01, 2.506628277459239e+00};
static const double ack_b[5] = {-5.447609879822406e+01, 1.615858368580409e+02,
                                -1.556989798598866e+02, 6.680131188771972e+01,
                                -1.328068155288572e+01};
static const double ack_c[6] = {-7.784894002430293e-03, -3.223964580411365e-01,
                                -2.400758277161838e+00, -2.549732539343734e+00,
                                4.374664141464968e+00,  2.938163982698783e+00};
static const double ack_d[4] = {7.784695709041462e-03, 3.224671290700398e-01,
                                2.445134137142996e+00, 3.754408661907416e+00};

static double ack_tail(double p) /* p in (0, 0.02425): the lower tail */
{
    double q = sqrt(-2.0 * log(p));
    double num = ((((ack_c[0] * q + ack_c[1]) * q + ack_c[2]) * q + ack_c[3]) * q + ack_c[4]) * q + ack_c[5];
    double den = (((ack_d[0] * q + ack_d[1]) * q + ack_d[2]) * q + ack_d[3]) * q + 1.0;
    return num / den;
}

double mpd_inv_normal(double p)
{
    const double plow = 0.02425;
    if (p < plow)
        return ack_tail(p);
    if (p > 1.0 - plow)
        return -ack_tail(1.0 - p);
    double q = p - 0.5, r = q * q;
    double num = ((((ack_a[0] * r + ack_a[1]) * r + ack_a[2]) * r + ack_a[3]) * r + ack_a[4]) * r + ack_a[5];
    double den = ((((ack_b[0] * r + ack_b[1]) * r + ack_b[2]) * r + ack_b[3]) * r + ack_b[4]) * r + 1.0;
    return num * q / den;
}

double mpd_normal(uint64_t h)
{
    return mpd_inv_normal(((double)(h >> 11) + 0.5) * 0x1.0p-53); /* in (0, 1) */
}

static inline double node_g(uint64_t seed, int n, uint32_t X, uint32_t Y, uint32_t Z)
{
    return mpd_normal(rng_hash3(seed, ((uint64_t)n << 32) | X, Y, Z));
}

double mpd_node_random(uint64_t seed, int n, uint32_t X, uint32_t Y, uint32_t Z)
{
    return node_g(seed, n, X, Y, Z);
}

/* The one place a node value is formed (eqs. (1), (3), (4), (11)): parents
 * p[] in pairs (minus, plus) per odd axis in x, y, z order; cnt odd axes. */
static inline float combine(int cnt, const float *p, double gl)
{
    double s;
    if (cnt == 1)
        s = ((double)p[0] + (double)p[1]) * 0.5;
    else if (cnt == 2)
        s = (((double)p[0] + (double)p[1]) + ((double)p[2] + (double)p[3])) * 0.25;
    else
        s = ((((double)p[0] + (double)p[1]) + ((double)p[2] + (double)p[3])) +
             ((double)p[4] + (double)p[5])) / 6.0;
    return (float)(s + gl);
}

/* ---- level-by-level fill of a box (Type I, and tiles / 3x3x3 blocks) ---- */

/* a holds a box of side S = 2^s lattice steps at resolution res (coordinate
 * unit 2^-res), (S+1)^3 floats, x fastest; its origin is g0 (global
 * coordinates at res). Fill the nodes of class cls (bit a set: axis a is an
 * odd multiple of h) at level n, planes iz0 .. iz1-1 of that class. */
/* One row of a class: nx nodes from index i0, every 2h; cnt is a constant
 * at each call site so the compiler specialises the gather. */
static inline void fill_row(float *a, size_t i0, size_t step, uint32_t nx, const size_t *d, const int cnt,
                            uint64_t seed, int n, uint32_t X0, uint32_t Y, uint32_t Z, double L)
{
    for (uint32_t q = 0; q < nx; q++) {
        size_t i = i0 + (size_t)q * step;
        float p[6];
        for (int c = 0; c < cnt; c++) {
            p[2 * c] = a[i - d[c]];
            p[2 * c + 1] = a[i + d[c]];
        }
        a[i] = combine(cnt, p, node_g(seed, n, X0 + 2 * q, Y, Z) * L);
    }
}

static void fill_class(const mpd *m, float *a, int s, int res, int n, int cls, const uint32_t g0[3],
                       uint32_t iz0, uint32_t iz1)
{
    const uint32_t S = 1u << s;
    const size_t S1 = (size_t)S + 1;
    const int k = res - n;
    const uint32_t h = 1u << k, h2 = h << 1;
    const uint32_t off[3] = {(cls & 1) ? h : 0, (cls & 2) ? h : 0, (cls & 4) ? h : 0};
    const size_t st[3] = {1, S1, S1 * S1};
    size_t d[3] = {0, 0, 0};
    int cnt = 0;
    for (int ax = 0; ax < 3; ax++)
        if (cls >> ax & 1)
            d[cnt++] = (size_t)h * st[ax];
    const double L = m->L[n];
    const uint64_t seed = m->seed;
    const uint32_t nx = (S - off[0]) / h2 + 1, X0 = (g0[0] + off[0]) >> k;
    for (uint32_t iz = iz0; iz < iz1; iz++) {
        uint32_t z = off[2] + iz * h2;
        uint32_t Z = (g0[2] + z) >> k;
        for (uint32_t y = off[1]; y <= S; y += h2) {
            uint32_t Y = (g0[1] + y) >> k;
            size_t i0 = (size_t)y * S1 + (size_t)z * S1 * S1 + off[0];
            if (cnt == 1)
                fill_row(a, i0, h2, nx, d, 1, seed, n, X0, Y, Z, L);
            else if (cnt == 2)
                fill_row(a, i0, h2, nx, d, 2, seed, n, X0, Y, Z, L);
            else
                fill_row(a, i0, h2, nx, d, 3, seed, n, X0, Y, Z, L);
        }
    }
}

static uint32_t class_planes(int s, int k, int cls)
{
    uint32_t per = (1u << s) >> (k + 1); /* S / 2h */
    return (cls & 4) ? per : per + 1;
}

static uint64_t class_nodes(int s, int k, int cls)
{
    uint64_t per = (uint64_t)((1u << s) >> (k + 1));
    uint64_t r = 1;
    for (int ax = 0; ax < 3; ax++)
        r *= (cls >> ax & 1) ? per : per + 1;
    return r;
}

/* Classes of a level in an order that respects the dependencies: in an
 * even plane (z a multiple of 2h) the x- and y-edges, then the xy-faces;
 * in an odd plane the z-edges, the xz- and yz-faces, then the centres,
 * which also need the xy-faces of the even planes at z +- h. */
static const int even_cls[3] = {1, 2, 3};
static const int odd_cls[4] = {4, 5, 6, 7};

/* Serial fill of levels nfrom .. res (nodes of coarser levels in the box
 * set), sweeping the planes in z so the working set stays in cache: even
 * plane e, then the odd plane just below it. Returns the nodes computed. */
static uint64_t fill_box(const mpd *m, float *a, int s, int res, const uint32_t g0[3], int nfrom)
{
    uint64_t count = 0;
    if (nfrom < res - s + 1)
        nfrom = res - s + 1;
    for (int n = nfrom; n <= res; n++) {
        int k = res - n;
        uint32_t ne = class_planes(s, k, 1);
        for (uint32_t e = 0; e < ne; e++) {
            for (int c = 0; c < 3; c++)
                fill_class(m, a, s, res, n, even_cls[c], g0, e, e + 1);
            if (e > 0)
                for (int c = 0; c < 4; c++)
                    fill_class(m, a, s, res, n, odd_cls[c], g0, e - 1, e);
        }
        for (int cls = 1; cls < 8; cls++)
            count += class_nodes(s, k, cls);
    }
    return count;
}

/* Parallel fill of a whole array (Type I, Type IV's top): per level, one
 * par_for over groups of even planes, then one over groups of odd planes.
 * Every node depends only on nodes already final, so the result does not
 * depend on the thread count. */
typedef struct pfill {
    const mpd *m;
    float *a;
    int s, n, odd;
    uint32_t planes, group;
} pfill;

static void pfill_chunk(void *ctx, size_t chunk, int worker)
{
    (void)worker;
    pfill *f = ctx;
    uint32_t z0 = (uint32_t)chunk * f->group, z1 = z0 + f->group;
    if (z1 > f->planes)
        z1 = f->planes;
    static const uint32_t g0[3] = {0, 0, 0};
    for (uint32_t z = z0; z < z1; z++) {
        if (f->odd)
            for (int c = 0; c < 4; c++)
                fill_class(f->m, f->a, f->s, f->s, f->n, odd_cls[c], g0, z, z + 1);
        else
            for (int c = 0; c < 3; c++)
                fill_class(f->m, f->a, f->s, f->s, f->n, even_cls[c], g0, z, z + 1);
    }
}

static rt_code fill_array(const mpd *m, float *a, int res, const rt_run *run)
{
    pfill f;
    f.m = m;
    f.a = a;
    f.s = res;
    for (int n = 1; n <= res; n++) {
        int k = res - n;
        f.n = n;
        /* about 64k nodes per chunk; the split only affects speed */
        uint64_t plane_nodes = class_nodes(res, k, 7) / class_planes(res, k, 7) * 4;
        f.group = (uint32_t)(plane_nodes >= 65536 ? 1 : 65536 / (plane_nodes ? plane_nodes : 1));
        for (f.odd = 0; f.odd < 2; f.odd++) {
            f.planes = class_planes(res, k, f.odd ? 4 : 1);
            size_t chunks = (f.planes + f.group - 1) / f.group;
            rt_code rc = par_for(run, "midpoint displacement", chunks, pfill_chunk, &f);
            if (rc)
                return rc;
        }
    }
    return RT_OK;
}

/* ---- sizes and validation --------------------------------------------- */

static size_t lattice_bytes(int res)
{
    if (res < 0 || res > 30)
        return 0;
    size_t n = ((size_t)1 << res) + 1;
    return rt_mul_size(rt_mul_size(rt_mul_size(n, n), n), sizeof(float));
}

size_t mpd_type1_bytes(int R) { return lattice_bytes(R); }

/* One level of the descent path: the cell index and its 3x3x3 block. */
typedef struct path {
    int valid; /* levels n0 .. valid-1 hold blocks */
    uint32_t cell[MPD_MAX_R][3];
    float blk[MPD_MAX_R][27];
} path;

size_t mpd_path_bytes(int levels)
{
    if (levels <= 0)
        return 0;
    return (size_t)levels * (27 * sizeof(float) + 3 * sizeof(uint32_t));
}

size_t mpd_type4_bytes(int R, int R2)
{
    size_t a = lattice_bytes(R2);
    return a ? a + mpd_path_bytes(R - R2) : 0;
}

static void fmt_bytes(char *buf, size_t len, double b)
{
    static const char *u[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
    int i = 0;
    while (b >= 1000.0 && i < 6) {
        b /= 1000.0;
        i++;
    }
    if (i == 0)
        snprintf(buf, len, "%.0f bytes", b);
    else
        snprintf(buf, len, "%.1f %s", b, u[i]);
}

static void fmt_limit(char *buf, size_t len, size_t b)
{
    if (b >= ((size_t)1 << 30) && b % ((size_t)1 << 30) == 0)
        snprintf(buf, len, "%zu GiB", b >> 30);
    else if (b >= ((size_t)1 << 20) && b % ((size_t)1 << 20) == 0)
        snprintf(buf, len, "%zu MiB", b >> 20);
    else if (b >= 1024 && b % 1024 == 0)
        snprintf(buf, len, "%zu KiB", b >> 10);
    else
        fmt_bytes(buf, len, (double)b);
}

static double lattice_bytes_d(int res)
{
    double n = ldexp(1.0, res) + 1.0;
    return n * n * n * (double)sizeof(float);
}

static double lattice_nodes_d(int res)
{
    double n = ldexp(1.0, res) + 1.0;
    return n * n * n;
}

static int nodes_fit(int res, double max_nodes)
{
    return max_nodes <= 0 || lattice_nodes_d(res) <= max_nodes;
}

int mpd_largest_r2(int R, size_t bytes, double nodes)
{
    int best = -1;
    for (int r2 = 0; r2 <= R; r2++)
        if (lattice_bytes_d(r2) <= (double)bytes && nodes_fit(r2, nodes))
            best = r2;
    return best;
}

void mpd_params_default(mpd_params *p)
{
    memset(p, 0, sizeof *p);
    p->R = 6;
    p->beta = 0.5;
    p->seed = 1;
    p->type = MPD_AUTO;
    p->R2 = -1;
}

/* "Type I at R = 9 needs 513^3 = 135005697 lattice nodes (limit 1000)". */
static void fmt_nodes(char *buf, size_t len, int res, const char *where, double max_nodes)
{
    double side = ldexp(1.0, res) + 1.0;
    snprintf(buf, len, "%.0f^3 = %.0f lattice nodes%s (limit %.0f)", side, side * side * side, where,
             max_nodes);
}

/* 1 if the lattice array of level res is over the byte limit or the node
 * cap (--max-voxels), with what it needs in buf: its bytes, then bytes_where
 * and the limit; or its nodes (fmt_nodes, with nodes_where). */
static int array_over(char *buf, size_t len, int res, size_t limit, double max_nodes, const char *bytes_where,
                      const char *nodes_where)
{
    if (lattice_bytes_d(res) > (double)limit) {
        char lim[64];
        fmt_bytes(buf, len, lattice_bytes_d(res));
        fmt_limit(lim, sizeof lim, limit);
        snprintf(buf + strlen(buf), len - strlen(buf), "%s (limit %s)", bytes_where, lim);
        return 1;
    }
    if (!nodes_fit(res, max_nodes)) {
        fmt_nodes(buf, len, res, nodes_where, max_nodes);
        return 1;
    }
    return 0;
}

rt_code mpd_init(mpd *m, const mpd_params *p, const rt_run *run, rt_error *e)
{
    memset(m, 0, sizeof *m);
    if (p->R < 1 || p->R > MPD_MAX_R)
        return rt_fail(e, RT_EINVAL, "R = %d is out of range (expected 1 .. %d)", p->R, MPD_MAX_R);
    if (!isfinite(p->beta))
        return rt_fail(e, RT_EINVAL, "beta = %g is not a finite number", p->beta);
    for (int i = 0; i < 8; i++)
        if (!isfinite(p->corner[i]))
            return rt_fail(e, RT_EINVAL, "corner %d = %g is not a finite number", i, p->corner[i]);
    if (p->type < 0 || p->type > 4)
        return rt_fail(e, RT_EINVAL,
                       "strategy = %d is not one of 0 (automatic), 1, 2, 3, 4 (Types I-IV)", p->type);
    size_t limit = p->mem_limit ? p->mem_limit : ((size_t)4 << 30);
    size_t budget = p->budget ? p->budget : ((size_t)64 << 20);
    if (budget > limit)
        budget = limit;
    double maxn = p->max_nodes > 0 ? p->max_nodes : 0;
    char need[96];
    int R = p->R, type = p->type, R2 = p->R2;

    if (type == MPD_AUTO) {
        int many = p->npoints_hint == 0 || (double)p->npoints_hint >= lattice_nodes_d(R) / 8.0;
        if (many && lattice_bytes_d(R) <= (double)limit && nodes_fit(R, maxn))
            type = MPD_TYPE1;
        else {
            type = MPD_TYPE4;
            R2 = mpd_largest_r2(R, budget, maxn);
            if (R2 < 0)
                type = MPD_TYPE3, R2 = 0;
        }
    }
    if (type == MPD_TYPE1) {
        if (array_over(need, sizeof need, R, limit, maxn, "", "")) {
            int r2 = mpd_largest_r2(R, limit, maxn);
            if (r2 >= 0)
                return rt_fail(e, RT_EINVAL,
                               "Type I at R = %d needs %s; use Type IV (strategy: 4) "
                               "with R2 = %d, or Type III (strategy: 3)",
                               R, need, r2);
            return rt_fail(e, RT_EINVAL, "Type I at R = %d needs %s; use Type III (strategy: 3)", R, need);
        }
        R2 = R;
    } else if (type == MPD_TYPE4) {
        if (R2 < 0)
            R2 = mpd_largest_r2(R, budget, maxn);
        if (R2 < 0 || R2 > R)
            return rt_fail(e, RT_EINVAL, "R2 = %d is out of range for Type IV (expected 0 .. R = %d)",
                           R2, R);
        if (array_over(need, sizeof need, R2, limit, maxn, " for its array", " in its array")) {
            int r2 = mpd_largest_r2(R, limit, maxn);
            if (r2 >= 0)
                return rt_fail(e, RT_EINVAL, "Type IV with R2 = %d needs %s; use R2 <= %d", R2, need, r2);
            return rt_fail(e, RT_EINVAL, "Type IV with R2 = %d needs %s; use Type III (strategy: 3)", R2,
                           need);
        }
    } else
        R2 = 0;

    m->R = R;
    m->type = type;
    m->R2 = R2;
    m->seed = p->seed;
    m->max_nodes = maxn;
    m->beta = p->beta;
    for (int i = 0; i < 8; i++)
        m->corner[i] = (double)(float)p->corner[i]; /* node values are floats */
    m->L[0] = 1.0;
    for (int n = 1; n <= MPD_MAX_R; n++)
        m->L[n] = exp(-(double)(n - 1) * p->beta); /* eq. (2) */

    if (type == MPD_TYPE1 || type == MPD_TYPE4) {
        size_t bytes = lattice_bytes(R2);
        m->arr = bytes ? rt_malloc(bytes) : NULL;
        if (!m->arr)
            return rt_fail(e, RT_ENOMEM, "out of memory for the Type %s array (%zu bytes)",
                           type == MPD_TYPE1 ? "I" : "IV", bytes);
        m->arr_bytes = bytes;
        size_t S = (size_t)1 << R2, S1 = S + 1;
        for (int c = 0; c < 8; c++) {
            size_t i = (c & 1 ? S : 0) + (c & 2 ? S : 0) * S1 + (c & 4 ? S : 0) * S1 * S1;
            m->arr[i] = (float)m->corner[c];
        }
        rt_code rc = fill_array(m, m->arr, R2, run);
        if (rc) {
            mpd_free(m);
            return rt_fail(e, rc, "interrupted");
        }
    }
    return RT_OK;
}

void mpd_free(mpd *m)
{
    rt_free(m->arr);
    m->arr = NULL;
    m->arr_bytes = 0;
}

/* ---- interpolation ------------------------------------------------------ */

static inline double lerp(double a, double b, double t) { return a + t * (b - a); }

/* v[8] corner values, index x + 2y + 4z; t per axis in [0, 1]. */
static inline double trilinear(const float v[8], const double t[3])
{
    double x00 = lerp(v[0], v[1], t[0]), x10 = lerp(v[2], v[3], t[0]);
    double x01 = lerp(v[4], v[5], t[0]), x11 = lerp(v[6], v[7], t[0]);
    double y0 = lerp(x00, x10, t[1]), y1 = lerp(x01, x11, t[1]);
    return lerp(y0, y1, t[2]);
}

/* Lattice cell and fraction of coordinate x at resolution R (clamped). */
static inline uint32_t cell_of(double x, int R, double *t)
{
    double Nf = ldexp(1.0, R);
    double u = x * Nf;
    if (!(u > 0.0))
        u = 0.0; /* also NaN */
    if (u > Nf)
        u = Nf;
    uint32_t c = (uint32_t)u;
    if (c >= (1u << R))
        c = (1u << R) - 1;
    *t = u - (double)c;
    return c;
}

/* 8 corners of a cell of an array of side S = 2^s at cell (cx, cy, cz). */
static inline void array_corners(const float *a, int s, const uint32_t c[3], float v[8])
{
    size_t S1 = ((size_t)1 << s) + 1;
    size_t i = c[0] + S1 * (c[1] + S1 * (size_t)c[2]);
    v[0] = a[i];
    v[1] = a[i + 1];
    v[2] = a[i + S1];
    v[3] = a[i + S1 + 1];
    v[4] = a[i + S1 * S1];
    v[5] = a[i + S1 * S1 + 1];
    v[6] = a[i + S1 * S1 + S1];
    v[7] = a[i + S1 * S1 + S1 + 1];
}

/* ---- Type III descent ---------------------------------------------------- */

static int base_level(const mpd *m) { return m->type == MPD_TYPE4 || m->type == MPD_TYPE1 ? m->R2 : 0; }

/* Corners of the level-n cell c (c in cells of side 2^(R-n)): for n = n0 from
 * the array or the initial corners, else from the parent's block. */
static void level_corners(const mpd *m, const path *pa, int n, const uint32_t c[3], float v[8])
{
    int n0 = base_level(m);
    if (n == n0) {
        if (m->arr)
            array_corners(m->arr, m->R2, c, v);
        else
            for (int i = 0; i < 8; i++)
                v[i] = (float)m->corner[i];
        return;
    }
    const float *b = pa->blk[n - 1];
    uint32_t o[3];
    for (int ax = 0; ax < 3; ax++)
        o[ax] = c[ax] - 2 * pa->cell[n - 1][ax];
    for (int i = 0; i < 8; i++)
        v[i] = b[(o[0] + (i & 1)) + 3 * (o[1] + (i >> 1 & 1)) + 9 * (o[2] + (i >> 2 & 1))];
}

/* Make the path hold blocks for the cells containing finest cell fc down to
 * level `to` - 1; returns nodes computed. */
static uint64_t descend(const mpd *m, path *pa, const uint32_t fc[3], int to)
{
    int n0 = base_level(m), R = m->R;
    int n = n0;
    while (n < pa->valid && n < to) {
        int sh = R - n;
        if (pa->cell[n][0] != fc[0] >> sh || pa->cell[n][1] != fc[1] >> sh ||
            pa->cell[n][2] != fc[2] >> sh)
            break;
        n++;
    }
    uint64_t count = 0;
    for (; n < to; n++) {
        int sh = R - n;
        uint32_t c[3] = {fc[0] >> sh, fc[1] >> sh, fc[2] >> sh};
        float v[8];
        level_corners(m, pa, n, c, v);
        float *b = pa->blk[n];
        for (int i = 0; i < 8; i++)
            b[2 * (i & 1) + 6 * (i >> 1 & 1) + 18 * (i >> 2 & 1)] = v[i];
        for (int ax = 0; ax < 3; ax++)
            pa->cell[n][ax] = c[ax];
        uint32_t g0[3] = {2 * c[0], 2 * c[1], 2 * c[2]};
        count += fill_box(m, b, 1, n + 1, g0, n + 1); /* the 19 new nodes */
        pa->valid = n + 1;
    }
    return count;
}

/* Corners of finest cell fc via the path. */
static uint64_t finest_corners(const mpd *m, path *pa, const uint32_t fc[3], float v[8])
{
    if (base_level(m) == m->R) {
        array_corners(m->arr, m->R, fc, v);
        return 0;
    }
    uint64_t cnt = descend(m, pa, fc, m->R);
    level_corners(m, pa, m->R, fc, v);
    return cnt;
}

/* Node g (0 .. 2^R per axis) by a descent from the root, for any type. */
static float descent_node(const mpd *m, const uint32_t g[3], uint64_t *nodes)
{
    uint32_t N = 1u << m->R;
    uint32_t c[3];
    int q = 0;
    for (int ax = 0; ax < 3; ax++) {
        c[ax] = g[ax] < N ? g[ax] : N - 1;
        q |= (int)(g[ax] - c[ax]) << ax;
    }
    path pa;
    pa.valid = 0;
    float v[8];
    uint64_t k = finest_corners(m, &pa, c, v);
    if (nodes)
        *nodes += k;
    return v[q];
}

/* ---- Type II memo -------------------------------------------------------- */

typedef struct memo {
    uint64_t *keys; /* UINT64_MAX = empty */
    float *vals;
    size_t cap, used, peak_bytes;
    int broken;     /* an allocation failed: stop inserting */
} memo;

static int memo_alloc(memo *mm, size_t cap)
{
    uint64_t *k = rt_malloc(cap * sizeof *k);
    float *v = rt_malloc(cap * sizeof *v);
    if (!k || !v) {
        rt_free(k);
        rt_free(v);
        return -1;
    }
    memset(k, 0xff, cap * sizeof *k);
    mm->keys = k;
    mm->vals = v;
    mm->cap = cap;
    mm->used = 0;
    size_t b = cap * (sizeof *k + sizeof *v);
    if (b > mm->peak_bytes)
        mm->peak_bytes = b;
    return 0;
}

static void memo_free(memo *mm)
{
    rt_free(mm->keys);
    rt_free(mm->vals);
    mm->keys = NULL;
    mm->vals = NULL;
    mm->cap = mm->used = 0;
}

static float *memo_find(memo *mm, uint64_t key, int *found)
{
    size_t i = (size_t)rng_mix64(key) & (mm->cap - 1);
    while (mm->keys[i] != UINT64_MAX) {
        if (mm->keys[i] == key) {
            *found = 1;
            return &mm->vals[i];
        }
        i = (i + 1) & (mm->cap - 1);
    }
    *found = 0;
    return &mm->vals[i];
}

#define MEMO_FIRST 1024 /* slots of a fresh memo */

/* The memo may hold at most max_nodes slots (0: no limit); a memo that
 * cannot start is not used (the descent gives the same values). */
static int memo_allowed(const mpd *m)
{
    return m->max_nodes <= 0 || (double)MEMO_FIRST <= m->max_nodes;
}

static void memo_insert(memo *mm, uint64_t key, float val, double max_nodes)
{
    if (mm->broken)
        return;
    if (2 * (mm->used + 1) > mm->cap) {
        memo old = *mm;
        if ((max_nodes > 0 && (double)old.cap * 2 > max_nodes) || memo_alloc(mm, old.cap * 2)) {
            *mm = old;
            mm->broken = 1;
            return;
        }
        for (size_t i = 0; i < old.cap; i++)
            if (old.keys[i] != UINT64_MAX) {
                int f;
                *memo_find(mm, old.keys[i], &f) = old.vals[i];
                mm->used++;
            }
        rt_free(old.keys);
        rt_free(old.vals);
    }
    int f;
    float *slot = memo_find(mm, key, &f);
    if (!f) {
        mm->keys[(size_t)(slot - mm->vals)] = key;
        *slot = val;
        mm->used++;
    }
}

/* Value of node c (resolution R) by walking parents (eqs. (8)–(11)). */
static float t2_get(const mpd *m, memo *mm, const uint32_t c[3], uint64_t *nodes)
{
    const int R = m->R;
    const uint32_t N = 1u << R;
    uint32_t low = (c[0] | c[1] | c[2]) & (N - 1);
    if (low == 0)
        return (float)m->corner[(c[0] != 0) + 2 * (c[1] != 0) + 4 * (c[2] != 0)];
    uint64_t key = (uint64_t)c[0] | ((uint64_t)c[1] << 21) | ((uint64_t)c[2] << 42);
    int found;
    float *slot = memo_find(mm, key, &found);
    if (found)
        return *slot;
    if (mm->broken) /* the memo is full: walking parents unmemoised would cost exponential time */
        return descent_node(m, c, nodes);
    int k = 0;
    while (!(low >> k & 1))
        k++;
    uint32_t h = 1u << k;
    int n = R - k, cnt = 0;
    float p[6];
    for (int ax = 0; ax < 3; ax++) {
        if (!(c[ax] >> k & 1))
            continue;
        uint32_t q[3] = {c[0], c[1], c[2]};
        q[ax] = c[ax] - h;
        p[2 * cnt] = t2_get(m, mm, q, nodes);
        q[ax] = c[ax] + h;
        p[2 * cnt + 1] = t2_get(m, mm, q, nodes);
        cnt++;
    }
    float v = combine(cnt, p, node_g(m->seed, n, c[0] >> k, c[1] >> k, c[2] >> k) * m->L[n]);
    (*nodes)++;
    memo_insert(mm, key, v, m->max_nodes);
    return v;
}

/* ---- evaluation of a block of points ---------------------------------- */

typedef struct evaluator {
    path pa;
    memo mm;
    uint64_t nodes;
} evaluator;

static void ev_init(evaluator *ev)
{
    ev->pa.valid = 0;
    memset(&ev->mm, 0, sizeof ev->mm);
    ev->nodes = 0;
}

/* spread the low 21 bits of v to every third bit */
static uint64_t spread3(uint32_t v)
{
    uint64_t x = v & 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

/* LSD radix sort of (key, idx) pairs on the low `bits` bits; tmp same size. */
static void radix_sort(uint64_t *key, uint32_t *idx, uint64_t *tk, uint32_t *ti, size_t n, int bits)
{
    for (int sh = 0; sh < bits; sh += 8) {
        size_t cnt[257] = {0};
        for (size_t i = 0; i < n; i++)
            cnt[((key[i] >> sh) & 255) + 1]++;
        for (int d = 0; d < 256; d++)
            cnt[d + 1] += cnt[d];
        for (size_t i = 0; i < n; i++) {
            size_t pos = cnt[(key[i] >> sh) & 255]++;
            tk[pos] = key[i];
            ti[pos] = idx[i];
        }
        memcpy(key, tk, n * sizeof *key);
        memcpy(idx, ti, n * sizeof *idx);
    }
}

typedef struct scratch {
    uint64_t *key, *tk;
    uint32_t *idx, *ti;
} scratch;

/* Evaluate n points (n <= the scratch size). */
static void eval_block(const mpd *m, evaluator *ev, scratch *sc, size_t n, const double *x,
                       const double *y, const double *z, double *out)
{
    const int R = m->R;
    if (m->type == MPD_TYPE1) {
        for (size_t i = 0; i < n; i++) {
            double t[3];
            uint32_t c[3] = {cell_of(x[i], R, &t[0]), cell_of(y[i], R, &t[1]), cell_of(z[i], R, &t[2])};
            float v[8];
            array_corners(m->arr, R, c, v);
            out[i] = trilinear(v, t);
        }
        return;
    }
    /* Types II–IV: visit the points in Morton order of their cells */
    for (size_t i = 0; i < n; i++) {
        double t;
        sc->key[i] = spread3(cell_of(x[i], R, &t)) | spread3(cell_of(y[i], R, &t)) << 1 |
                     spread3(cell_of(z[i], R, &t)) << 2;
        sc->idx[i] = (uint32_t)i;
    }
    radix_sort(sc->key, sc->idx, sc->tk, sc->ti, n, 3 * R);
    int use_memo = 0;
    if (m->type == MPD_TYPE2) {
        if (!ev->mm.keys && memo_allowed(m) && memo_alloc(&ev->mm, MEMO_FIRST) == 0)
            ev->mm.broken = 0;
        use_memo = ev->mm.keys != NULL;
    }
    for (size_t s = 0; s < n; s++) {
        size_t i = sc->idx[s];
        double t[3];
        uint32_t c[3] = {cell_of(x[i], R, &t[0]), cell_of(y[i], R, &t[1]), cell_of(z[i], R, &t[2])};
        float v[8];
        if (use_memo) {
            for (int q = 0; q < 8; q++) {
                uint32_t g[3] = {c[0] + (q & 1), c[1] + (q >> 1 & 1), c[2] + (q >> 2 & 1)};
                v[q] = t2_get(m, &ev->mm, g, &ev->nodes);
            }
        } else
            ev->nodes += finest_corners(m, &ev->pa, c, v);
        out[i] = trilinear(v, t);
    }
}

#define SMALL_BLOCK 256

void mpd_eval(const void *ctx, size_t n, const double *x, const double *y, const double *z,
              double *out)
{
    const mpd *m = ctx;
    evaluator ev;
    ev_init(&ev);
    uint64_t key[SMALL_BLOCK], tk[SMALL_BLOCK];
    uint32_t idx[SMALL_BLOCK], ti[SMALL_BLOCK];
    scratch sc = {key, tk, idx, ti};
    for (size_t b = 0; b < n; b += SMALL_BLOCK) {
        size_t len = n - b < SMALL_BLOCK ? n - b : SMALL_BLOCK;
        eval_block(m, &ev, &sc, len, x + b, y + b, z + b, out + b);
    }
    memo_free(&ev.mm);
}

double mpd_node(const mpd *m, uint32_t i, uint32_t j, uint32_t k)
{
    uint32_t N = 1u << m->R;
    uint32_t g[3] = {i > N ? N : i, j > N ? N : j, k > N ? N : k};
    if (m->arr && m->R2 == m->R) {
        size_t S1 = (size_t)N + 1;
        return m->arr[g[0] + S1 * (g[1] + S1 * (size_t)g[2])];
    }
    return descent_node(m, g, NULL);
}

/* ---- parallel evaluation ------------------------------------------------ */

typedef struct pjob {
    const mpd *m;
    size_t n;
    const double *x, *y, *z;
    double *out;
    evaluator *ev; /* per worker */
    scratch *sc;   /* per worker */
    uint64_t *nodes;
    size_t *work;
} pjob;

static void points_chunk(void *ctx, size_t chunk, int worker)
{
    pjob *j = ctx;
    size_t b = chunk * MPD_CHUNK, len = j->n - b < MPD_CHUNK ? j->n - b : MPD_CHUNK;
    evaluator *ev = &j->ev[worker];
    eval_block(j->m, ev, &j->sc[worker], len, j->x + b, j->y + b, j->z + b, j->out + b);
    if (ev->mm.keys) { /* Type II: the memo lives for one chunk */
        if (ev->mm.peak_bytes > j->work[worker])
            j->work[worker] = ev->mm.peak_bytes;
        memo_free(&ev->mm);
        ev->mm.broken = 0;
    }
}

static void stats_begin(const mpd *m, mpd_stats *st)
{
    if (!st)
        return;
    memset(st, 0, sizeof *st);
    st->array_bytes = m->arr_bytes;
}

rt_code mpd_eval_points(const mpd *m, const rt_run *run, size_t n, const double *x, const double *y,
                        const double *z, double *out, mpd_stats *st, rt_error *e)
{
    stats_begin(m, st);
    if (n == 0)
        return RT_OK;
    size_t nchunks = (n + MPD_CHUNK - 1) / MPD_CHUNK;
    int nw = par_workers(run, nchunks);
    pjob j = {m, n, x, y, z, out, NULL, NULL, NULL, NULL};
    j.ev = rt_calloc((size_t)nw, sizeof *j.ev);
    j.sc = rt_calloc((size_t)nw, sizeof *j.sc);
    j.work = rt_calloc((size_t)nw, sizeof *j.work);
    void *buf = rt_malloc((size_t)nw * MPD_CHUNK * 2 * (sizeof(uint64_t) + sizeof(uint32_t)));
    if (!j.ev || !j.sc || !j.work || !buf) {
        rt_free(j.ev);
        rt_free(j.sc);
        rt_free(j.work);
        rt_free(buf);
        return rt_fail(e, RT_ENOMEM, "out of memory evaluating %zu points", n);
    }
    uint64_t *kb = buf;
    uint32_t *ib = (uint32_t *)(kb + (size_t)nw * MPD_CHUNK * 2);
    for (int w = 0; w < nw; w++) {
        ev_init(&j.ev[w]);
        j.sc[w].key = kb + (size_t)w * 2 * MPD_CHUNK;
        j.sc[w].tk = j.sc[w].key + MPD_CHUNK;
        j.sc[w].idx = ib + (size_t)w * 2 * MPD_CHUNK;
        j.sc[w].ti = j.sc[w].idx + MPD_CHUNK;
    }
    rt_code rc = par_for(run, "fractal D(P)", nchunks, points_chunk, &j);
    if (st) {
        st->workers = (size_t)nw;
        for (int w = 0; w < nw; w++) {
            st->nodes += j.ev[w].nodes;
            size_t wb = m->type == MPD_TYPE2 ? j.work[w] : mpd_path_bytes(m->R - base_level(m));
            if (wb > st->work_bytes)
                st->work_bytes = wb;
        }
    }
    for (int w = 0; w < nw; w++)
        memo_free(&j.ev[w].mm);
    rt_free(j.ev);
    rt_free(j.sc);
    rt_free(j.work);
    rt_free(buf);
    if (rc)
        return rt_fail(e, rc, "interrupted");
    return RT_OK;
}

/* ---- grid evaluation by tiles -------------------------------------------- */

typedef struct axis_map {
    uint32_t *cell;  /* per grid index: finest cell */
    double *t;       /* per grid index: fraction */
    uint32_t *order; /* grid indices sorted by tile */
    uint32_t *start; /* per tile: first position in order (ntiles + 1) */
} axis_map;

typedef struct gjob {
    const mpd *m;
    int nt, ts_log; /* tiles per axis, log2 tile side */
    int n[3];
    axis_map ax[3];
    double *out;
    float **tile;   /* per worker */
    evaluator *ev;  /* per worker */
    uint64_t *nodes;
} gjob;

static void grid_tile(void *ctx, size_t chunk, int worker)
{
    gjob *j = ctx;
    const mpd *m = j->m;
    const int R = m->R;
    uint32_t tc[3] = {(uint32_t)(chunk % (size_t)j->nt), (uint32_t)(chunk / (size_t)j->nt % (size_t)j->nt),
                      (uint32_t)(chunk / ((size_t)j->nt * (size_t)j->nt))};
    for (int a = 0; a < 3; a++)
        if (j->ax[a].start[tc[a]] == j->ax[a].start[tc[a] + 1])
            return; /* no grid point in this tile */
    evaluator *ev = &j->ev[worker];
    const int s = j->ts_log, mt = R - s; /* the tile is a cell of level mt */
    const uint32_t TS = 1u << s;
    const size_t S1 = (size_t)TS + 1;
    const float *a = NULL;
    uint32_t origin[3] = {tc[0] * TS, tc[1] * TS, tc[2] * TS};
    if (m->type == MPD_TYPE1) {
        a = NULL;
    } else if (m->type == MPD_TYPE2) {
        a = NULL;
    } else {
        float *tb = j->tile[worker];
        int nfrom;
        if (m->type == MPD_TYPE4 && m->R2 >= mt) {
            /* copy the array's nodes inside the tile, then fill below R2 */
            int st = R - m->R2; /* stride of array nodes in the tile */
            uint32_t na = (TS >> st) + 1;
            size_t A1 = ((size_t)1 << m->R2) + 1;
            for (uint32_t kz = 0; kz < na; kz++)
                for (uint32_t ky = 0; ky < na; ky++)
                    for (uint32_t kx = 0; kx < na; kx++) {
                        size_t ai = (origin[0] >> st) + kx +
                                    A1 * ((origin[1] >> st) + ky + A1 * ((size_t)(origin[2] >> st) + kz));
                        tb[((size_t)kx << st) + S1 * (((size_t)ky << st) + S1 * ((size_t)kz << st))] =
                            m->arr[ai];
                    }
            nfrom = m->R2 + 1;
        } else {
            float v[8];
            uint32_t fc[3] = {origin[0], origin[1], origin[2]};
            if (mt > base_level(m))
                ev->nodes += descend(m, &ev->pa, fc, mt);
            level_corners(m, &ev->pa, mt, tc, v);
            for (int i = 0; i < 8; i++)
                tb[(i & 1 ? TS : 0) + S1 * ((i & 2 ? TS : 0) + S1 * (size_t)(i & 4 ? TS : 0))] = v[i];
            nfrom = mt + 1;
        }
        ev->nodes += fill_box(m, tb, s, R, origin, nfrom);
        a = tb;
    }
    const axis_map *X = &j->ax[0], *Y = &j->ax[1], *Z = &j->ax[2];
    for (uint32_t pz = Z->start[tc[2]]; pz < Z->start[tc[2] + 1]; pz++) {
        uint32_t iz = Z->order[pz];
        for (uint32_t py = Y->start[tc[1]]; py < Y->start[tc[1] + 1]; py++) {
            uint32_t iy = Y->order[py];
            size_t row = (size_t)j->n[0] * (iy + (size_t)j->n[1] * iz);
            for (uint32_t px = X->start[tc[0]]; px < X->start[tc[0] + 1]; px++) {
                uint32_t ix = X->order[px];
                uint32_t c[3] = {X->cell[ix], Y->cell[iy], Z->cell[iz]};
                double t[3] = {X->t[ix], Y->t[iy], Z->t[iz]};
                float v[8];
                if (a) {
                    uint32_t lc[3] = {c[0] - origin[0], c[1] - origin[1], c[2] - origin[2]};
                    array_corners(a, s, lc, v);
                } else if (m->type == MPD_TYPE1) {
                    array_corners(m->arr, R, c, v);
                } else {
                    if (!ev->mm.keys && (!memo_allowed(m) || memo_alloc(&ev->mm, MEMO_FIRST) != 0)) {
                        ev->nodes += finest_corners(m, &ev->pa, c, v);
                        j->out[row + ix] = trilinear(v, t);
                        continue;
                    }
                    for (int q = 0; q < 8; q++) {
                        uint32_t g[3] = {c[0] + (q & 1), c[1] + (q >> 1 & 1), c[2] + (q >> 2 & 1)};
                        v[q] = t2_get(m, &ev->mm, g, &ev->nodes);
                    }
                }
                j->out[row + ix] = trilinear(v, t);
            }
        }
    }
    if (ev->mm.keys) { /* Type II: memo per tile */
        if (ev->mm.peak_bytes > j->nodes[worker])
            j->nodes[worker] = ev->mm.peak_bytes; /* reused as peak bytes */
        memo_free(&ev->mm);
        ev->mm.broken = 0;
    }
}

static int axis_setup(axis_map *am, int n, double lo, double hi, int R, int s, int nt)
{
    am->cell = rt_malloc((size_t)n * sizeof *am->cell);
    am->t = rt_malloc((size_t)n * sizeof *am->t);
    am->order = rt_malloc((size_t)n * sizeof *am->order);
    am->start = rt_calloc((size_t)nt + 1, sizeof *am->start);
    if (!am->cell || !am->t || !am->order || !am->start)
        return -1;
    for (int i = 0; i < n; i++) {
        double x = n == 1 ? lo : lo + (hi - lo) * (double)i / (double)(n - 1);
        am->cell[i] = cell_of(x, R, &am->t[i]);
        am->start[(am->cell[i] >> s) + 1]++;
    }
    for (int k = 0; k < nt; k++)
        am->start[k + 1] += am->start[k];
    uint32_t *pos = rt_malloc((size_t)nt * sizeof *pos);
    if (!pos)
        return -1;
    memcpy(pos, am->start, (size_t)nt * sizeof *pos);
    for (int i = 0; i < n; i++)
        am->order[pos[am->cell[i] >> s]++] = (uint32_t)i;
    rt_free(pos);
    return 0;
}

static void axis_free(axis_map *am)
{
    rt_free(am->cell);
    rt_free(am->t);
    rt_free(am->order);
    rt_free(am->start);
}

rt_code mpd_eval_grid(const mpd *m, const rt_run *run, const double lo[3], const double hi[3], int nx,
                      int ny, int nz, double *out, mpd_stats *st, rt_error *e)
{
    stats_begin(m, st);
    if (nx < 1 || ny < 1 || nz < 1)
        return rt_fail(e, RT_EINVAL, "grid size %d x %d x %d: every side must be at least 1", nx, ny,
                       nz);
    gjob j;
    memset(&j, 0, sizeof j);
    j.m = m;
    j.ts_log = m->R < MPD_TILE_LOG ? m->R : MPD_TILE_LOG;
    j.nt = 1 << (m->R - j.ts_log);
    j.n[0] = nx;
    j.n[1] = ny;
    j.n[2] = nz;
    j.out = out;
    int nw = par_workers(run, (size_t)j.nt * j.nt * j.nt);
    rt_code rc = RT_OK;
    j.tile = rt_calloc((size_t)nw, sizeof *j.tile);
    j.ev = rt_calloc((size_t)nw, sizeof *j.ev);
    j.nodes = rt_calloc((size_t)nw, sizeof *j.nodes);
    int ok = j.tile && j.ev && j.nodes;
    for (int a = 0; a < 3 && ok; a++)
        ok = axis_setup(&j.ax[a], j.n[a], lo[a], hi[a], m->R, j.ts_log, j.nt) == 0;
    size_t S1 = ((size_t)1 << j.ts_log) + 1;
    size_t tile_bytes = S1 * S1 * S1 * sizeof(float);
    if (ok && (m->type == MPD_TYPE3 || m->type == MPD_TYPE4))
        for (int w = 0; w < nw && ok; w++)
            ok = (j.tile[w] = rt_malloc(tile_bytes)) != NULL;
    if (!ok)
        rc = rt_fail(e, RT_ENOMEM, "out of memory evaluating a %d x %d x %d grid", nx, ny, nz);
    else {
        for (int w = 0; w < nw; w++)
            ev_init(&j.ev[w]);
        rc = par_for(run, "fractal D(P) grid", (size_t)j.nt * j.nt * j.nt, grid_tile, &j);
        if (rc)
            rt_fail(e, rc, "interrupted");
        if (st) {
            st->workers = (size_t)nw;
            for (int w = 0; w < nw; w++) {
                st->nodes += j.ev[w].nodes;
                size_t wb = m->type == MPD_TYPE2   ? j.nodes[w]
                            : m->type == MPD_TYPE1 ? 0
                                                   : tile_bytes + mpd_path_bytes(m->R - base_level(m));
                if (wb > st->work_bytes)
                    st->work_bytes = wb;
            }
        }
    }
    if (j.tile)
        for (int w = 0; w < nw; w++)
            rt_free(j.tile[w]);
    if (j.ev)
        for (int w = 0; w < nw; w++)
            memo_free(&j.ev[w].mm);
    for (int a = 0; a < 3; a++)
        axis_free(&j.ax[a]);
    rt_free(j.tile);
    rt_free(j.ev);
    rt_free(j.nodes);
    return rc;
}
