/* field_eval.c — running compiled field programs over blocks of points,
 * and filling volumes from fields. See field.h. */
#include "field.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "density.h"
#include "image.h"
#include "noise.h"
#include "par.h"

/* One switch per instruction per block; each case a tight loop. dst never
 * aliases an operand (the register allocator guarantees it). */
#define LOOP1(expr)                                                                                \
    do {                                                                                           \
        for (size_t i = 0; i < n; i++) {                                                           \
            double A = a[i];                                                                       \
            d[i] = (expr);                                                                         \
        }                                                                                          \
    } while (0)
#define LOOP2(expr)                                                                                \
    do {                                                                                           \
        for (size_t i = 0; i < n; i++) {                                                           \
            double A = a[i], B = b[i];                                                             \
            d[i] = (expr);                                                                         \
        }                                                                                          \
    } while (0)
#define LOOP3(expr)                                                                                \
    do {                                                                                           \
        for (size_t i = 0; i < n; i++) {                                                           \
            double A = a[i], B = b[i], C = c[i];                                                   \
            d[i] = (expr);                                                                         \
        }                                                                                          \
    } while (0)

void field_run(const field_instr *code, size_t ncode, double *const *reg, size_t n)
{
    for (size_t pc = 0; pc < ncode; pc++) {
        const field_instr *in = &code[pc];
        double *restrict d = reg[in->dst];
        const double *a = reg[in->a], *b = reg[in->b], *c = reg[in->c];
        switch (in->op) {
        case FOP_UNARY + FIELD_NEG: LOOP1(-A); break;
        case FOP_UNARY + FIELD_NOT: LOOP1(A == 0 ? 1.0 : 0.0); break;
        case FOP_UNARY + FIELD_ABS: LOOP1(fabs(A)); break;
        case FOP_UNARY + FIELD_FLOOR: LOOP1(floor(A)); break;
        case FOP_UNARY + FIELD_CEIL: LOOP1(ceil(A)); break;
        case FOP_UNARY + FIELD_ROUND: LOOP1(floor(A + 0.5)); break;
        case FOP_UNARY + FIELD_FRACT: LOOP1(A - floor(A)); break;
        case FOP_UNARY + FIELD_SIGN: LOOP1(A > 0 ? 1.0 : A < 0 ? -1.0 : A); break;
        case FOP_UNARY + FIELD_SQRT: LOOP1(sqrt(A)); break;
        case FOP_UNARY + FIELD_EXP: LOOP1(exp(A)); break;
        case FOP_UNARY + FIELD_LOG: LOOP1(log(A)); break;
        case FOP_UNARY + FIELD_SIN: LOOP1(sin(A)); break;
        case FOP_UNARY + FIELD_COS: LOOP1(cos(A)); break;
        case FOP_UNARY + FIELD_TAN: LOOP1(tan(A)); break;
        case FOP_UNARY + FIELD_ASIN: LOOP1(asin(A)); break;
        case FOP_UNARY + FIELD_ACOS: LOOP1(acos(A)); break;
        case FOP_UNARY + FIELD_ATAN: LOOP1(atan(A)); break;
        case FOP_UNARY + FIELD_SINH: LOOP1(sinh(A)); break;
        case FOP_UNARY + FIELD_COSH: LOOP1(cosh(A)); break;
        case FOP_UNARY + FIELD_TANH: LOOP1(tanh(A)); break;

        case FOP_BINARY + FIELD_ADD: LOOP2(A + B); break;
        case FOP_BINARY + FIELD_SUB: LOOP2(A - B); break;
        case FOP_BINARY + FIELD_MUL: LOOP2(A * B); break;
        case FOP_BINARY + FIELD_DIV: LOOP2(A / B); break;
        case FOP_BINARY + FIELD_POW: LOOP2(pow(A, B)); break;
        case FOP_BINARY + FIELD_MIN: LOOP2(A < B ? A : B); break;
        case FOP_BINARY + FIELD_MAX: LOOP2(A > B ? A : B); break;
        case FOP_BINARY + FIELD_LT: LOOP2(A < B ? 1.0 : 0.0); break;
        case FOP_BINARY + FIELD_LE: LOOP2(A <= B ? 1.0 : 0.0); break;
        case FOP_BINARY + FIELD_GT: LOOP2(A > B ? 1.0 : 0.0); break;
        case FOP_BINARY + FIELD_GE: LOOP2(A >= B ? 1.0 : 0.0); break;
        case FOP_BINARY + FIELD_EQ: LOOP2(A == B ? 1.0 : 0.0); break;
        case FOP_BINARY + FIELD_NE: LOOP2(A != B ? 1.0 : 0.0); break;
        case FOP_BINARY + FIELD_AND: LOOP2(A != 0 && B != 0 ? 1.0 : 0.0); break;
        case FOP_BINARY + FIELD_OR: LOOP2(A != 0 || B != 0 ? 1.0 : 0.0); break;
        case FOP_BINARY + FIELD_ATAN2: LOOP2(atan2(A, B)); break;
        case FOP_BINARY + FIELD_MOD: LOOP2(A - B * floor(A / B)); break;

        case FOP_SELECT: LOOP3(A != 0 ? B : C); break;
        case FOP_CLAMP: LOOP3(A < B ? B : A > C ? C : A); break;
        case FOP_LERP: LOOP3(A + C * (B - A)); break;
        case FOP_EXTERNAL: in->fn(in->ptr, n, a, b, c, d); break;
        case FOP_PERLIN: noise_perlin3_block(in->ptr, n, a, b, c, d); break;
        case FOP_FBM:
            noise_fbm3_block(in->ptr, in->octaves, in->k[0], in->k[1], n, a, b, c, d);
            break;
        case FOP_TURB: noise_turbulence3_block(in->ptr, in->octaves, n, a, b, c, d); break;
        case FOP_DENSITY: density_eval_block(in->ptr, n, a, b, c, d); break;
        case FOP_SDF: density_sdf_block(in->ptr, in->k[0], n, a, b, c, d); break;
        case FOP_SUNION: {
            double k = in->k[0];
            LOOP2(density_smooth_union(A, B, k));
            break;
        }
        case FOP_BIAS: dmf_bias_block(in->k[0], n, a, d); break;
        case FOP_GAIN: dmf_gain_block(in->k[0], n, a, d); break;
        case FOP_SMOOTHSTEP: dmf_smoothstep_block(in->k[0], in->k[1], n, a, d); break;
        case FOP_STEP: {
            double e = in->k[0];
            LOOP1(A >= e ? 1.0 : 0.0);
            break;
        }
        case FOP_AFFINE: {
            double s = in->k[0], o = in->k[1];
            LOOP1(A * s + o);
            break;
        }
        default: break;
        }
    }
}

