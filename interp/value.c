/* value.c — heap values, reference counting, environments, printing. */
#include "value.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "builtin.h"
#include "cstack.h"
#include "fileio.h"
#include "state.h"

static void *heap_new(interp *I, size_t size, int kind)
{
    heap *h = mem_alloc(I, size);
    if (!h)
        return NULL;
    memset(h, 0, size);
    h->rc = 1;
    h->kind = (uint8_t)kind;
    h->prev = NULL;
    h->next = I->heap_all;
    if (I->heap_all)
        I->heap_all->prev = h;
    I->heap_all = h;
    return h;
}

static void heap_unlink(interp *I, heap *h)
{
    if (h->prev)
        h->prev->next = h->next;
    else
        I->heap_all = h->next;
    if (h->next)
        h->next->prev = h->prev;
}

/* Queue a heap object whose last reference is being dropped: it leaves the
 * list of all objects, and its `next` links it into `pending`. */
static void drop_heap(interp *I, heap *h, heap **pending)
{
    if (h && --h->rc == 0) {
        heap_unlink(I, h);
        h->next = *pending;
        *pending = h;
    }
}

static void drop_value(interp *I, value v, heap **pending)
{
    if (v.k >= V_STR && v.k != V_BUILTIN)
        drop_heap(I, v.u.h, pending);
}

/* Drop the references an object holds (into `pending`, not recursively). */
static void drop_children(interp *I, heap *h, heap **pending)
{
    switch (h->kind) {
    case H_LIST: {
        vlist *l = (vlist *)h;
        for (size_t i = 0; i < l->n; i++)
            drop_value(I, l->items[i], pending);
        break;
    }
    case H_REC: {
        vrec *r = (vrec *)h;
        for (size_t i = 0; i < r->n; i++)
            drop_value(I, r->vals[i], pending);
        break;
    }
    case H_FUNC: {
        vfunc *f = (vfunc *)h;
        if (f->closure)
            drop_heap(I, &f->closure->h, pending);
        break;
    }
    case H_ENV: {
        env *e = (env *)h;
        for (size_t i = 0; i < e->n; i++)
            drop_value(I, e->vals[i], pending);
        if (e->parent)
            drop_heap(I, &e->parent->h, pending);
        break;
    }
    default:
        break;
    }
}

/* Free an unlinked object's own storage. */
static void free_storage(interp *I, heap *h)
{
    switch (h->kind) {
    case H_LIST:
        mem_free(I, ((vlist *)h)->items);
        break;
    case H_REC:
        mem_free(I, ((vrec *)h)->keys);
        mem_free(I, ((vrec *)h)->vals);
        break;
    case H_ENV: {
        env *e = (env *)h;
        if (!e->index && e->cap <= ENV_POOL_CAP && I->env_pool_n < ENV_POOL_MAX) {
            /* kept for the next call or block: most scopes are small and
             * short-lived, and a call would otherwise pay three allocations */
            e->h.next = I->env_pool ? &I->env_pool->h : NULL;
            I->env_pool = e;
            I->env_pool_n++;
            return;
        }
        mem_free(I, e->names);
        mem_free(I, e->vals);
        mem_free(I, e->index);
        break;
    }
    case H_OBJ: {
        vobj *o = (vobj *)h;
        if (o->cls->destroy)
            o->cls->destroy(o->payload); /* may drop values itself (re-entrant) */
        break;
    }
    default:
        break;
    }
    mem_free(I, h);
}

/* Free one object without touching what it refers to. */
static void heap_destroy(interp *I, heap *h)
{
    heap_unlink(I, h);
    free_storage(I, h);
}

/* Freeing is iterative: objects whose count reaches zero wait on a local
 * list instead of being freed recursively, so dropping a list nested 10^6
 * deep uses no stack. */
void val_heap_unref(interp *I, heap *h)
{
    heap *pending = NULL;
    drop_heap(I, h, &pending);
    while (pending) {
        heap *x = pending;
        pending = x->next;
        drop_children(I, x, &pending);
        free_storage(I, x);
    }
}


