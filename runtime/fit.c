/* fit.c — fitting a 2-D IFS to a binary mask; the method is described in fit.h. */
#include "fit.h"

#include <math.h>
#include <string.h>
#include <time.h>

#include "par.h"
#include "progress.h"
#include "rng.h"
#include "rt_alloc.h"

#define NPAR 6            /* θ, φ, u1, u2, tx, ty per map */
#define SMAX 0.98         /* |s| < SMAX: contraction by construction */
#define BIG 1e20          /* "no feature" in the distance transform */
#define NLEVELS 4
#define BURN 20
#define PI 3.14159265358979323846
/* parameters: n maps × NPAR, n log-weights, and for a RIFS n×n transition flags (1 allowed, 0 forbidden) */
#define XLEN (FIT_MAX_MAPS * NPAR + FIT_MAX_MAPS + FIT_MAX_MAPS * FIT_MAX_MAPS)

typedef struct level {
    int gw, gh, nt;
    unsigned char *T;  /* gw*gh target cells */
    double *dT;        /* distance (cells) to the nearest target cell */
    uint32_t points;   /* chaos-game points per evaluation */
} level;

typedef struct scratch {
    unsigned char *hit;
    double *dA, *f, *d, *z;
    int *v;
    double drawn;      /* chaos-game points drawn by the evaluations on this scratch */
} scratch;

typedef struct fitter {
    const fit_opts *o;
    level lv[NLEVELS];
    int nlv;
    scratch sc[FIT_LAMBDA];
    double cand[FIT_LAMBDA][XLEN];
    double loss[FIT_LAMBDA];
    /* the generation being evaluated */
    const double *x;   /* current parameters (n*NPAR) then log-weights (n) */
    int n, li, mode;   /* mode 0: shape steps, 1: weights only */
    long gen;
    double sigma;
    uint64_t stream;   /* rng stream of this generation's offspring */
    double cx, cy;     /* target centroid (frame) on the coarsest level */
} fitter;

/* ---- distance transform (Felzenszwalb & Huttenlocher, "Distance Transforms of Sampled
 * Functions", Theory of Computing 8, 2012: the lower envelope of parabolas) --------------- */

static void dt1d(const double *f, int n, double *d, int *v, double *z)
{
    int k = 0;
    v[0] = 0;
    z[0] = -HUGE_VAL; /* no intersection is at or left of -inf: k never goes below 0 */
    z[1] = HUGE_VAL;
    for (int q = 1; q < n; q++) {
        double s;
        for (;;) {
            int p = v[k];
            s = ((f[q] + (double)q * q) - (f[p] + (double)p * p)) / (2.0 * (q - p));
            if (s > z[k])
                break;
            k--;
        }
        k++;
        v[k] = q;
        z[k] = s;
        z[k + 1] = HUGE_VAL;
    }
    k = 0;
    for (int q = 0; q < n; q++) {
        while (z[k + 1] < q)
            k++;
        double dq = q - v[k];
        d[q] = dq * dq + f[v[k]];
    }
}

/* out = Euclidean distance (cells) from each cell to the nearest fg cell. */
static void dt2(const unsigned char *fg, int w, int h, double *out, scratch *s)
{
    for (int x = 0; x < w; x++) {
        for (int y = 0; y < h; y++)
            s->f[y] = fg[(size_t)y * w + x] ? 0 : BIG;
        dt1d(s->f, h, s->d, s->v, s->z);
        for (int y = 0; y < h; y++)
            out[(size_t)y * w + x] = s->d[y];
    }
    for (int y = 0; y < h; y++) {
        double *row = out + (size_t)y * w;
        memcpy(s->f, row, sizeof(double) * (size_t)w);
        dt1d(s->f, w, s->d, s->v, s->z);
        for (int x = 0; x < w; x++)
            row[x] = sqrt(s->d[x]);
    }
}

/* ---- parameters ----------------------------------------------------------------------------- */

static void to_affine(const double *q, affine *a)
{
    double ct = cos(q[0]), st = sin(q[0]), cp = cos(q[1]), sp = sin(q[1]);
    double s1 = SMAX * tanh(q[2]), s2 = SMAX * tanh(q[3]);
    *a = affine_identity(2);
    /* R(θ) · diag(s1, s2) · R(φ) */
    a->m[0][0] = ct * s1 * cp - st * s2 * sp;
    a->m[0][1] = -ct * s1 * sp - st * s2 * cp;
    a->m[1][0] = st * s1 * cp + ct * s2 * sp;
    a->m[1][1] = -st * s1 * sp + ct * s2 * cp;
    a->t[0] = q[4];
    a->t[1] = q[5];
}

