/* state.c — interpreter state: allocation hook, names, sources, errors and
 * the one diagnostic printer. */
#include "state.h"

#include <stdarg.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "fileio.h"

const char *err_kind_name(err_kind k)
{
    static const char *names[] = {
#define X(id, name, code) name,
        ERROR_KINDS(X)
#undef X
    };
    return names[k];
}

int err_kind_exit(err_kind k)
{
    static const int codes[] = {
#define X(id, name, code) code,
        ERROR_KINDS(X)
#undef X
    };
    return codes[k];
}

/* ---- allocation ---------------------------------------------------------- */

/* Why the hook last refused an allocation. */
enum mem_fail_kind { MEM_FAIL_NONE, MEM_FAIL_LIMIT, MEM_FAIL_INJECTED, MEM_FAIL_SYSTEM };

static void *fail(interp *I, int kind, size_t n, long count)
{
    atomic_store(&I->mem_fail_size, n);
    atomic_store(&I->mem_fail_n, count);
    atomic_store(&I->mem_fail, kind);
    return NULL;
}

/* The one allocation hook (rt_alloc_hook.alloc). Runs on any thread: the
 * budget is taken with a compare-and-swap before the block is allocated, so
 * concurrent engine workers can never overshoot lim.max_memory together. */
static void *mem_get(void *ud, void *p, size_t osize, size_t nsize, int zero)
{
    interp *I = ud;
    if (nsize == 0) {
        free(p);
        atomic_fetch_sub(&I->mem_used, osize);
        return NULL;
    }
    size_t grow = nsize > osize ? nsize - osize : 0;
    if (grow) {
        long count = atomic_fetch_add(&I->alloc_count, 1) + 1;
        if (I->fail_alloc_at && count == I->fail_alloc_at)
            return fail(I, MEM_FAIL_INJECTED, nsize, count);
        size_t max = I->lim.max_memory;
        size_t used = atomic_load(&I->mem_used);
        do {
            if (grow > max || used > max - grow)
                return fail(I, MEM_FAIL_LIMIT, nsize, count);
        } while (!atomic_compare_exchange_weak(&I->mem_used, &used, used + grow));
    }
    void *q = zero ? calloc(1, nsize) : realloc(p, nsize);
    if (!q) {
        atomic_fetch_sub(&I->mem_used, grow);
        return fail(I, MEM_FAIL_SYSTEM, nsize, 0);
    }
    if (nsize < osize)
        atomic_fetch_sub(&I->mem_used, osize - nsize);
    return q;
}

static void *mem_hook(void *ud, void *p, size_t osize, size_t nsize)
{
    return mem_get(ud, p, osize, nsize, 0);
}

/* rt_alloc_hook.zalloc: a new zeroed block, counted like mem_hook's. */
static void *mem_zhook(void *ud, size_t nsize)
{
    return mem_get(ud, NULL, 0, nsize, 1);
}

static double mem_limit(void *ud, rt_limit k, const char **flag)
{
    interp *I = ud;
    switch (k) {
    case RT_LIMIT_MEMORY: {
        size_t used = atomic_load(&I->mem_used);
        *flag = "--max-memory MiB";
        return used > I->lim.max_memory ? 0 : (double)(I->lim.max_memory - used);
    }
    case RT_LIMIT_PIXELS:
        *flag = "--max-pixels";
        return I->lim.max_pixels;
    case RT_LIMIT_VOXELS:
        *flag = "--max-voxels";
        return I->lim.max_voxels;
    }
    return -1;
}

/* Record the error for the hook's last refusal (prefixed "WHAT: " if what)
 * and forget the refusal. */
