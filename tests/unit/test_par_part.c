/* test_par_part.c — sharded engine calls (par.h: par_part_*) against a fake
 * sharder: which chunks each mode runs, and what the sections hand over. */
#include <stdatomic.h>
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "par.h"

typedef struct fake {
    rt_sharder rt;
    int mode;
    size_t lo, hi;
    int sections;
    par_part_op op;
    size_t total, unit;
    unsigned char merged; /* MERGE: the byte sections fill with */
} fake;

static int f_begin(rt_sharder *s, const char *kind, size_t nchunks, size_t *lo, size_t *hi)
{
    fake *f = (fake *)s;
    (void)kind;
    (void)nchunks;
    *lo = f->lo;
    *hi = f->hi;
    return f->mode;
}

static rt_code f_section(rt_sharder *s, par_part_op op, void *buf, size_t total, size_t unit, par_combine_fn fn,
                         void *ctx, rt_error *e)
{
    fake *f = (fake *)s;
    (void)fn, (void)ctx, (void)e;
    f->sections++;
    f->op = op;
    f->total = total;
    f->unit = unit;
    if (f->mode == PAR_MERGE)
        memset(buf, f->merged, total);
    return RT_OK;
}

static atomic_int hits[100];

static void visit(void *ctx, size_t chunk, int worker)
{
    (void)ctx, (void)worker;
    atomic_fetch_add(&hits[chunk], 1);
}

static int run_mode(int mode, size_t lo, size_t hi, int threads, fake *f)
{
    memset(f, 0, sizeof *f);
    f->rt.begin = f_begin;
    f->rt.section = f_section;
    f->mode = mode;
    f->lo = lo;
    f->hi = hi;
    f->merged = 7;
    for (int i = 0; i < 100; i++)
        atomic_store(&hits[i], 0);
    rt_run run = {threads, NULL, 0};
    par_set_sharder(&f->rt);
    par_part p;
    rt_error e;
    int ok = par_part_begin(&p, &run, "test", 100, &e) == RT_OK && par_part_for(&p, "test", visit, NULL) == RT_OK;
    uint64_t acc[3] = {1, 2, 3};
    ok = ok && par_part_sum(&p, acc, 3, &e) == RT_OK;
    if (mode == PAR_MERGE)
        ok = ok && acc[0] == 0x0707070707070707ull;
    else
        ok = ok && acc[0] == 1 && acc[2] == 3;
    par_set_sharder(NULL);
    return ok;
}

int main(void)
{
    fake f;
    for (int t = 1; t <= 3; t++) {
        /* a shard runs exactly its chunks, once each, numbered as in the whole call */
        CHECK(run_mode(PAR_SHARD, 30, 57, t, &f), "shard mode failed (%d threads)", t);
        int right = 1;
        for (int i = 0; i < 100; i++)
            right &= atomic_load(&hits[i]) == (i >= 30 && i < 57);
        CHECK(right, "shard [30, 57) ran other chunks (%d threads)", t);
        CHECK(f.sections == 1 && f.op == PAR_OP_SUM && f.total == 24, "sum section: %d sections, op %d, %zu bytes",
              f.sections, f.op, f.total);
        /* merge runs no chunk; the sections fill the accumulator */
        CHECK(run_mode(PAR_MERGE, 0, 100, t, &f), "merge mode failed (%d threads)", t);
        int none = 1;
        for (int i = 0; i < 100; i++)
            none &= atomic_load(&hits[i]) == 0;
        CHECK(none, "merge ran chunks (%d threads)", t);
        /* full runs everything and hands over nothing */
        CHECK(run_mode(PAR_FULL, 0, 0, t, &f), "full mode failed (%d threads)", t);
        int all = 1;
        for (int i = 0; i < 100; i++)
            all &= atomic_load(&hits[i]) == 1;
        CHECK(all && f.sections == 0, "full mode: not every chunk once, or %d sections", f.sections);
    }
    /* without a sharder: every chunk, sections do nothing */
    for (int i = 0; i < 100; i++)
        atomic_store(&hits[i], 0);
    rt_run run = {2, NULL, 0};
    par_part p;
    rt_error e;
    CHECK(par_part_begin(&p, &run, "test", 100, &e) == RT_OK && p.mode == PAR_FULL, "no sharder: not PAR_FULL");
    CHECK(par_part_for(&p, "test", visit, NULL) == RT_OK, "no sharder: par_part_for failed");
    int all = 1;
    for (int i = 0; i < 100; i++)
        all &= atomic_load(&hits[i]) == 1;
    CHECK(all, "no sharder: not every chunk once");
    /* a refusing sharder stops the engine */
    f.rt.begin = f_begin;
    f.mode = -1;
    par_set_sharder(&f.rt);
    CHECK(par_part_begin(&p, &run, "test", 100, &e) == RT_ECANCEL, "a refusing sharder did not stop the call");
    par_set_sharder(NULL);
    return check_done("test_par_part");
}