static void weights(const double *x, int n, double *p)
{
    double dmax = 0, sum = 0;
    double det[FIT_MAX_MAPS];
    for (int i = 0; i < n; i++) {
        det[i] = fabs(tanh(x[i * NPAR + 2]) * tanh(x[i * NPAR + 3])) * SMAX * SMAX;
        if (det[i] > dmax)
            dmax = det[i];
    }
    for (int i = 0; i < n; i++) {
        double d = det[i] > 0.01 * dmax ? det[i] : 0.01 * dmax;
        if (dmax == 0)
            d = 1;
        p[i] = d * exp(x[n * NPAR + i]);
        sum += p[i];
    }
    for (int i = 0; i < n; i++)
        p[i] /= sum;
}

void fit_svd2(const double m[2][2], double *theta, double *s1, double *s2, double *phi)
{
    double a = m[0][0], b = m[0][1], c = m[1][0], d = m[1][1];
    double E = (a + d) / 2, F = (a - d) / 2, G = (c + b) / 2, H = (c - b) / 2;
    double Q = hypot(E, H), R = hypot(F, G);
    double a1 = atan2(G, F), a2 = atan2(H, E);
    *s1 = Q + R;
    *s2 = Q - R;
    *theta = (a2 + a1) / 2;
    *phi = (a2 - a1) / 2;
}

static int nparams(const fitter *F, int n) { return n * NPAR + n + (F->o->rifs ? n * n : 0); }

/* The transition graph i -> j (allowed[i*n + j] != 0) is strongly connected: every map
 * reaches map 1 and map 1 reaches every map. */
static int irreducible(const double *allowed, int n)
{
    for (int dir = 0; dir < 2; dir++) {
        int seen[FIT_MAX_MAPS] = {1}, stack[FIT_MAX_MAPS], top = 0, count = 1;
        stack[top++] = 0;
        while (top) {
            int i = stack[--top];
            for (int j = 0; j < n; j++)
                if (!seen[j] && allowed[dir ? j * n + i : i * n + j]) {
                    seen[j] = 1;
                    count++;
                    stack[top++] = j;
                }
        }
        if (count < n)
            return 0;
    }
    return 1;
}

/* Row-stochastic transition matrix: P_ij ∝ allowed_ij · p_j (an IFS: every row is p). */
static void transitions(const fitter *F, const double *x, int n, const double *p, double *P)
{
    const double *al = x + n * NPAR + n;
    for (int i = 0; i < n; i++) {
        double sum = 0;
        for (int j = 0; j < n; j++)
            sum += P[i * n + j] = F->o->rifs ? p[j] * (al[i * n + j] != 0) : p[j];
        for (int j = 0; j < n; j++)
            P[i * n + j] = sum > 0 ? P[i * n + j] / sum : 0;
    }
}

/* ---- the loss ---------------------------------------------------------------------------- */

static double eval_loss(const fitter *F, const double *x, int n, const level *L, scratch *s)
{
    double ma[FIT_MAX_MAPS], mb[FIT_MAX_MAPS], mc[FIT_MAX_MAPS], md[FIT_MAX_MAPS], me[FIT_MAX_MAPS],
        mf[FIT_MAX_MAPS], p[FIT_MAX_MAPS];
    uint64_t cum[FIT_MAX_MAPS][FIT_MAX_MAPS];
    double P[FIT_MAX_MAPS * FIT_MAX_MAPS];
    weights(x, n, p);
    transitions(F, x, n, p, P);
    for (int i = 0; i < n; i++) {
        affine a;
        to_affine(x + i * NPAR, &a);
        ma[i] = a.m[0][0], mb[i] = a.m[0][1], mc[i] = a.m[1][0], md[i] = a.m[1][1];
        me[i] = a.t[0], mf[i] = a.t[1];
        double acc = 0;
        int lastj = 0;
        for (int j = 0; j < n; j++) {
            acc += P[i * n + j];
            cum[i][j] = (uint64_t)(acc * 4294967296.0);
            if (P[i * n + j] > 0)
                lastj = j;
        }
        for (int j = lastj; j < n; j++) /* the last allowed map takes the rounding */
            cum[i][j] = UINT64_MAX;
    }
    /* start at the fixed point of map 1: (I - A) z = t */
    double det = (1 - ma[0]) * (1 - md[0]) - mb[0] * mc[0];
    double zx = ((1 - md[0]) * me[0] + mb[0] * mf[0]) / det;
    double zy = (mc[0] * me[0] + (1 - ma[0]) * mf[0]) / det;
    int gw = L->gw, gh = L->gh;
    size_t cells = (size_t)gw * gh;
    memset(s->hit, 0, cells);
    rng r;
    rng_init(&r, F->o->seed, 0x6669740000000000ull + (uint64_t)(L - F->lv));
    uint32_t out = 0, total = L->points;
    s->drawn += total;
    int state = 0; /* the last map applied (a RIFS chooses the next by its row) */
    for (uint32_t i = 0; i < total + BURN; i++) {
        uint64_t r32 = rng_next(&r) >> 32;
        int k = 0;
        while (r32 >= cum[state][k])
            k++;
        state = k;
        double nx = ma[k] * zx + mb[k] * zy + me[k];
        double ny = mc[k] * zx + md[k] * zy + mf[k];
        zx = nx;
        zy = ny;
        if (i < BURN)
            continue;
        if (zx >= 0 && zx < 1 && zy > 0 && zy <= 1) {
            int cx = (int)(zx * gw), cy = (int)((1 - zy) * gh);
            if (cx >= gw)
                cx = gw - 1;
            if (cy >= gh)
                cy = gh - 1;
            s->hit[(size_t)cy * gw + cx] = 1;
        } else {
            out++;
        }
    }
    size_t na = 0;
    double outside = 0;
    for (size_t c = 0; c < cells; c++)
        if (s->hit[c]) {
            na++;
            outside += L->dT[c];
        }
    double g = gw > gh ? gw : gh;
    if (na == 0)
        return 1e9;
    dt2(s->hit, gw, gh, s->dA, s);
    double cover = 0;
    for (size_t c = 0; c < cells; c++)
        if (L->T[c])
            cover += s->dA[c];
    return cover / L->nt + outside / (double)na + 0.25 * g * ((double)out / total);
}