void val_heap_free_all(interp *I)
{
    while (I->heap_all)
        heap_destroy(I, I->heap_all);
    while (I->env_pool) {
        env *e = I->env_pool;
        I->env_pool = (env *)e->h.next;
        mem_free(I, e->names);
        mem_free(I, e->vals);
        mem_free(I, e);
    }
    I->env_pool_n = 0;
}

value val_str(interp *I, const char *s, size_t len)
{
    vstr *str = heap_new(I, sizeof(vstr) + len + 1, H_STR);
    if (!str)
        return val_nil();
    memcpy(str->s, s, len);
    str->s[len] = 0;
    str->len = len;
    value v;
    v.k = V_STR;
    v.u.h = &str->h;
    return v;
}

value val_cstr(interp *I, const char *s) { return val_str(I, s, strlen(s)); }

value val_list(interp *I, size_t cap)
{
    if ((double)cap > I->lim.max_list) { /* the length a caller is about to fill */
        err_at(I, NULL, ERR_LIMIT, "list longer than %.0f items (raise it with --max-list)", I->lim.max_list);
        return val_nil();
    }
    vlist *l = heap_new(I, sizeof(vlist), H_LIST);
    if (!l)
        return val_nil();
    if (cap) {
        l->items = mem_alloc(I, cap * sizeof(value));
        if (!l->items) {
            heap_destroy(I, &l->h);
            return val_nil();
        }
        l->cap = cap;
    }
    value v;
    v.k = V_LIST;
    v.u.h = &l->h;
    return v;
}

int val_list_push(interp *I, vlist *l, value v)
{
    /* every push, not only when the list grows its storage: the limit is
     * exact whatever capacity val_list reserved */
    if ((double)l->n + 1 > I->lim.max_list) {
        val_unref(I, v);
        return err_at(I, NULL, ERR_LIMIT, "list longer than %.0f items (raise it with --max-list)",
                      I->lim.max_list);
    }
    if (l->n == l->cap) {
        size_t nc = l->cap ? l->cap * 2 : 8;
        value *ni = mem_realloc(I, l->items, nc * sizeof(value));
        if (!ni) {
            val_unref(I, v);
            return -1;
        }
        I->count.list_grows++;
        l->items = ni;
        l->cap = nc;
    }
    l->items[l->n++] = v;
    return 0;
}

int val_list_build(interp *I, size_t n, val_item_fn item, const void *ctx, value *out)
{
    value l = val_list(I, n);
    if (l.k == V_NIL)
        return -1;
    for (size_t i = 0; i < n; i++) {
        value v;
        if (item(I, ctx, i, &v) || val_list_push(I, AS_LIST(l), v)) {
            val_unref(I, l);
            return -1;
        }
    }
    *out = l;
    return 0;
}

value val_rec(interp *I)
{
    vrec *r = heap_new(I, sizeof(vrec), H_REC);
    value v;
    if (!r)
        return val_nil();
    v.k = V_REC;
    v.u.h = &r->h;
    return v;
}

value *val_rec_get(const vrec *r, const char *key)
{
    for (size_t i = 0; i < r->n; i++)
        if (r->keys[i] == key)
            return &r->vals[i];
    return NULL;
}

int val_rec_set(interp *I, vrec *r, const char *key, value v)
{
    value *old = val_rec_get(r, key);
    if (old) {
        val_unref(I, *old);
        *old = v;
        return 0;
    }
    if (r->n == r->cap) {
        size_t nc = r->cap ? r->cap * 2 : 4;
        const char **nk = mem_realloc(I, r->keys, nc * sizeof *nk);
        if (!nk) {
            val_unref(I, v);
            return -1;
        }
        r->keys = nk;
        value *nv = mem_realloc(I, r->vals, nc * sizeof *nv);
        if (!nv) {
            val_unref(I, v);
            return -1;
        }
        r->vals = nv;
        r->cap = nc;
    }
    r->keys[r->n] = key;
    r->vals[r->n] = v;
    r->n++;
    return 0;
}