static int refused(interp *I, const char *what, size_t n, const char *fallback)
{
    int kind = atomic_exchange(&I->mem_fail, MEM_FAIL_NONE);
    const char *sep = what ? ": " : "";
    what = what ? what : "";
    switch (kind) {
    case MEM_FAIL_LIMIT:
        return err_at(I, NULL, ERR_LIMIT, "%s%smemory limit of %.0f MiB exceeded (raise it with --max-memory MiB)",
                      what, sep, (double)I->lim.max_memory / 1048576.0);
    case MEM_FAIL_INJECTED:
        return err_at(I, NULL, ERR_MEMORY, "%s%sout of memory (allocation %ld failed, as --fail-alloc asked)",
                      what, sep, atomic_load(&I->mem_fail_n));
    case MEM_FAIL_SYSTEM:
        return err_at(I, NULL, ERR_MEMORY, "%s%sout of memory (allocating %zu bytes)", what, sep,
                      atomic_load(&I->mem_fail_size));
    default: /* not refused by the hook: a size that overflowed, or the engine's own reason */
        if (fallback)
            return err_at(I, NULL, ERR_MEMORY, "%s%s%s", what, sep, fallback);
        if (n)
            return err_at(I, NULL, ERR_MEMORY, "%s%sout of memory (allocating %zu bytes)", what, sep, n);
        return err_at(I, NULL, ERR_MEMORY, "%s%sout of memory (a buffer size overflows)", what, sep);
    }
}

void *mem_alloc(interp *I, size_t n)
{
    void *p = rt_malloc(n);
    if (!p)
        refused(I, NULL, n, NULL);
    return p;
}

void *mem_calloc(interp *I, size_t count, size_t size)
{
    void *p = rt_calloc(count, size);
    if (!p)
        refused(I, NULL, 0, NULL);
    return p;
}

void *mem_realloc(interp *I, void *p, size_t n)
{
    void *q = rt_realloc(p, n);
    if (!q)
        refused(I, NULL, n, NULL);
    return q;
}

void mem_free(interp *I, void *p)
{
    (void)I;
    rt_free(p);
}

int mem_precheck(interp *I, double bytes, const char *what)
{
    double used = (double)atomic_load(&I->mem_used), max = (double)I->lim.max_memory;
    if (!(bytes >= 0 && bytes <= max && used + bytes <= max))
        return err_at(I, NULL, ERR_LIMIT,
                      "%s needs %.0f MiB, over the memory limit of %.0f MiB (%.0f MiB in use; raise "
                      "it with --max-memory MiB)",
                      what, bytes / 1048576.0, max / 1048576.0, used / 1048576.0);
    return 0;
}

int mem_engine_error(interp *I, const char *what, const char *msg)
{
    return refused(I, what, 0, msg);
}

/* ---- arena for syntax trees --------------------------------------------- */

/* Blocks grow 4× from 64 KiB up to 8 MiB (64 KiB, 256 KiB, 1 MiB, 4 MiB,
 * 8 MiB, 8 MiB …), so a small script's tree wastes little and a large one's
 * soon takes big blocks; at most the newest block is partly unused, and
 * only what is used is touched. A block of 2 MiB or more starts its data on a
 * 2 MiB boundary inside a piece 2 MiB larger (as hist_zeroed does), so the
 * runtime's huge-page hint covers all of it: first touch costs one page
 * fault per 2 MiB, not per 4 KiB (on these machines a fault costs more than
 * writing its page). The slack is never touched but counts in the budget. */
#define ARENA_MIN ((size_t)64 << 10)
#define ARENA_MAX ((size_t)8 << 20)
#define ARENA_HUGE ((size_t)2 << 20)
void *mem_arena_grow(interp *I, size_t n)
{
    size_t cap = I->arena ? I->arena->cap * 4 : ARENA_MIN;
    cap = cap < ARENA_MIN ? ARENA_MIN : cap > ARENA_MAX ? ARENA_MAX : cap;
    if (n > cap)
        cap = n;
    size_t slack = cap >= ARENA_HUGE ? ARENA_HUGE : 0;
    char *mem = mem_alloc(I, sizeof(arena_block) + cap + slack);
    if (!mem)
        return NULL;
    arena_block *b = (arena_block *)mem;
    if (slack) {
        uintptr_t data = (uintptr_t)(mem + offsetof(arena_block, data));
        b = (arena_block *)(mem + (ARENA_HUGE - data % ARENA_HUGE) % ARENA_HUGE);
    }
    b->mem = mem;
    b->cap = cap;
    b->used = n;
    b->next = I->arena;
    I->arena = b;
    return b->data;
}