/* ---- collage initialisation -------------------------------------------------------------- */

/* the level the collage is searched on: the 64-cell grid (holes of a fractal show there;
 * at 32 cells they are mostly filled in) */
static int collage_level(const fitter *F) { return F->nlv >= 2 ? 1 : 0; }

/* a cap below FIT_MIN_POINTS: the quick search of fit.h ("A small cap") */
static int quick(const fitter *F) { return F->o->max_points > 0 && F->o->max_points < FIT_MIN_POINTS; }

/* starts of the coarse levels */
static int nstarts(const fitter *F) { return F->o->start ? 1 : quick(F) ? 2 : FIT_STARTS; }

/* Target cells newly covered by the image w(T) minus the distance-transform sum of the
 * image points outside T (times |s1 s2|, the image's area per mapped cell). */
static double collage_score(const level *L, const double *q, const unsigned char *covered, uint32_t *stamp,
                            uint32_t *gen, int every)
{
    int gw = L->gw, gh = L->gh;
    size_t cells = (size_t)gw * gh;
    double g = gw > gh ? gw : gh;
    affine a;
    to_affine(q, &a);
    (*gen)++;
    double gain = 0, pen = 0;
    int seen = 0;
    for (size_t c = 0; c < cells; c++) {
        if (!L->T[c] || seen++ % every)
            continue;
        double ux = ((double)(c % gw) + 0.5) / gw, uy = 1 - ((double)(c / gw) + 0.5) / gh;
        double vx = a.m[0][0] * ux + a.m[0][1] * uy + a.t[0];
        double vy = a.m[1][0] * ux + a.m[1][1] * uy + a.t[1];
        if (!(vx >= 0 && vx < 1 && vy > 0 && vy <= 1)) {
            pen += 0.25 * g;
            continue;
        }
        int ix = (int)(vx * gw), iy = (int)((1 - vy) * gh);
        if (ix >= gw)
            ix = gw - 1;
        if (iy >= gh)
            iy = gh - 1;
        size_t k = (size_t)iy * gw + ix;
        if (L->T[k]) {
            if (!covered[k] && stamp[k] != *gen) {
                stamp[k] = *gen;
                gain++;
            }
        } else {
            pen += L->dT[k];
        }
    }
    return gain - pen * fabs(SMAX * tanh(q[2]) * SMAX * tanh(q[3]));
}

/* variant 0: on collage_level, positions on a grid over the bounding box, each winner
 * polished; variant 1: on the coarsest level, positions on up to 64 target cells */
