/* par.h — the one parallel loop of the runtime.
 *
 * par_for runs fn(ctx, chunk, worker) for chunk = 0 .. nchunks-1 on
 * run->threads POSIX threads (the caller's thread is worker 0). Chunks are
 * handed out in increasing order from a shared counter; which worker runs a
 * chunk is not deterministic, so a deterministic engine
 *   - derives all randomness from the chunk index (rng_init(&r, seed, chunk)),
 *   - writes results per chunk, or into per-worker accumulators only when the
 *     merge is exact and order-free (integer counts), and
 *   - merges per-chunk floating-point results in chunk order afterwards.
 * The chunk decomposition itself must not depend on the thread count.
 *
 * Cancellation: if run->cancel becomes non-zero, no further chunks start and
 * par_for returns RT_ECANCEL. With run->progress set and stderr a terminal, a
 * progress bar labelled `label` is drawn and erased at the end.
 */
#ifndef PAR_H
#define PAR_H

#include "rt.h"

typedef void (*par_fn)(void *ctx, size_t chunk, int worker);

rt_code par_for(const rt_run *run, const char *label, size_t nchunks, par_fn fn, void *ctx);

/* Number of online cores (>= 1). */
int par_cores(void);

/* Number of workers par_for will use for run (>= 1), for sizing per-worker
 * accumulators before the call. */
int par_workers(const rt_run *run, size_t nchunks);

/* ---- sharded engine calls (frac run --shard I/N, frac merge; docs/scale.md) ----
 *
 * An engine whose result is an exact function of its chunks' work can be
 * split across processes. It calls par_part_begin instead of going straight
 * to par_for, runs its chunks with par_part_for, and hands its raw
 * accumulator — before any normalising, tone mapping or other step that needs
 * every chunk — to par_part_sum (integer sums: counts, exact colour sums) or
 * par_part_rows (fills: chunk c owns bytes [c*chunk_bytes, (c+1)*chunk_bytes)
 * of the buffer), one call per section of the accumulator, always in the same
 * order; then it finishes exactly as in a single run.
 *
 * Without a sharder installed (every ordinary run and the C tests) the mode
 * is PAR_FULL: par_part_for is par_for and the sections do nothing.
 * Otherwise the sharder (implemented by the interpreter, interp/shard.c)
 * numbers the calls and decides, per call:
 *   PAR_SHARD  compute only the chunks [lo, hi) (shard I of N gets the
 *              contiguous range nchunks*I/N .. nchunks*(I+1)/N); the sections
 *              are recorded into the part file; what the engine makes of the
 *              incomplete accumulator afterwards is never used;
 *   PAR_MERGE  compute no chunks; the sections are filled from the parts
 *              (sums added, rows placed), so the engine finishes with the
 *              accumulator of the single run, bit for bit;
 *   PAR_FULL   compute everything (a call whose result the script inspects).
 * An engine that runs several par_for loops shards at most one of them (the
 * others run in full everywhere, before or after it). */
typedef enum par_part_mode { PAR_FULL = 0, PAR_SHARD, PAR_MERGE } par_part_mode;

typedef enum par_part_op { PAR_OP_SUM = 1, PAR_OP_ROWS = 2, PAR_OP_COMBINE = 3 } par_part_op;

/* PAR_OP_COMBINE: fold n elements of a part (part) into the accumulator
 * (acc); must be exact and order-free (a max with a total order, a min). */
typedef void (*par_combine_fn)(void *ctx, void *acc, const void *part, size_t n);

typedef struct rt_sharder {
    /* A new shardable call of `kind` (a short name) with nchunks chunks:
     * returns its mode, and for PAR_SHARD the chunk range in *lo, *hi; -1
     * stops the engine (RT_ECANCEL): the evaluation is being abandoned. */
    int (*begin)(struct rt_sharder *s, const char *kind, size_t nchunks, size_t *lo, size_t *hi);
    /* One section: op, the buffer of total bytes (SUM: total/unit
     * integers, uint64 for unit 8, uint32 for unit 4 — the same record
     * either way, its values are numbers); unit: chunk_bytes for ROWS, the
     * element size for COMBINE (with fn, ctx). Record it (PAR_SHARD) or fill it (PAR_MERGE). */
    rt_code (*section)(struct rt_sharder *s, par_part_op op, void *buf, size_t total, size_t unit,
                       par_combine_fn fn, void *ctx, rt_error *e);
} rt_sharder;

/* Install the process's sharder (NULL: none). Process-wide for the reason
 * the allocation hook is (rt_alloc.h): a process runs one interpreter at a
 * time, and rt_run is initialised positionally in many places. Set it only
 * while no engine runs. */
rt_sharder *par_set_sharder(rt_sharder *s); /* returns the previous one */

typedef struct par_part {
    const rt_run *run;
    rt_sharder *sharder;
    par_part_mode mode;
    size_t nchunks, lo, hi; /* the chunks this process computes */
} par_part;

rt_code par_part_begin(par_part *p, const rt_run *run, const char *kind, size_t nchunks, rt_error *e);
/* par_for over the chunks of p's mode (chunk numbers are the call's own: lo..hi-1). */
rt_code par_part_for(const par_part *p, const char *label, par_fn fn, void *ctx);
/* Section of n exact integer sums. */
rt_code par_part_sum(const par_part *p, uint64_t *acc, size_t n, rt_error *e);
/* The same for uint32 sums whose totals stay below 2^32 (a merge that would
 * wrap fails); a part is the same as par_part_sum's of the same values. */
rt_code par_part_sum32(const par_part *p, uint32_t *acc, size_t n, rt_error *e);
/* Section of a buffer filled chunk by chunk (the last chunk may be shorter). */
rt_code par_part_rows(const par_part *p, void *buf, size_t total_bytes, size_t chunk_bytes, rt_error *e);
/* Section of n elements of elem bytes, merged with fn (order-free). */
rt_code par_part_combine(const par_part *p, void *buf, size_t n, size_t elem, par_combine_fn fn, void *ctx,
                         rt_error *e);

#endif