value val_func(interp *I, const node *lambda, env *closure, const char *name)
{
    vfunc *f = heap_new(I, sizeof(vfunc), H_FUNC);
    if (!f)
        return val_nil();
    f->lambda = lambda;
    f->closure = closure;
    if (closure)
        closure->h.rc++;
    f->name = name;
    value v;
    v.k = V_FUNC;
    v.u.h = &f->h;
    return v;
}

value val_obj(interp *I, const obj_class *cls, void *payload)
{
    vobj *o = heap_new(I, sizeof(vobj), H_OBJ);
    if (!o) {
        if (cls->destroy)
            cls->destroy(payload);
        return val_nil();
    }
    o->cls = cls;
    o->payload = payload;
    value v;
    v.k = V_OBJ;
    v.u.h = &o->h;
    return v;
}

env *val_env_new(interp *I, env *parent)
{
    env *e = I->env_pool;
    if (e) {
        /* a pooled scope keeps its arrays (capacity e->cap) */
        I->env_pool = (env *)e->h.next;
        I->env_pool_n--;
        e->h.rc = 1;
        e->h.prev = NULL;
        e->h.next = I->heap_all;
        if (I->heap_all)
            I->heap_all->prev = &e->h;
        I->heap_all = &e->h;
        e->n = 0;
        e->loose = 0;
    } else {
        e = heap_new(I, sizeof(env), H_ENV);
        I->count.scope_allocs++;
    }
    if (!e)
        return NULL;
    I->count.scopes++;
    e->parent = parent;
    if (parent)
        parent->h.rc++;
    return e;
}

static long env_find(const env *e, const char *name)
{
    if (e->index) {
        size_t m = e->index_cap - 1;
        for (size_t h = name_hash(name) & m; e->index[h]; h = (h + 1) & m)
            if (e->names[e->index[h] - 1] == name)
                return (long)e->index[h] - 1;
        return -1;
    }
    for (size_t i = e->n; i-- > 0;)
        if (e->names[i] == name)
            return (long)i;
    return -1;
}

static int env_reindex(interp *I, env *e)
{
    size_t cap = 64;
    while (cap < e->n * 2 + 2)
        cap *= 2;
    uint32_t *ix = mem_alloc(I, cap * sizeof *ix);
    if (!ix)
        return -1;
    memset(ix, 0, cap * sizeof *ix);
    for (size_t i = 0; i < e->n; i++) {
        size_t h = name_hash(e->names[i]) & (cap - 1);
        while (ix[h])
            h = (h + 1) & (cap - 1);
        ix[h] = (uint32_t)i + 1;
    }
    mem_free(I, e->index);
    e->index = ix;
    e->index_cap = cap;
    return 0;
}

int val_env_define(interp *I, env *e, const char *name, value v)
{
    if (e->n > 0)
        I->count.name_searches++;
    long at = env_find(e, name);
    if (at >= 0) {
        val_unref(I, e->vals[at]);
        e->vals[at] = v;
        return 0;
    }
    e->loose = 1; /* its place is not necessarily the slot resolve.c gave it */
    return val_env_append(I, e, name, v);
}

int val_env_append(interp *I, env *e, const char *name, value v)
{
    if (e->n == e->cap && e->borrowed) {
        size_t nc = e->cap * 2;
        const char **nn = mem_alloc(I, nc * sizeof *nn);
        value *nv = nn ? mem_alloc(I, nc * sizeof *nv) : NULL;
        if (!nv) {
            mem_free(I, nn);
            val_unref(I, v);
            return -1;
        }
        memcpy(nn, e->names, e->n * sizeof *nn);
        memcpy(nv, e->vals, e->n * sizeof *nv);
        e->names = nn;
        e->vals = nv;
        e->cap = nc;
        e->borrowed = 0;
    }
    if (e->n == e->cap) {
        size_t nc = e->cap ? e->cap * 2 : 8;
        const char **nn = mem_realloc(I, e->names, nc * sizeof *nn);
        if (!nn) {
            val_unref(I, v);
            return -1;
        }
        e->names = nn;
        value *nv = mem_realloc(I, e->vals, nc * sizeof *nv);
        if (!nv) {
            val_unref(I, v);
            return -1;
        }
        e->vals = nv;
        e->cap = nc;
    }
    e->names[e->n] = name;
    e->vals[e->n] = v;
    e->n++;
    if (e->n > 16 && (e->n * 2 > e->index_cap)) {
        if (env_reindex(I, e))
            return -1;
    } else if (e->index) {
        size_t m = e->index_cap - 1, h = name_hash(name) & m;
        while (e->index[h])
            h = (h + 1) & m;
        e->index[h] = (uint32_t)e->n;
    }
    return 0;
}