void *mem_arena_alloc(interp *I, size_t n)
{
    void *p = mem_arena_raw(I, n);
    if (p)
        memset(p, 0, n);
    return p;
}

/* ---- interned names ------------------------------------------------------- */

static uint64_t hash_bytes(const char *s, size_t n)
{
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; i++)
        h = (h ^ (unsigned char)s[i]) * 1099511628211ull;
    return h;
}

/* strncmp(e, s, len) == 0 && e[len] == 0, without the call (names are short) */
/* An interned name is stored after its length (4 bytes), so a name with a
 * NUL inside it (a record key made from a string) is compared and rehashed
 * whole, and no comparison reads past a shorter stored name. */
static size_t name_len(const char *e)
{
    uint32_t n;
    memcpy(&n, e - sizeof n, sizeof n);
    return n;
}

static int same_name(const char *e, const char *s, size_t len)
{
    return name_len(e) == len && memcmp(e, s, len) == 0;
}

const char *interp_intern(interp *I, const char *s, size_t len)
{
    if (I->intern_n * 2 >= I->intern_cap) {
        size_t nc = I->intern_cap ? I->intern_cap * 2 : 1024;
        char **nt = mem_alloc(I, nc * sizeof *nt);
        if (!nt)
            return NULL;
        memset(nt, 0, nc * sizeof *nt);
        for (size_t i = 0; i < I->intern_cap; i++) {
            char *e = I->intern_tab[i];
            if (!e)
                continue;
            size_t j = hash_bytes(e, name_len(e)) & (nc - 1);
            while (nt[j])
                j = (j + 1) & (nc - 1);
            nt[j] = e;
        }
        mem_free(I, I->intern_tab);
        I->intern_tab = nt;
        I->intern_cap = nc;
    }
    size_t j = hash_bytes(s, len) & (I->intern_cap - 1);
    while (I->intern_tab[j]) {
        char *e = I->intern_tab[j];
        if (same_name(e, s, len))
            return e;
        j = (j + 1) & (I->intern_cap - 1);
    }
    if (len > UINT32_MAX)
        return NULL;
    char *e = mem_arena_raw(I, sizeof(uint32_t) + len + 1); /* names live as long as the session, like the trees */
    if (!e)
        return NULL;
    uint32_t n32 = (uint32_t)len;
    memcpy(e, &n32, sizeof n32);
    e += sizeof n32;
    memcpy(e, s, len);
    e[len] = 0;
    I->intern_tab[j] = e;
    I->intern_n++;
    return e;
}

/* ---- sources -------------------------------------------------------------- */

static char *dup_str(interp *I, const char *s, size_t n)
{
    char *d = mem_alloc(I, n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = 0;
    }
    return d;
}

int interp_add_source(interp *I, const char *name, const char *text, size_t len)
{
    if (I->nsrc >= 65535) /* tokens store the source index in 16 bits */
        return err_pos(I, -1, 0, 0, ERR_LIMIT, "too many sources in one session (65535); start a new one");
    if (I->nsrc == I->cap_src) {
        int nc = I->cap_src ? I->cap_src * 2 : 8;
        source *ns = mem_realloc(I, I->srcs, (size_t)nc * sizeof *ns);
        if (!ns)
            return -1;
        I->srcs = ns;
        I->cap_src = nc;
    }
    source *s = &I->srcs[I->nsrc];
    s->name = dup_str(I, name, strlen(name));
    s->text = dup_str(I, text, len);
    const char *slash = strrchr(name, '/');
    s->first_line = 1;
    s->is_module = 0;
    s->dir = slash ? dup_str(I, name, (size_t)(slash - name)) : dup_str(I, ".", 1);
    if (!s->name || !s->text || !s->dir) {
        mem_free(I, s->name);
        mem_free(I, s->text);
        mem_free(I, s->dir);
        return -1;
    }
    return I->nsrc++;
}

/* ---- life cycle ----------------------------------------------------------- */