size_t field_prog_scratch_size(const field_prog *p)
{
    return rt_mul_size(p->nconst + p->ntemp, RT_BLOCK);
}

#define STACK_DOUBLES 4096 /* 32 KiB of registers on the C stack */

/* Run p over n points in blocks of at most blk, with registers in scratch
 * ((nconst + ntemp) * blk doubles). */
static void run_blocks(const field_prog *p, double *scratch, size_t blk, size_t n, const double *x,
                       const double *y, const double *z, double *out)
{
    size_t nr = 3 + p->nconst + p->ntemp;
    double *regbuf[3 + 256];
    double **reg = nr <= 3 + 256 ? regbuf : rt_malloc(nr * sizeof *reg);
    if (!reg) {
        for (size_t i = 0; i < n; i++)
            out[i] = NAN;
        return;
    }
    for (size_t r = 3; r < nr; r++)
        reg[r] = scratch + (r - 3) * blk;
    for (size_t k = 0; k < p->nconst; k++)
        for (size_t i = 0; i < blk && i < n; i++)
            reg[3 + k][i] = p->consts[k];
    for (size_t s = 0; s < n; s += blk) {
        size_t m = n - s < blk ? n - s : blk;
        reg[0] = (double *)(x + s); /* inputs are only read */
        reg[1] = (double *)(y + s);
        reg[2] = (double *)(z + s);
        field_run(p->code, p->ncode, reg, m);
        memcpy(out + s, reg[p->result], m * sizeof *out);
    }
    if (reg != regbuf)
        rt_free(reg);
}

void field_prog_eval_scratch(const field_prog *p, double *scratch, size_t n, const double *x,
                             const double *y, const double *z, double *out)
{
    run_blocks(p, scratch, RT_BLOCK, n, x, y, z, out);
}

void field_prog_eval(const field_prog *p, size_t n, const double *x, const double *y,
                     const double *z, double *out)
{
    double stack[STACK_DOUBLES];
    size_t nr = p->nconst + p->ntemp;
    size_t blk = RT_BLOCK;
    if (nr * blk > STACK_DOUBLES)
        blk = nr ? STACK_DOUBLES / nr : RT_BLOCK;
    if (blk >= 16) {
        run_blocks(p, stack, blk, n, x, y, z, out);
        return;
    }
    double *heap = rt_malloc(rt_mul_size(nr, RT_BLOCK) * sizeof *heap);
    if (!heap) {
        for (size_t i = 0; i < n; i++)
            out[i] = NAN;
        return;
    }
    run_blocks(p, heap, RT_BLOCK, n, x, y, z, out);
    rt_free(heap);
}

