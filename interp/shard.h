/* shard.h — one render split across processes and merged byte-identically.
 *
 *   frac run --shard I/N [-o DIR] SCRIPT   shard I of N: writes DIR/NAME.shard-I-of-N.part
 *   frac merge [-o DIR] SCRIPT PART...     the outputs of `frac run -o DIR SCRIPT`
 *
 * The hook is the runtime's fixed chunks (par.h: par_part_*). Every shardable
 * engine call is numbered in evaluation order (the script evaluates the same
 * way in every process, so call k is the same call everywhere). In a shard,
 * call k computes only its contiguous range of chunks and hands its raw
 * accumulator to shard_section, which appends it as a record to the part
 * being built; the builtin's result becomes a *partial value* (its own class,
 * holding the call number). `save` of a partial value writes nothing (the
 * record is already in the part) — a shard writes no file but its part.
 * Any other use of a partial value — passed to another builtin, printed,
 * operated on, a field looked up, compared — is a *taint*: the evaluation is
 * abandoned, call k is marked "full" (computed completely in every shard,
 * recorded nowhere), a note says once which call and why, and the script
 * runs again from the start; this repeats until no taint is left (each round
 * adds one call, so it ends). A second shardable call inside the same builtin
 * while the first one's result is still pending is a taint too.
 *
 * merge first checks every part completely (header, every record's CRC-32,
 * the same script hash, params, seed, version and N, each shard exactly once,
 * the same records everywhere) and refuses with a precise error, writing
 * nothing, when one is wrong. Then it evaluates the script: call k with a
 * record takes its accumulator from the parts — sums added, rows placed,
 * streamed part by part, never N copies — and finishes as in a single run;
 * call k without a record (a full call) is computed. A split call whose
 * builtin fitted a window first (the pre-pass of chaos, measure, …) has one
 * more record after its sections, the window as doubles: the merge takes it
 * instead of fitting (shard_window_put/take). The format is in
 * docs/scale.md.
 *
 * The struct lives on main's stack across the attempts (no heap of its own
 * between them: each attempt's interpreter has its own allocation hook);
 * what one attempt allocates is freed by shard_attempt_end.
 */
#ifndef SHARD_H
#define SHARD_H

#include <stddef.h>
#include <stdint.h>

#include "fileio.h"
#include "par.h"
#include "state.h"

#define SHARD_FORMAT 4
#define SHARD_OP_WINDOW 4 /* a record's op: the window fitted for its call (after the par_part_op ones) */
#define SHARD_MAX_FULL 4096
#define SHARD_MAX_PARTS 65536

typedef struct shard_rec shard_rec;

typedef struct shard {
    rt_sharder rt; /* the runtime's view (first member) */
    int merging;   /* 0: a shard writing its part; 1: merge */
    int index, count;
    char *const *all;   /* merge: the part paths as given */
    int nall;
    char *const *parts; /* merge: those of this attempt's frame (all without --frames) */
    int nparts;
    char **sel;         /* merge --frames: this frame's parts (one attempt) */

    /* kept across attempts */
    uint32_t full[SHARD_MAX_FULL]; /* calls computed fully (tainted) */
    int nfull;
    int again; /* the attempt was abandoned by a taint: run again */

    /* one attempt */
    interp *I;
    unsigned char hash[32]; /* SHA-256 of the script text */
    uint32_t seq;         /* shardable calls begun */
    long pending;         /* call whose partial result awaits its builtin's return; -1 none */
    const node *pending_at;
    long live;            /* partial values alive */
    long cur;             /* the call whose sections are being exchanged; -1 none */
    uint32_t sub;         /* its next section */
    size_t cur_nchunks;
    char cur_kind[16];
    long win_seq;         /* shard: the call the window below was fitted for; -1 none */
    int win_dim;          /* its dimension; 0 after a second fit for the same call (none recorded) */
    double win[6];        /* lo[dim], hi[dim] */
    long win_taken;       /* merge: the call whose window was taken from the parts; -1 none */
    bytebuf part;         /* shard: the part file being built */
    uint32_t nrec;
    FILE *devnull;        /* shard: print() goes nowhere (merge prints) */
    /* merge */
    shard_rec *recs;      /* the records of shard 0, in order (all parts have the same) */
    uint32_t nrecs, next_rec;
    uint32_t ncalls;      /* the engine calls the shards' evaluation made */
    bytebuf files;        /* the files the shards read: path NUL, SHA-256, … */
    bytebuf reads;        /* shard: the paths this evaluation read, NUL-terminated */
    int *order;           /* order[i]: the index in parts of shard i */
    long *off;            /* per shard: file offset of its next record */
} shard;

/* Set up from the command line: spec is "I/N" or "auto" (environment).
 * 0, or -1 after printing a usage error to stderr. */
int shard_init_run(shard *s, const char *spec);
void shard_init_merge(shard *s, char *const *parts, int nparts);
/* --frames: a new frame starts (its engine calls are numbered afresh, no
 * call is known to be full yet). */
void shard_new_frame(shard *s);

/* An attempt: I is the fresh interpreter, text the script. Merge checks
 * every part here (an error is recorded in I and -1 returned). */
int shard_attempt_begin(shard *s, interp *I, const char *script, const unsigned char *text, size_t len);
/* The script ran without error (ok != 0): a shard writes its part.
 * Frees what the attempt allocated. Returns -1 if writing failed (error in I). */
int shard_attempt_end(shard *s, int ok, const char *script);

/* Merge's check of every part (set up by shard_init_merge) against a script
 * whose SHA-256 is given, without a script: for tests/fuzz/fuzz_shard.c.
 * 0, or -1 with the error in I; shard_attempt_end(s, 0, "") frees. */
int shard_check_parts(shard *s, interp *I, const unsigned char script_hash[32]);

/* The evaluator's hooks (eval.c), cheap when s has no partial values. */
int shard_scan_args(interp *I, const char *builtin_name, const node *call, const value *pos, int npos,
                    const value *named, int nnamed);
/* After a builtin returned rc: wraps a pending partial result; a builtin
 * that failed with a partial result pending is a taint. Returns the new rc. */
int shard_after_builtin(interp *I, int rc, value *out);
/* In a shard, the engine call just made is split: its result will be
 * replaced by a partial value, so a binding may skip finishing it (tone
 * mapping a histogram nobody will see). */
int shard_pending(const interp *I);
/* In a shard, the split engine call whose partial result the current
 * builtin will return (-1: none) and in *at where it was made — for a value
 * computed lazily and kept (superifs_image keeps the super IFS's points). */
long shard_pending_call(const interp *I, const node **at);
/* The current builtin's result is drawn from split call seq's partial
 * result (made at `at`), kept from an earlier builtin: it becomes a partial
 * value of that call too (used elsewhere, the call is made full and the
 * script re-run). */
void shard_pend_again(interp *I, long seq, const node *at);
/* Windows fitted for the next engine call (the pre-pass finding an
 * attractor's bounds, lang_chaos_fit_call). In a shard, put notes lo and hi
 * (dim values each); if that call is split, its part gets a window record
 * after the call's sections (two fits before one call: none). In merge,
 * take returns 1 with the shards' window in lo, hi when the parts hold one
 * for the next call (the binding then skips its pre-pass), else 0. */
void shard_window_put(interp *I, int dim, const double *lo, const double *hi);
int shard_window_take(interp *I, int dim, double *lo, double *hi);
/* save(v, …) in a shard: writes nothing (1: handled), 0 otherwise. */
int shard_skip_save(interp *I);

#endif
