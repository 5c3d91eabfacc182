/* par.c — parallel-for over fixed chunks with POSIX threads. */
#define _POSIX_C_SOURCE 200809L
#include "par.h"

#include <pthread.h>
#include <stdatomic.h>
#include <unistd.h>

#include "progress.h"

typedef struct job {
    par_fn fn;
    void *ctx;
    size_t nchunks;
    atomic_size_t next;
    volatile sig_atomic_t *cancel;
    atomic_int cancelled;
    progress prog;
} job;

typedef struct worker_arg {
    job *j;
    int id;
} worker_arg;

static void run_worker(job *j, int id)
{
    for (;;) {
        if (j->cancel && *j->cancel) {
            atomic_store(&j->cancelled, 1);
            return;
        }
        size_t c = atomic_fetch_add(&j->next, 1);
        if (c >= j->nchunks)
            return;
        j->fn(j->ctx, c, id);
        progress_step(&j->prog, 1);
    }
}

static void *thread_main(void *p)
{
    worker_arg *a = p;
    run_worker(a->j, a->id);
    return NULL;
}

int par_cores(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > 256 ? 256 : (int)n;
}

int par_workers(const rt_run *run, size_t nchunks)
{
    int t = run && run->threads > 0 ? run->threads : 1;
    if (t > 256)
        t = 256;
    if ((size_t)t > nchunks)
        t = nchunks ? (int)nchunks : 1;
    return t;
}

rt_code par_for(const rt_run *run, const char *label, size_t nchunks, par_fn fn, void *ctx)
{
    job j;
    j.fn = fn;
    j.ctx = ctx;
    j.nchunks = nchunks;
    atomic_init(&j.next, 0);
    atomic_init(&j.cancelled, 0);
    j.cancel = run ? run->cancel : NULL;
    progress_begin(&j.prog, label, nchunks, run ? run->progress : 0);

    int nt = par_workers(run, nchunks);
    pthread_t th[256];
    worker_arg args[256];
    int started = 0;
    for (int i = 1; i < nt; i++) {
        args[i].j = &j;
        args[i].id = i;
        if (pthread_create(&th[i], NULL, thread_main, &args[i]) != 0)
            break; /* fewer threads is still correct */
        started = i;
    }
    run_worker(&j, 0);
    for (int i = 1; i <= started; i++)
        pthread_join(th[i], NULL);
    progress_end(&j.prog);
    return atomic_load(&j.cancelled) ? RT_ECANCEL : RT_OK;
}

/* ---- sharded engine calls ---- */

static rt_sharder *the_sharder;

rt_sharder *par_set_sharder(rt_sharder *s)
{
    rt_sharder *old = the_sharder;
    the_sharder = s;
    return old;
}

rt_code par_part_begin(par_part *p, const rt_run *run, const char *kind, size_t nchunks, rt_error *e)
{
    p->run = run;
    p->sharder = the_sharder;
    p->mode = PAR_FULL;
    p->nchunks = nchunks;
    p->lo = 0;
    p->hi = nchunks;
    if (!p->sharder)
        return RT_OK;
    size_t lo = 0, hi = nchunks;
    int m = p->sharder->begin(p->sharder, kind, nchunks, &lo, &hi);
    if (m < 0)
        return rt_fail(e, RT_ECANCEL, "%s: evaluation abandoned (it is re-run)", kind);
    p->mode = (par_part_mode)m;
    if (p->mode == PAR_SHARD) {
        p->lo = lo < nchunks ? lo : nchunks;
        p->hi = hi < p->lo ? p->lo : hi < nchunks ? hi : nchunks;
    } else if (p->mode == PAR_MERGE) {
        p->lo = p->hi = 0;
    }
    return RT_OK;
}

typedef struct offset_job {
    par_fn fn;
    void *ctx;
    size_t lo;
} offset_job;

static void offset_chunk(void *ctx, size_t chunk, int worker)
{
    const offset_job *o = ctx;
    o->fn(o->ctx, o->lo + chunk, worker);
}

rt_code par_part_for(const par_part *p, const char *label, par_fn fn, void *ctx)
{
    if (p->mode == PAR_FULL)
        return par_for(p->run, label, p->nchunks, fn, ctx);
    if (p->hi <= p->lo)
        return RT_OK;
    offset_job o = {fn, ctx, p->lo};
    return par_for(p->run, label, p->hi - p->lo, offset_chunk, &o);
}

rt_code par_part_sum(const par_part *p, uint64_t *acc, size_t n, rt_error *e)
{
    if (p->mode == PAR_FULL)
        return RT_OK;
    return p->sharder->section(p->sharder, PAR_OP_SUM, acc, n * sizeof *acc, sizeof *acc, NULL, NULL, e);
}

rt_code par_part_sum32(const par_part *p, uint32_t *acc, size_t n, rt_error *e)
{
    if (p->mode == PAR_FULL)
        return RT_OK;
    return p->sharder->section(p->sharder, PAR_OP_SUM, acc, n * sizeof *acc, sizeof *acc, NULL, NULL, e);
}

rt_code par_part_rows(const par_part *p, void *buf, size_t total_bytes, size_t chunk_bytes, rt_error *e)
{
    if (p->mode == PAR_FULL)
        return RT_OK;
    return p->sharder->section(p->sharder, PAR_OP_ROWS, buf, total_bytes, chunk_bytes, NULL, NULL, e);
}

rt_code par_part_combine(const par_part *p, void *buf, size_t n, size_t elem, par_combine_fn fn, void *ctx,
                         rt_error *e)
{
    if (p->mode == PAR_FULL)
        return RT_OK;
    return p->sharder->section(p->sharder, PAR_OP_COMBINE, buf, n * elem, elem, fn, ctx, e);
}