value *val_env_lookup(env *e, const char *name)
{
    for (; e; e = e->parent) {
        long at = env_find(e, name);
        if (at >= 0)
            return &e->vals[at];
    }
    return NULL;
}

const char *val_type_name(value v)
{
    switch (v.k) {
    case V_NIL: return "nil";
    case V_BOOL: return "boolean";
    case V_NUM: return "number";
    case V_STR: return "string";
    case V_LIST: return "list";
    case V_REC: return "record";
    case V_FUNC:
    case V_BUILTIN: return "function";
    case V_OBJ: return AS_OBJ(v)->cls->name;
    }
    return "value";
}

int val_truthy(value v)
{
    switch (v.k) {
    case V_NIL: return 0;
    case V_BOOL: return v.u.b;
    default: return 1;
    }
}

int val_equal(interp *I, value a, value b)
{
    if (a.k != b.k)
        return 0;
    switch (a.k) {
    case V_NIL: return 1;
    case V_BOOL: return a.u.b == b.u.b;
    case V_NUM: return a.u.n == b.u.n;
    case V_STR: return AS_STR(a)->len == AS_STR(b)->len && memcmp(AS_STR(a)->s, AS_STR(b)->s, AS_STR(a)->len) == 0;
    case V_LIST:
    case V_REC:
        if (a.u.h == b.u.h)
            return 1;
        /* lists nest as deep as the data: the C stack bounds the recursion */
        if (cstack_exhausted()) {
            cstack_error(I, NULL, "values nested too deeply to compare");
            return -1;
        }
        break;
    case V_BUILTIN: return a.u.bi == b.u.bi;
    default: return a.u.h == b.u.h;
    }
    if (a.k == V_LIST) {
        vlist *x = AS_LIST(a), *y = AS_LIST(b);
        if (x->n != y->n)
            return 0;
        for (size_t i = 0; i < x->n; i++) {
            int r = val_equal(I, x->items[i], y->items[i]);
            if (r != 1)
                return r;
        }
        return 1;
    }
    vrec *x = AS_REC(a), *y = AS_REC(b);
    if (x->n != y->n)
        return 0;
    for (size_t i = 0; i < x->n; i++) {
        value *o = val_rec_get(y, x->keys[i]);
        int r = o ? val_equal(I, x->vals[i], *o) : 0;
        if (r != 1)
            return r;
    }
    return 1;
}

/* Numbers print in the shortest form that reads back to the same double
 * (%.17g would show 0.1 as 0.10000000000000001). */
void val_fmt_number(double n, char *buf, size_t size)
{
    if (isnan(n)) {
        snprintf(buf, size, "nan");
        return;
    }
    if (isinf(n)) {
        snprintf(buf, size, n > 0 ? "inf" : "-inf");
        return;
    }
    if (n == floor(n) && fabs(n) < 1e15) {
        snprintf(buf, size, "%.0f", n == 0 ? 0.0 : n);
        return;
    }
    for (int prec = 1; prec <= 17; prec++) {
        snprintf(buf, size, "%.*g", prec, n);
        if (strtod(buf, NULL) == n)
            return;
    }
}