void field_prog_fn(const void *prog, size_t n, const double *x, const double *y, const double *z,
                   double *out)
{
    field_prog_eval(prog, n, x, y, z, out);
}

double field_prog_eval1(const field_prog *p, double x, double y, double z)
{
    double v;
    field_prog_eval(p, 1, &x, &y, &z, &v);
    return v;
}

/* ---- the terminal preview */

rt_code field_preview(const field_prog *p, image *im, rt_error *e)
{
    int w = im->w, h = im->h;
    double *v = rt_mallocn((size_t)w * (size_t)h, sizeof *v);
    if (!v)
        return rt_fail(e, RT_ENOMEM, "out of memory for the field preview");
    double xs[RT_BLOCK], ys[RT_BLOCK], zs[RT_BLOCK];
    for (int j = 0; j < h; j++)
        for (int i0 = 0; i0 < w; i0 += RT_BLOCK) {
            int m = w - i0 < RT_BLOCK ? w - i0 : RT_BLOCK;
            for (int i = 0; i < m; i++) {
                xs[i] = -1 + 2 * (i0 + i + 0.5) / w;
                ys[i] = 1 - 2 * (j + 0.5) / h;
                zs[i] = 0;
            }
            field_prog_eval(p, (size_t)m, xs, ys, zs, v + (size_t)j * (size_t)w + (size_t)i0);
        }
    double mn = INFINITY, mx = -INFINITY;
    size_t np = (size_t)w * (size_t)h;
    for (size_t i = 0; i < np; i++)
        if (isfinite(v[i])) {
            mn = v[i] < mn ? v[i] : mn;
            mx = v[i] > mx ? v[i] : mx;
        }
    for (size_t i = 0; i < np; i++) {
        float g = mx > mn && isfinite(v[i]) ? (float)((v[i] - mn) / (mx - mn)) : 0.0f;
        im->px[4 * i] = im->px[4 * i + 1] = im->px[4 * i + 2] = g;
        im->px[4 * i + 3] = 1;
    }
    rt_free(v);
    return RT_OK;
}

/* ---- volumes */

typedef struct vol_job {
    rt_field_fn fn;
    const void *ctx;
    volume *vol;
} vol_job;

static double centre(const volume *v, int axis, int i, int n)
{
    return v->lo[axis] + (v->hi[axis] - v->lo[axis]) * ((double)i + 0.5) / (double)n;
}

static void vol_slice(void *ctx, size_t chunk, int worker)
{
    (void)worker;
    vol_job *j = ctx;
    volume *v = j->vol;
    int k = (int)chunk;
    double xs[RT_BLOCK], ys[RT_BLOCK], zs[RT_BLOCK], out[RT_BLOCK];
    double zc = centre(v, 2, k, v->nz);
    for (int jy = 0; jy < v->ny; jy++) {
        double yc = centre(v, 1, jy, v->ny);
        for (int i0 = 0; i0 < v->nx; i0 += RT_BLOCK) {
            int m = v->nx - i0 < RT_BLOCK ? v->nx - i0 : RT_BLOCK;
            for (int i = 0; i < m; i++) {
                xs[i] = centre(v, 0, i0 + i, v->nx);
                ys[i] = yc;
                zs[i] = zc;
            }
            j->fn(j->ctx, (size_t)m, xs, ys, zs, out);
            float *dst = volume_at(v, i0, jy, k);
            for (int i = 0; i < m; i++)
                dst[i] = (float)out[i];
        }
    }
}

rt_code field_sample_volume(rt_field_fn fn, const void *ctx, volume *vol, const rt_run *run,
                            rt_error *e)
{
    if (!vol->v || vol->nx < 1 || vol->ny < 1 || vol->nz < 1)
        return rt_fail(e, RT_EINVAL, "volume to fill is empty (%d x %d x %d)", vol->nx, vol->ny,
                       vol->nz);
    vol_job j = {fn, ctx, vol};
    /* one chunk per z slice: a shard fills its slices, merge places them (par.h) */
    par_part pp;
    size_t slice = (size_t)vol->nx * (size_t)vol->ny * sizeof *vol->v;
    rt_code c = par_part_begin(&pp, run, "field volume", (size_t)vol->nz, e);
    if (c)
        return c;
    c = par_part_for(&pp, "field", vol_slice, &j);
    if (c == RT_ECANCEL)
        return rt_fail(e, RT_ECANCEL, "interrupted");
    return c ? c : par_part_rows(&pp, vol->v, slice * (size_t)vol->nz, slice, e);
}