void interp_init(interp *I)
{
    memset(I, 0, sizeof *I);
    atomic_init(&I->mem_used, 0);
    atomic_init(&I->alloc_count, 0);
    atomic_init(&I->mem_fail, MEM_FAIL_NONE);
    atomic_init(&I->mem_fail_size, 0);
    atomic_init(&I->mem_fail_n, 0);
    I->hook.alloc = mem_hook;
    I->hook.limit = mem_limit;
    I->hook.zalloc = mem_zhook;
    I->hook.ud = I;
    rt_alloc_set_hook(&I->hook);
    I->lim.max_memory = (size_t)4096 << 20;
    I->lim.max_depth = 1000;
    I->lim.max_pixels = 64e6;
    I->lim.max_points = 1e10;
    I->lim.max_voxels = 512.0 * 512 * 512;
    I->lim.max_list = 1e8;
    I->seed = 1;
    I->threads = 1;
    I->out = stdout;
    I->err.src = -1;
}

void interp_free(interp *I)
{
    val_heap_free_all(I);
    for (int i = 0; i < I->nmods; i++)
        mem_free(I, I->mods[i].key);
    mem_free(I, I->mods);
    for (int i = 0; i < I->nsrc; i++) {
        mem_free(I, I->srcs[i].name);
        mem_free(I, I->srcs[i].text);
        mem_free(I, I->srcs[i].dir);
    }
    mem_free(I, I->srcs);
    mem_free(I, I->intern_tab); /* the names are in the arena */
    while (I->arena) {
        arena_block *b = I->arena;
        I->arena = b->next;
        mem_free(I, b->mem);
    }
    mem_free(I, I->stack);
    mem_free(I, I->params);
    mem_free(I, I->overrides);
    mem_free(I, I->builtins);
    rt_alloc_set_hook(NULL); /* blocks freed later go to free() uncounted */
}

/* ---- errors --------------------------------------------------------------- */

static int verr(interp *I, int src, int line, int col, err_kind k, const char *fmt, va_list ap)
{
    if (I->err.active)
        return -1; /* first error wins */
    err_state *e = &I->err;
    e->active = 1;
    e->kind = k;
    e->src = src;
    e->line = line;
    e->col = col;
    e->note[0] = 0;
    e->note_src = -1;
    e->incomplete = 0;
    vsnprintf(e->msg, sizeof e->msg, fmt, ap);
    /* call trace, innermost first */
    e->ntrace = 0;
    e->trace_dropped = 0;
    for (int i = I->depth - 1; i >= 0; i--) {
        if (e->ntrace == MAX_TRACE) {
            e->trace_dropped = i + 1;
            break;
        }
        const node *c = I->stack[i].call;
        e->trace[e->ntrace].fname = I->stack[i].fname;
        e->trace[e->ntrace].src = c ? c->src : -1;
        e->trace[e->ntrace].line = c ? c->line : 0;
        e->trace[e->ntrace].col = c ? c->col : 0;
        e->ntrace++;
    }
    return -1;
}

int err_at(interp *I, const node *at, err_kind k, const char *fmt, ...)
{
    if (!at)
        at = I->cur;
    va_list ap;
    va_start(ap, fmt);
    int r = verr(I, at ? at->src : -1, at ? at->line : 0, at ? at->col : 0, k, fmt, ap);
    va_end(ap);
    return r;
}

int err_pos(interp *I, int src, int line, int col, err_kind k, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int r = verr(I, src, line, col, k, fmt, ap);
    va_end(ap);
    return r;
}

void err_clear(interp *I)
{
    memset(&I->err, 0, sizeof I->err);
    I->err.src = -1;
}

