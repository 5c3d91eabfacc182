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

#endif