static void collage_init(fitter *F, int n, double *x, unsigned char *covered, uint32_t *stamp, int variant)
{
    const level *L = &F->lv[variant ? 0 : collage_level(F)];
    int gw = L->gw, gh = L->gh;
    size_t cells = (size_t)gw * gh;
    /* moments */
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    for (int cy = 0; cy < gh; cy++)
        for (int cx = 0; cx < gw; cx++)
            if (L->T[(size_t)cy * gw + cx]) {
                double px = (cx + 0.5) / gw, py = 1 - (cy + 0.5) / gh;
                sx += px, sy += py, sxx += px * px, syy += py * py, sxy += px * py;
            }
    double mx = sx / L->nt, my = sy / L->nt;
    double vxx = sxx / L->nt - mx * mx, vyy = syy / L->nt - my * my, vxy = sxy / L->nt - mx * my;
    double alpha = 0.5 * atan2(2 * vxy, vxx - vyy);
    F->cx = mx, F->cy = my;
    /* candidate positions: a 12×12 grid over the target's bounding box (the image of the
     * centroid often lies in a hole of the target, so not only target cells) */
    double x0 = 1, x1 = 0, y0 = 1, y1 = 0;
    for (size_t c = 0; c < cells; c++)
        if (L->T[c]) {
            double ux = ((double)(c % gw) + 0.5) / gw, uy = 1 - ((double)(c / gw) + 0.5) / gh;
            x0 = fmin(x0, ux), x1 = fmax(x1, ux), y0 = fmin(y0, uy), y1 = fmax(y1, uy);
        }
    int npos = 0, side = quick(F) ? 4 : 12;
    double px[144], py[144];
    for (int j = 0; j < side && !variant; j++)
        for (int i = 0; i < side; i++) {
            px[npos] = x0 + (x1 - x0) * (i + 0.5) / side;
            py[npos++] = y0 + (y1 - y0) * (j + 0.5) / side;
        }
    if (variant) {
        int most = quick(F) ? 16 : 64, stride = (L->nt + most - 1) / most, t = 0;
        for (size_t c = 0; c < cells; c++)
            if (L->T[c] && t++ % stride == 0 && npos < most) {
                px[npos] = ((double)(c % gw) + 0.5) / gw;
                py[npos++] = 1 - ((double)(c / gw) + 0.5) / gh;
            }
    }
    int most = quick(F) ? 100 : 600; /* the search scores at most ~600 target cells (quick: ~100) */
    int every = variant ? 1 : (L->nt + most - 1) / most;
    static const double sc[8][2] = {{0.5, 0.5},  {0.35, 0.35}, {0.65, 0.65}, {0.8, 0.8},
                                    {0.25, 0.25}, {0.6, 0.3},  {0.3, 0.6},   {0.5, 0.15}};
    memset(covered, 0, cells);
    uint32_t gen = 0;
    memset(stamp, 0, cells * sizeof *stamp);
    for (int m = 0; m < n; m++) {
        double best = -HUGE_VAL, bq[NPAR] = {0};
        /* frames: the principal axes, and the picture's axes (the principal axis of a
         * shape with isotropic moments, like an equilateral triangle, is noise) */
        for (int ai = 0; ai < 2; ai++)
            for (int bi = 0; bi < 12; bi += quick(F) ? 3 : 1) /* quick: 4 rotations, not 12 */
                for (int refl = 0; refl < 2; refl++)
                    for (int si = 0; si < 8; si++)
                        for (int pi = 0; pi < npos; pi++) {
                            double al = ai ? 0 : alpha;
                            double q[NPAR] = {bi * PI / 6 + al, -al, atanh(sc[si][0] / SMAX),
                                              (refl ? -1 : 1) * atanh(sc[si][1] / SMAX), 0, 0};
                            affine a;
                            to_affine(q, &a);
                            q[4] = px[pi] - (a.m[0][0] * mx + a.m[0][1] * my);
                            q[5] = py[pi] - (a.m[1][0] * mx + a.m[1][1] * my);
                            double score = collage_score(L, q, covered, stamp, &gen, every);
                            if (score > best) {
                                best = score;
                                memcpy(bq, q, sizeof bq);
                            }
                        }
        best = collage_score(L, bq, covered, stamp, &gen, 1);
        /* local polish of the winner: shifts of up to 2 cells, scale ±10 %, rotation ±5° */
        for (int round = 0; round < (variant ? 0 : quick(F) ? 1 : 2); round++) {
            double base[NPAR];
            memcpy(base, bq, sizeof base);
            for (int dy = -2; dy <= 2; dy++)
                for (int dx = -2; dx <= 2; dx++)
                    for (int ds = -1; ds <= 1; ds++)
                        for (int dr = -1; dr <= 1; dr++) {
                            double q[NPAR];
                            memcpy(q, base, sizeof q);
                            double f = 1 + 0.1 * ds;
                            for (int i = 2; i < 4; i++) {
                                double sv = SMAX * tanh(q[i]) * f;
                                sv = sv > 0.97 ? 0.97 : sv < -0.97 ? -0.97 : sv;
                                q[i] = atanh(sv / SMAX);
                            }
                            q[0] += dr * PI / 36;
                            q[4] += (double)dx / gw;
                            q[5] += (double)dy / gh;
                            double score = collage_score(L, q, covered, stamp, &gen, 1);
                            if (score > best) {
                                best = score;
                                memcpy(bq, q, sizeof bq);
                            }
                        }
        }
        memcpy(x + m * NPAR, bq, sizeof bq);
        affine a;
        to_affine(bq, &a);
        for (size_t c = 0; c < cells; c++) {
            if (!L->T[c])
                continue;
            double ux = ((double)(c % gw) + 0.5) / gw, uy = 1 - ((double)(c / gw) + 0.5) / gh;
            double vx = a.m[0][0] * ux + a.m[0][1] * uy + a.t[0];
            double vy = a.m[1][0] * ux + a.m[1][1] * uy + a.t[1];
            if (vx >= 0 && vx < 1 && vy > 0 && vy <= 1) {
                int ix = (int)(vx * gw), iy = (int)((1 - vy) * gh);
                covered[(size_t)(iy < gh ? iy : gh - 1) * gw + (ix < gw ? ix : gw - 1)] = 1;
            }
        }
    }
    for (int i = 0; i < n; i++)
        x[n * NPAR + i] = 0; /* log-weights */
}