static void print_line_caret(interp *I, FILE *f, int src, int line, int col)
{
    if (src < 0 || src >= I->nsrc || line < 1)
        return;
    const char *p = I->srcs[src].text;
    for (int l = I->srcs[src].first_line; l < line && *p; p++)
        if (*p == '\n')
            l++;
    const char *q = p;
    while (*q && *q != '\n')
        q++;
    int len = (int)(q - p);
    if (len > 0 && p[len - 1] == '\r')
        len--;
    /* A long line shows a window of about 120 bytes around the column,
     * marked with … at the cut ends, so a 60 KB line stays one screen. */
    int from = 0, to = len;
    if (len > 160) {
        from = col - 1 > 60 ? col - 1 - 60 : 0;
        to = from + 120 < len ? from + 120 : len;
        while (from > 0 && ((unsigned char)p[from] & 0xC0) == 0x80)
            from--;
        while (to < len && ((unsigned char)p[to] & 0xC0) == 0x80)
            to++;
    }
    fprintf(f, "%5d | %s%.*s%s\n      | %s", line, from ? "…" : "", to - from, p + from, to < len ? "…" : "",
            from ? " " : "");
    /* Tabs stay tabs so the caret lines up; other bytes become spaces (one
     * per UTF-8 character). */
    for (int i = from; i < col - 1 && i < to; i++) {
        unsigned char c = (unsigned char)p[i];
        if ((c & 0xC0) == 0x80)
            continue;
        fputc(c == '\t' ? '\t' : ' ', f);
    }
    fputs("^\n", f);
}

void diag_print(interp *I, FILE *f, const err_state *e)
{
    if (e->src >= 0 && e->src < I->nsrc)
        fprintf(f, "%s:%d:%d: error: %s\n", I->srcs[e->src].name, e->line, e->col, e->msg);
    else
        fprintf(f, "frac: error: %s\n", e->msg);
    print_line_caret(I, f, e->src, e->line, e->col);
    if (e->note[0]) {
        if (e->note_src >= 0 && e->note_src < I->nsrc) {
            fprintf(f, "%s:%d:%d: note: %s\n", I->srcs[e->note_src].name, e->note_line,
                    e->note_col, e->note);
            print_line_caret(I, f, e->note_src, e->note_line, e->note_col);
        } else {
            fprintf(f, "note: %s\n", e->note);
        }
    }
    for (int i = 0; i < e->ntrace; i++) {
        const char *fn = e->trace[i].fname ? e->trace[i].fname : "<lambda>";
        if (e->trace[i].src >= 0 && e->trace[i].src < I->nsrc)
            fprintf(f, "  in %s, called from %s:%d:%d\n", fn, I->srcs[e->trace[i].src].name,
                    e->trace[i].line, e->trace[i].col);
        else
            fprintf(f, "  in %s\n", fn);
    }
    if (e->trace_dropped)
        fprintf(f, "  … %d more calls\n", e->trace_dropped);
}

/* ---- suggestions ---------------------------------------------------------- */

static size_t edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > 64 || lb > 64)
        return 99;
    size_t row[65];
    for (size_t j = 0; j <= lb; j++)
        row[j] = j;
    for (size_t i = 1; i <= la; i++) {
        size_t prev = row[0];
        row[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t cur = row[j];
            size_t sub = prev + (a[i - 1] != b[j - 1]);
            size_t del = row[j] + 1, ins = row[j - 1] + 1;
            row[j] = sub < del ? (sub < ins ? sub : ins) : (del < ins ? del : ins);
            prev = cur;
        }
    }
    return row[lb];
}

const char *interp_suggest_name(const char *name, const char *const *cands, size_t n)
{
    const char *best = NULL;
    size_t bestd = 99;
    size_t len = strlen(name);
    size_t maxd = len <= 3 ? 1 : len <= 6 ? 2 : 3;
    for (size_t i = 0; i < n; i++) /* a candidate differing only in case wins */
        if (cands[i] && strcmp(cands[i], name) != 0 && strcasecmp(cands[i], name) == 0)
            return cands[i];
    for (size_t i = 0; i < n; i++) {
        if (!cands[i] || strcmp(cands[i], name) == 0)
            continue;
        size_t d = edit_distance(name, cands[i]);
        if (d < bestd || (d == bestd && best && strcmp(cands[i], best) < 0)) {
            bestd = d;
            best = cands[i];
        }
    }
    return bestd <= maxd ? best : NULL;
}