static void print_string_repr(bytebuf *out, const vstr *s)
{
    bytebuf_byte(out, '"');
    for (size_t i = 0; i < s->len; i++) {
        char c = s->s[i];
        switch (c) {
        case '"': bytebuf_append(out, "\\\"", 2); break;
        case '\\': bytebuf_append(out, "\\\\", 2); break;
        case '\n': bytebuf_append(out, "\\n", 2); break;
        case '\t': bytebuf_append(out, "\\t", 2); break;
        default: bytebuf_byte(out, (unsigned char)c);
        }
    }
    bytebuf_byte(out, '"');
}

/* A value that is not a list or record. */
static void print_atom(value v, bytebuf *out, int repr)
{
    char buf[64];
    switch (v.k) {
    case V_NIL: bytebuf_printf(out, "nil"); break;
    case V_BOOL: bytebuf_printf(out, v.u.b ? "true" : "false"); break;
    case V_NUM:
        val_fmt_number(v.u.n, buf, sizeof buf);
        bytebuf_printf(out, "%s", buf);
        break;
    case V_STR:
        if (repr)
            print_string_repr(out, AS_STR(v));
        else
            bytebuf_append(out, AS_STR(v)->s, AS_STR(v)->len);
        break;
    case V_FUNC: {
        vfunc *f = AS_FUNC(v);
        bytebuf_printf(out, "<fn %s>", f->name ? f->name : "lambda");
        break;
    }
    case V_BUILTIN: bytebuf_printf(out, "<builtin %s>", v.u.bi->name); break;
    case V_OBJ: {
        vobj *o = AS_OBJ(v);
        if (o->cls->summary)
            o->cls->summary(o->payload, out);
        else
            bytebuf_printf(out, "<%s>", o->cls->name);
        break;
    }
    case V_LIST:
    case V_REC:
        break;
    }
}

/* Lists and records print with an explicit stack of open containers (not
 * recursion), so a list nested 10^5 deep prints. The stack is plain memory,
 * like the output buffer; if it cannot grow the rest shows as `…`. */
typedef struct print_frame {
    value v;
    size_t i; /* next item */
} print_frame;

void val_print(interp *I, value v, bytebuf *out, int repr)
{
    (void)I;
    if (v.k != V_LIST && v.k != V_REC) {
        print_atom(v, out, repr);
        return;
    }
    print_frame local[64], *st = local;
    size_t n = 0, cap = sizeof local / sizeof local[0];
    st[n++] = (print_frame){v, 0};
    bytebuf_byte(out, v.k == V_LIST ? '[' : '{');
    while (n) {
        print_frame *f = &st[n - 1];
        value child;
        if (f->v.k == V_LIST) {
            vlist *l = AS_LIST(f->v);
            size_t shown = l->n > 1000 ? 1000 : l->n;
            if (f->i == shown) {
                if (shown < l->n)
                    bytebuf_printf(out, ", … (%zu items)", l->n);
                bytebuf_byte(out, ']');
                n--;
                continue;
            }
            if (f->i)
                bytebuf_append(out, ", ", 2);
            child = l->items[f->i++];
        } else {
            vrec *r = AS_REC(f->v);
            if (f->i == r->n) {
                bytebuf_byte(out, '}');
                n--;
                continue;
            }
            bytebuf_printf(out, "%s%s: ", f->i ? ", " : "", r->keys[f->i]);
            child = r->vals[f->i++];
        }
        if (child.k != V_LIST && child.k != V_REC) {
            print_atom(child, out, 1);
            continue;
        }
        if (n == cap) {
            size_t nc = cap * 2;
            print_frame *ns = st == local ? rt_mallocn(nc, sizeof *ns) : rt_reallocn(st, nc, sizeof *ns);
            if (!ns) { /* the hook refused: the caller reports out of memory */
                out->failed = 1;
                break;
            }
            if (st == local)
                memcpy(ns, local, sizeof local);
            st = ns;
            cap = nc;
        }
        st[n++] = (print_frame){child, 0};
        bytebuf_byte(out, child.k == V_LIST ? '[' : '{');
    }
    if (st != local)
        rt_free(st);
}