/* ---- the evolution strategy -------------------------------------------------------------- */

static const double step_scale[NPAR] = {3.0, 3.0, 2.0, 2.0, 0.5, 0.5};

static void offspring(void *ctx, size_t k, int worker)
{
    (void)worker;
    fitter *F = ctx;
    int n = F->n, np = nparams(F, n);
    double *c = F->cand[k];
    memcpy(c, F->x, sizeof(double) * (size_t)np);
    rng r;
    rng_init(&r, F->o->seed, rng_hash3(F->stream, (uint64_t)F->gen, k, (uint64_t)F->li));
    if (F->mode == 1) {
        int j = (int)(rng_uniform(&r) * n);
        c[n * NPAR + j] += 0.5 * rng_normal(&r);
    } else if (F->o->rifs && rng_uniform(&r) < 0.2) { /* forbid or allow one transition */
        int t = (int)(rng_uniform(&r) * n * n);
        double *al = c + n * NPAR + n;
        al[t] = al[t] != 0 ? 0 : 1;
        if (!irreducible(al, n)) {
            F->loss[k] = HUGE_VAL;
            return;
        }
    } else {
        double u = rng_uniform(&r);
        int j = (int)(rng_uniform(&r) * n);
        if (u < 0.75) { /* one map: all its parameters, or its translation, or its linear part */
            double v = rng_uniform(&r);
            int lo = v < 0.75 ? 0 : 4, hi = v < 0.5 || v >= 0.75 ? NPAR : 4;
            for (int i = lo; i < hi; i++)
                c[j * NPAR + i] += F->sigma * step_scale[i] * rng_normal(&r);
        } else if (u < 0.95) {
            for (int m = 0; m < n; m++)
                for (int i = 0; i < NPAR; i++)
                    c[m * NPAR + i] += F->sigma / 3 * step_scale[i] * rng_normal(&r);
        } else { /* a jump: map j's image of the centroid moves to a random target cell */
            const level *L = &F->lv[F->li];
            size_t want = (size_t)(rng_uniform(&r) * L->nt), seen = 0, cells = (size_t)L->gw * L->gh;
            for (size_t cc = 0; cc < cells; cc++)
                if (L->T[cc] && seen++ == want) {
                    affine a;
                    to_affine(c + j * NPAR, &a);
                    double qx = ((double)(cc % L->gw) + 0.5) / L->gw, qy = 1 - ((double)(cc / L->gw) + 0.5) / L->gh;
                    c[j * NPAR + 4] = qx - (a.m[0][0] * F->cx + a.m[0][1] * F->cy);
                    c[j * NPAR + 5] = qy - (a.m[1][0] * F->cx + a.m[1][1] * F->cy);
                    break;
                }
        }
        for (int m = 0; m < n; m++) /* keep u finite and the maps inside a sane box */
            for (int i = 2; i < NPAR; i++) {
                double lim = i < 4 ? 6.0 : 3.0;
                if (c[m * NPAR + i] > lim)
                    c[m * NPAR + i] = lim;
                if (c[m * NPAR + i] < -lim)
                    c[m * NPAR + i] = -lim;
            }
    }
    F->loss[k] = eval_loss(F, c, n, &F->lv[F->li], &F->sc[k]);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* ---- setup ------------------------------------------------------------------------------- */

static void fitter_free(fitter *F)
{
    for (int i = 0; i < F->nlv; i++) {
        rt_free(F->lv[i].T);
        rt_free(F->lv[i].dT);
    }
    for (int k = 0; k < FIT_LAMBDA; k++) {
        rt_free(F->sc[k].hit);
        rt_free(F->sc[k].dA);
        rt_free(F->sc[k].f);
        rt_free(F->sc[k].d);
        rt_free(F->sc[k].z);
        rt_free(F->sc[k].v);
    }
}

static rt_code fitter_init(fitter *F, const fit_mask *t, rt_error *e)
{
    static const int sides[NLEVELS] = {32, 64, 128, 256};
    int longer = t->w > t->h ? t->w : t->h;
    for (int i = 0; i < NLEVELS; i++) {
        int side = sides[i];
        if (i > 0 && sides[i - 1] >= longer)
            break;
        double sc = side >= longer ? 1.0 : (double)side / longer;
        level *L = &F->lv[F->nlv++];
        L->gw = sc == 1.0 ? t->w : (int)fmax(2, floor(t->w * sc + 0.5));
        L->gh = sc == 1.0 ? t->h : (int)fmax(2, floor(t->h * sc + 0.5));
        size_t cells = (size_t)L->gw * L->gh;
        L->T = rt_calloc(cells, 1);
        L->dT = rt_mallocn(cells, sizeof(double));
        if (!L->T || !L->dT)
            return rt_fail(e, RT_ENOMEM, "out of memory");
        /* max-pool: a cell is foreground if any mask pixel in it is */
        for (int py = 0; py < t->h; py++)
            for (int px = 0; px < t->w; px++)
                if (t->m[(size_t)py * t->w + px]) {
                    int cx = (int)((long)px * L->gw / t->w), cy = (int)((long)py * L->gh / t->h);
                    L->T[(size_t)cy * L->gw + cx] = 1;
                }
        for (size_t c = 0; c < cells; c++)
            L->nt += L->T[c];
        double p = 10.0 * L->nt;
        p = p < FIT_MIN_POINTS ? FIT_MIN_POINTS : p > 1048576 ? 1048576 : p;
        if (F->o->max_points > 0 && p > F->o->max_points) /* --max-points */
            p = F->o->max_points >= 1 ? floor(F->o->max_points) : 1;
        L->points = (uint32_t)p;
    }
    const level *fine = &F->lv[F->nlv - 1];
    int side = fine->gw > fine->gh ? fine->gw : fine->gh;
    size_t cells = (size_t)fine->gw * fine->gh;
    for (int k = 0; k < FIT_LAMBDA; k++) {
        scratch *s = &F->sc[k];
        s->hit = rt_malloc(cells);
        s->dA = rt_mallocn(cells, sizeof(double));
        s->f = rt_mallocn((size_t)side, sizeof(double));
        s->d = rt_mallocn((size_t)side, sizeof(double));
        s->z = rt_mallocn((size_t)side + 1, sizeof(double));
        s->v = rt_mallocn((size_t)side, sizeof(int));
        if (!s->hit || !s->dA || !s->f || !s->d || !s->z || !s->v)
            return rt_fail(e, RT_ENOMEM, "out of memory");
    }
    for (int i = 0; i < F->nlv; i++)
        dt2(F->lv[i].T, F->lv[i].gw, F->lv[i].gh, F->lv[i].dT, &F->sc[0]);
    return RT_OK;
}

/* ---- the level schedule ---------------------------------------------------------------- */

static const double share[NLEVELS][NLEVELS] = {
    {1, 0, 0, 0}, {0.6, 0.4, 0, 0}, {0.45, 0.35, 0.2, 0}, {0.4, 0.3, 0.2, 0.1}};

/* generations of level li (li == nlv: the probability stage) */
static long level_gens(const fitter *F, int li)
{
    long total = F->o->iterations;
    if (li == F->nlv)
        return total / 10 > 0 ? total / 10 : 1;
    return (long)ceil(total * share[F->nlv - 1][li]);
}

/* levels run from every start: the 32- and 64-cell grids (or only the first when there
 * are at most two levels) */
static int coarse_levels(const fitter *F) { return F->nlv >= 3 ? 2 : 1; }

static long gens_per_count(const fitter *F)
{
    int starts = nstarts(F);
    long g = 0;
    for (int li = 0; li <= F->nlv; li++)
        g += level_gens(F, li) * (li < coarse_levels(F) ? starts : 1);
    return g;
}

static int cancelled(const rt_run *run) { return run && run->cancel && *run->cancel; }

/* Levels lo .. hi-1 of the schedule (hi = nlv + 1 includes the probability stage) on x. */
static rt_code run_levels(fitter *F, double *x, int lo, int hi, int start, const rt_run *run, const rt_run *prun,
                          progress *pg, double t0, long *gens_done, int *timed_out)
{
    int n = F->n, np = nparams(F, n);
    F->x = x;
    for (int li = lo; li < hi && !*timed_out; li++) {
        int last = li == F->nlv; /* the probability stage, on the finest level */
        F->li = last ? F->nlv - 1 : li;
        F->mode = last;
        long gens = level_gens(F, li);
        double cur = eval_loss(F, x, n, &F->lv[F->li], &F->sc[0]);
        if (li > 0 && !last)
            F->sigma = fmax(0.02, F->sigma * 0.6);
        for (long g = 0; g < gens; g++) {
            F->gen = g;
            F->stream = 0x657300 + (uint64_t)li + 16 * (uint64_t)start;
            rt_code c = par_for(prun, NULL, FIT_LAMBDA, offspring, F);
            if (c)
                return c;
            int best = 0;
            for (int k = 1; k < FIT_LAMBDA; k++)
                if (F->loss[k] < F->loss[best])
                    best = k;
            if (F->loss[best] <= cur) {
                int improved = F->loss[best] < cur;
                cur = F->loss[best];
                memcpy(x, F->cand[best], sizeof(double) * (size_t)np);
                if (improved)
                    F->sigma = fmin(0.5, F->sigma * 1.2);
            } else {
                F->sigma = fmax(0.003, F->sigma * 0.97);
            }
            (*gens_done)++;
            progress_step(pg, 1);
            if (cancelled(run))
                return RT_ECANCEL;
            if (F->o->time_s > 0 && now_s() - t0 > F->o->time_s) {
                *timed_out = 1;
                break;
            }
        }
    }
    return RT_OK;
}

/* ---- one map count ---------------------------------------------------------------------- */

static rt_code fit_count(fitter *F, int n, const rt_run *run, progress *pg, double t0, double *x, double *loss,
                         long *gens_done, int *timed_out)
{
    const fit_opts *o = F->o;
    *loss = HUGE_VAL; /* no fit yet: what an error return leaves */
    double x2[XLEN]; /* the second collage variant (starts 1 and 3) */
    size_t cells0 = (size_t)F->lv[0].gw * F->lv[0].gh;
    if (o->start) {
        for (int i = 0; i < n; i++) {
            const affine *a = &o->start[i];
            double th, s1, s2, ph;
            double m2[2][2] = {{a->m[0][0], a->m[0][1]}, {a->m[1][0], a->m[1][1]}};
            fit_svd2(m2, &th, &s1, &s2, &ph);
            double lim = SMAX * 0.999;
            s1 = s1 > lim ? lim : s1;
            s2 = s2 > lim ? lim : s2 < -lim ? -lim : s2;
            double q[NPAR] = {th, ph, atanh(s1 / SMAX), atanh(s2 / SMAX), a->t[0], a->t[1]};
            memcpy(x + i * NPAR, q, sizeof q);
            x[n * NPAR + i] = 0;
        }
        /* centroid for the jumps */
        const level *L = &F->lv[0];
        double sx = 0, sy = 0;
        for (size_t c = 0; c < cells0; c++)
            if (L->T[c]) {
                sx += ((double)(c % L->gw) + 0.5) / L->gw;
                sy += 1 - ((double)(c / L->gw) + 0.5) / L->gh;
            }
        F->cx = sx / L->nt, F->cy = sy / L->nt;
    } else {
        const level *CLv = &F->lv[collage_level(F)];
        size_t ccells = (size_t)CLv->gw * CLv->gh;
        unsigned char *covered = rt_malloc(ccells);
        uint32_t *stamp = rt_mallocn(ccells, sizeof *stamp);
        if (!covered || !stamp) {
            rt_free(covered);
            rt_free(stamp);
            return RT_ENOMEM;
        }
        collage_init(F, n, x2, covered, stamp, 1);
        collage_init(F, n, x, covered, stamp, 0);
        rt_free(covered);
        rt_free(stamp);
    }
    if (o->start)
        memcpy(x2, x, sizeof x2);
    for (int i = 0; i < n * n; i++) /* a RIFS starts as the IFS: every transition allowed */
        x[n * NPAR + n + i] = x2[n * NPAR + n + i] = 1;
    rt_run prun = run ? *run : (rt_run){.threads = 1};
    prun.progress = 0; /* the fit draws its own bar */
    F->n = n;
    /* the coarse levels from FIT_STARTS starts (the two collages, as they are and moved, each
     * with its own offspring streams); the best on the last coarse level goes on to the fine
     * levels */
    int hi = coarse_levels(F), starts = nstarts(F), np = nparams(F, n);
    double bestx[XLEN], best = HUGE_VAL, bsigma = 0.15;
    for (int st = 0; st < starts && !*timed_out; st++) {
        double xs[XLEN];
        memcpy(xs, st % 2 ? x2 : x, sizeof(double) * (size_t)np);
        if (st % 4 >= 2) {
            rng r;
            rng_init(&r, o->seed, rng_hash3(0x7374617274ull, (uint64_t)st, (uint64_t)n, 0));
            for (int m = 0; m < n; m++)
                for (int i = 0; i < NPAR; i++)
                    xs[m * NPAR + i] += 0.1 * step_scale[i] * rng_normal(&r);
        }
        F->sigma = 0.15;
        rt_code c = run_levels(F, xs, 0, hi, st, run, &prun, pg, t0, gens_done, timed_out);
        if (c)
            return c;
        double l = eval_loss(F, xs, n, &F->lv[hi - 1], &F->sc[0]);
        if (st == 0 || l < best) { /* the first start always counts: a NaN loss leaves bestx set */
            best = l;
            bsigma = F->sigma;
            memcpy(bestx, xs, sizeof(double) * (size_t)np);
        }
    }
    memcpy(x, bestx, sizeof(double) * (size_t)np);
    F->sigma = bsigma;
    if (!*timed_out) {
        rt_code c = run_levels(F, x, hi, F->nlv + 1, 0, run, &prun, pg, t0, gens_done, timed_out);
        if (c)
            return c;
    }
    *loss = eval_loss(F, x, n, &F->lv[F->nlv - 1], &F->sc[0]);
    return RT_OK;
}

rt_code fit_run(const fit_mask *t, const fit_opts *o, const rt_run *run, fit_result *r, rt_error *e)
{
    memset(r, 0, sizeof *r);
    if (t->w < 2 || t->h < 2)
        return rt_fail(e, RT_EINVAL, "the target is %d×%d pixels (a target needs at least 2×2)", t->w, t->h);
    size_t npx = (size_t)t->w * t->h, nfg = 0;
    for (size_t i = 0; i < npx; i++)
        nfg += t->m[i] != 0;
    if (nfg == 0)
        return rt_fail(e, RT_EINVAL, "the target has no foreground pixels (nothing to fit)");
    if (nfg == npx)
        return rt_fail(e, RT_EINVAL, "every pixel of the target is foreground (a fit needs some background)");
    if (o->nmin < 1 || o->nmax > FIT_MAX_MAPS || o->nmin > o->nmax)
        return rt_fail(e, RT_EINVAL, "maps must be from 1 to %d (got %d..%d)", FIT_MAX_MAPS, o->nmin, o->nmax);
    if (o->start && (o->nstart != o->nmin || o->nstart != o->nmax))
        return rt_fail(e, RT_EINVAL, "the start IFS has %d maps but maps is %d..%d", o->nstart, o->nmin, o->nmax);
    if (o->iterations < 1)
        return rt_fail(e, RT_EINVAL, "iterations must be >= 1");
    if (!(o->max_points >= 0))
        return rt_fail(e, RT_EINVAL, "the points cap must be >= 0 (0: none)");
    fitter *F = rt_calloc(1, sizeof *F);
    if (!F)
        return rt_fail(e, RT_ENOMEM, "out of memory");
    F->o = o;
    rt_code c = fitter_init(F, t, e);
    progress pg;
    long per = c ? 0 : gens_per_count(F);
    progress_begin(&pg, "fit", (size_t)per * (size_t)(o->nmax - o->nmin + 1), run ? run->progress : 0);
    double t0 = now_s(), best = HUGE_VAL;
    int timed_out = 0;
    const level *fine = &F->lv[F->nlv - 1];
    double to256 = 256.0 / (fine->gw > fine->gh ? fine->gw : fine->gh);
    for (int n = o->nmin; !c && n <= o->nmax && !timed_out; n++) {
        double x[XLEN], loss;
        c = fit_count(F, n, run, &pg, t0, x, &loss, &r->generations, &timed_out);
        if (c == RT_ENOMEM)
            rt_fail(e, c, "out of memory");
        else if (c == RT_ECANCEL)
            rt_fail(e, c, "interrupted");
        else if (c)
            rt_fail(e, c, "fit failed");
        if (c)
            break;
        double score = loss * to256 + FIT_PENALTY * n;
        if (score < best) {
            best = score;
            r->n = n;
            r->loss = loss;
            r->loss256 = loss * to256;
            for (int i = 0; i < n; i++)
                to_affine(x + i * NPAR, &r->maps[i]);
            weights(x, n, r->p);
            r->rifs = o->rifs;
            transitions(F, x, n, r->p, r->P);
        }
    }
    progress_end(&pg);
    for (int k = 0; k < FIT_LAMBDA; k++)
        r->points += F->sc[k].drawn;
    fitter_free(F);
    rt_free(F);
    return c;
}

fit_fg fit_mask_from_image(const image *im, fit_fg mode, double threshold, unsigned char *out)
{
    size_t n = (size_t)im->w * im->h;
    if (mode == FIT_FG_AUTO) {
        mode = FIT_FG_DARK;
        for (size_t i = 0; i < n; i++)
            if (im->px[4 * i + 3] < 1) {
                mode = FIT_FG_ALPHA;
                break;
            }
        if (mode != FIT_FG_ALPHA) {
            double sum = 0;
            long cnt = 0;
            for (int y = 0; y < im->h; y++)
                for (int x = 0; x < im->w; x++)
                    if (y == 0 || x == 0 || y == im->h - 1 || x == im->w - 1) {
                        const float *p = image_at(im, x, y);
                        sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                        cnt++;
                    }
            mode = sum / cnt >= 0.5 ? FIT_FG_DARK : FIT_FG_LIGHT;
        }
    }
    for (size_t i = 0; i < n; i++) {
        const float *p = im->px + 4 * i;
        double l = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        out[i] = mode == FIT_FG_ALPHA ? p[3] >= threshold : mode == FIT_FG_DARK ? l < threshold : l >= threshold;
    }
    return mode;
}
