/* builtins_core.c — math, lists, strings, printing, randomness. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "builtin.h"
#include "cstack.h"
#include "eval.h"
#include "fileio.h"
#include "lexer.h"
#include "rng.h"

/* ---- math -------------------------------------------------------------------- */

/* A math function applies element-wise to lists, and to engine objects that
 * handle it through their class's arith hook (fields build graph nodes). */
typedef double (*math1)(double);

static int apply1(interp *I, value a, math1 f, int opcode, value *out)
{
    if (a.k == V_NUM) {
        *out = val_num(f(a.u.n));
        return 0;
    }
    if (a.k == V_LIST) {
        if (cstack_exhausted()) /* nested lists recurse */
            return cstack_error(I, NULL, "lists nested too deeply");
        value res = val_list(I, AS_LIST(a)->n);
        if (res.k == V_NIL)
            return -1;
        for (size_t i = 0; i < AS_LIST(a)->n; i++) {
            value r;
            if (apply1(I, AS_LIST(a)->items[i], f, opcode, &r) || val_list_push(I, AS_LIST(res), r)) {
                val_unref(I, res);
                return -1;
            }
        }
        *out = res;
        return 0;
    }
    if (a.k == V_OBJ && AS_OBJ(a)->cls->arith) {
        int r = AS_OBJ(a)->cls->arith(I, opcode, a, val_nil(), out);
        if (r != 0)
            return r < 0 ? -1 : 0;
    }
    return err_at(I, NULL, ERR_TYPE, "expected a number, a list of numbers or a field, got %s",
                  val_type_name(a));
}

static double d_abs(double x) { return fabs(x); }
static double d_round(double x) { return floor(x + 0.5); }
static double d_sign(double x) { return x > 0 ? 1 : x < 0 ? -1 : 0; }


#define MATH1(cname, fname, f, code)                                               \
    static int cname(interp *I, value *a, int n, value *out)                      \
    {                                                                              \
        (void)n;                                                                   \
        return apply1(I, a[0], f, code, out);                                     \
    }
MATH1(b_sqrt, "sqrt", sqrt, OP_SQRT)
MATH1(b_exp, "exp", exp, OP_EXP)
MATH1(b_log, "log", log, OP_LOG)
MATH1(b_sin, "sin", sin, OP_SIN)
MATH1(b_cos, "cos", cos, OP_COS)
MATH1(b_tan, "tan", tan, OP_TAN)
MATH1(b_asin, "asin", asin, OP_ASIN)
MATH1(b_acos, "acos", acos, OP_ACOS)
MATH1(b_atan, "atan", atan, OP_ATAN)
MATH1(b_abs, "abs", d_abs, OP_ABS)
MATH1(b_floor, "floor", floor, OP_FLOOR)
MATH1(b_ceil, "ceil", ceil, OP_CEIL)
MATH1(b_round, "round", d_round, OP_ROUND)
MATH1(b_sign, "sign", d_sign, OP_SIGN)

static int b_pow(interp *I, value *a, int n, value *out)
{
    (void)n;
    return eval_binary(I, T_CARET, a[0], a[1], out, NULL);
}

static int b_atan2(interp *I, value *a, int n, value *out)
{
    (void)n;
    if (a[0].k == V_NUM && a[1].k == V_NUM) {
        *out = val_num(atan2(a[0].u.n, a[1].u.n));
        return 0;
    }
    vobj *o = a[0].k == V_OBJ ? AS_OBJ(a[0]) : a[1].k == V_OBJ ? AS_OBJ(a[1]) : NULL;
    if (o && o->cls->arith) {
        int r = o->cls->arith(I, OP_ATAN2, a[0], a[1], out);
        if (r != 0)
            return r < 0 ? -1 : 0;
    }
    return err_at(I, NULL, ERR_TYPE, "atan2 expects two numbers, got %s and %s", val_type_name(a[0]),
                  val_type_name(a[1]));
}

static int minmax(interp *I, value *a, int n, value *out, int want_max)
{
    /* min(a, b, …) or min(list) */
    value *items = a;
    size_t count = (size_t)n;
    if (n == 1 && a[0].k == V_LIST) {
        items = AS_LIST(a[0])->items;
        count = AS_LIST(a[0])->n;
    }
    if (count == 0)
        return err_at(I, NULL, ERR_VALUE, "%s of nothing (give at least one value)", want_max ? "max" : "min");
    value best = items[0];
    val_ref(best);
    for (size_t i = 1; i < count; i++) {
        value x = items[i];
        if (best.k == V_NUM && x.k == V_NUM) {
            if (want_max ? x.u.n > best.u.n : x.u.n < best.u.n)
                best = x;
            continue;
        }
        /* fields and images: element-wise through the arith hook */
        value r;
        int op = want_max ? OP_MAX : OP_MIN;
        vobj *o = best.k == V_OBJ ? AS_OBJ(best) : x.k == V_OBJ ? AS_OBJ(x) : NULL;
        int h = o && o->cls->arith ? o->cls->arith(I, op, best, x, &r) : 0;
        if (h < 0) {
            val_unref(I, best);
            return -1;
        }
        if (!h) {
            val_unref(I, best);
            return err_at(I, NULL, ERR_TYPE, "%s expects numbers, got %s and %s", want_max ? "max" : "min",
                          val_type_name(best), val_type_name(x));
        }
        val_unref(I, best);
        best = r;
    }
    *out = best;
    return 0;
}

static int b_min(interp *I, value *a, int n, value *out) { return minmax(I, a, n, out, 0); }
static int b_max(interp *I, value *a, int n, value *out) { return minmax(I, a, n, out, 1); }

static int b_clamp(interp *I, value *a, int n, value *out)
{
    (void)n;
    value lo[2] = {a[0], a[1]}, t;
    if (minmax(I, lo, 2, &t, 1))
        return -1;
    value hi[2] = {t, a[2]};
    int r = minmax(I, hi, 2, out, 0);
    val_unref(I, t);
    return r;
}

static int b_lerp(interp *I, value *a, int n, value *out)
{
    (void)n;
    /* a + (b - a) * t, element-wise */
    value d, m;
    if (eval_binary(I, T_MINUS, a[1], a[0], &d, NULL))
        return -1;
    int r = eval_binary(I, T_STAR, d, a[2], &m, NULL);
    val_unref(I, d);
    if (r)
        return -1;
    r = eval_binary(I, T_PLUS, a[0], m, out, NULL);
    val_unref(I, m);
    return r;
}

/* ---- vectors ------------------------------------------------------------------ */

static int b_dot(interp *I, value *a, int n, value *out)
{
    (void)n;
    double x[64], y[64];
    if (a[0].k != V_LIST || a[1].k != V_LIST || AS_LIST(a[0])->n != AS_LIST(a[1])->n ||
        AS_LIST(a[0])->n > 64)
        return err_at(I, NULL, ERR_TYPE, "dot expects two lists of numbers of the same length");
    size_t k = AS_LIST(a[0])->n;
    if (builtin_get_vec(I, a[0], x, k, "dot's first argument") || builtin_get_vec(I, a[1], y, k, "dot's second argument"))
        return -1;
    double s = 0;
    for (size_t i = 0; i < k; i++)
        s += x[i] * y[i];
    *out = val_num(s);
    return 0;
}

static int b_length(interp *I, value *a, int n, value *out)
{
    (void)n;
    double x[64];
    if (a[0].k != V_LIST || AS_LIST(a[0])->n > 64 || builtin_get_vec(I, a[0], x, AS_LIST(a[0])->n, "norm's argument"))
        return I->err.active ? -1 : err_at(I, NULL, ERR_TYPE, "norm expects a list of numbers");
    double s = 0;
    for (size_t i = 0; i < AS_LIST(a[0])->n; i++)
        s += x[i] * x[i];
    *out = val_num(sqrt(s));
    return 0;
}

/* ---- lists -------------------------------------------------------------------- */

static int b_len(interp *I, value *a, int n, value *out)
{
    (void)n;
    switch (a[0].k) {
    case V_LIST: *out = val_num((double)AS_LIST(a[0])->n); return 0;
    case V_STR: *out = val_num((double)AS_STR(a[0])->len); return 0;
    case V_REC: *out = val_num((double)AS_REC(a[0])->n); return 0;
    default: return err_at(I, NULL, ERR_TYPE, "len expects a list, string or record, got %s", val_type_name(a[0]));
    }
}

static int b_range(interp *I, value *a, int n, value *out)
{
    (void)n;
    /* range(n) = [0 .. n-1]; range(a, b) = [a .. b-1]; range(a, b, step) */
    double start = 0, stop, step = 1;
    if (a[1].k == V_NIL) {
        stop = a[0].u.n;
    } else {
        start = a[0].u.n;
        stop = a[1].u.n;
    }
    if (a[2].k != V_NIL)
        step = a[2].u.n;
    if (step == 0 || !isfinite(step) || !isfinite(start) || !isfinite(stop))
        return err_at(I, NULL, ERR_VALUE, "range needs finite bounds and a non-zero step");
    double count = ceil((stop - start) / step);
    if (count < 0)
        count = 0;
    if (count > I->lim.max_list)
        return err_at(I, NULL, ERR_LIMIT, "range of %.0f items is longer than the list limit of %.0f (raise it with --max-list)",
                      count, I->lim.max_list);
    if (I->lazy_range) { /* a `for` walks the items without the list (eval.c) */
        I->lazy_range->start = start;
        I->lazy_range->step = step;
        I->lazy_range->count = (size_t)count;
        I->lazy_range->used = 1;
        return 0;
    }
    value l = val_list(I, (size_t)count);
    if (l.k == V_NIL)
        return -1;
    for (size_t i = 0; i < (size_t)count; i++)
        if (val_list_push(I, AS_LIST(l), val_num(start + step * (double)i))) {
            val_unref(I, l);
            return -1;
        }
    *out = l;
    return 0;
}

static int b_linspace(interp *I, value *a, int n, value *out)
{
    (void)n;
    long k;
    if (builtin_get_int(I, a[2], 1, (long)I->lim.max_list, &k, "linspace: argument 'n'"))
        return -1;
    value l = val_list(I, (size_t)k);
    if (l.k == V_NIL)
        return -1;
    for (long i = 0; i < k; i++) {
        double t = k == 1 ? 0 : (double)i / (double)(k - 1);
        if (val_list_push(I, AS_LIST(l), val_num(a[0].u.n + (a[1].u.n - a[0].u.n) * t))) {
            val_unref(I, l);
            return -1;
        }
    }
    *out = l;
    return 0;
}

static int b_map(interp *I, value *a, int n, value *out)
{
    (void)n;
    vlist *src = AS_LIST(a[0]);
    value l = val_list(I, src->n);
    if (l.k == V_NIL)
        return -1;
    for (size_t i = 0; i < src->n; i++) {
        value r;
        if (eval_call_value(I, a[1], &src->items[i], 1, &r) || val_list_push(I, AS_LIST(l), r)) {
            val_unref(I, l);
            return -1;
        }
    }
    *out = l;
    return 0;
}

static int b_filter(interp *I, value *a, int n, value *out)
{
    (void)n;
    vlist *src = AS_LIST(a[0]);
    value l = val_list(I, 0);
    if (l.k == V_NIL)
        return -1;
    for (size_t i = 0; i < src->n; i++) {
        value r;
        if (eval_call_value(I, a[1], &src->items[i], 1, &r)) {
            val_unref(I, l);
            return -1;
        }
        int keep = val_truthy(r);
        val_unref(I, r);
        if (keep) {
            val_ref(src->items[i]);
            if (val_list_push(I, AS_LIST(l), src->items[i])) {
                val_unref(I, l);
                return -1;
            }
        }
    }
    *out = l;
    return 0;
}

static int b_fold(interp *I, value *a, int n, value *out)
{
    (void)n;
    vlist *src = AS_LIST(a[0]);
    value acc = a[1];
    val_ref(acc);
    for (size_t i = 0; i < src->n; i++) {
        value args[2] = {acc, src->items[i]}, r;
        int rc = eval_call_value(I, a[2], args, 2, &r);
        val_unref(I, acc);
        if (rc)
            return -1;
        acc = r;
    }
    *out = acc;
    return 0;
}

/* x = concat(x, …) where the variable x holds the only other reference to
 * its list (eval.c sets append_target then): the list is extended in place,
 * amortised O(1) per item, which no one can observe. Anything else (an
 * argument that is not a list, the list limit) takes the copying path,
 * which reports it as before. 1 done, 0 not applicable, -1 out of memory. */
static int concat_in_place(interp *I, value *a, int n, value *out)
{
    if (n < 1 || a[0].k != V_LIST || I->append_target != a[0].u.h || a[0].u.h->rc != 2)
        return 0;
    vlist *l = AS_LIST(a[0]);
    size_t total = l->n;
    for (int k = 1; k < n; k++) {
        if (a[k].k != V_LIST)
            return 0;
        total += AS_LIST(a[k])->n;
    }
    if ((double)total > I->lim.max_list)
        return 0;
    if (total > l->cap) {
        size_t cap = l->cap * 2 > total ? l->cap * 2 : total;
        value *items = mem_realloc(I, l->items, cap * sizeof *items);
        if (!items)
            return -1;
        l->items = items;
        l->cap = cap;
        I->count.list_grows++;
    }
    for (int k = 1; k < n; k++) {
        const vlist *m = AS_LIST(a[k]);
        for (size_t i = 0, mn = m->n; i < mn; i++) {
            val_ref(m->items[i]);
            l->items[l->n++] = m->items[i];
        }
    }
    val_ref(a[0]);
    *out = a[0];
    return 1;
}

static int b_concat(interp *I, value *a, int n, value *out)
{
    int r = concat_in_place(I, a, n, out);
    if (r)
        return r < 0 ? -1 : 0;
    value l = val_list(I, 0);
    if (l.k == V_NIL)
        return -1;
    for (int k = 0; k < n; k++) {
        if (a[k].k != V_LIST) {
            val_unref(I, l);
            return err_at(I, NULL, ERR_TYPE, "concat expects lists, but argument %d is %s", k + 1,
                          val_type_name(a[k]));
        }
        for (size_t i = 0; i < AS_LIST(a[k])->n; i++) {
            value x = AS_LIST(a[k])->items[i];
            val_ref(x);
            if (val_list_push(I, AS_LIST(l), x)) {
                val_unref(I, l);
                return -1;
            }
        }
    }
    *out = l;
    return 0;
}

static int b_sum(interp *I, value *a, int n, value *out)
{
    (void)n;
    vlist *src = AS_LIST(a[0]);
    value acc = val_num(0);
    for (size_t i = 0; i < src->n; i++) {
        value r;
        if (eval_binary(I, T_PLUS, acc, src->items[i], &r, NULL)) {
            val_unref(I, acc);
            return -1;
        }
        val_unref(I, acc);
        acc = r;
    }
    *out = acc;
    return 0;
}

static int b_reverse(interp *I, value *a, int n, value *out)
{
    (void)n;
    vlist *src = AS_LIST(a[0]);
    value l = val_list(I, src->n);
    if (l.k == V_NIL)
        return -1;
    for (size_t i = src->n; i-- > 0;) {
        val_ref(src->items[i]);
        if (val_list_push(I, AS_LIST(l), src->items[i])) {
            val_unref(I, l);
            return -1;
        }
    }
    *out = l;
    return 0;
}

static int b_repeat(interp *I, value *a, int n, value *out)
{
    (void)n;
    long times;
    if (builtin_get_int(I, a[1], 0, (long)I->lim.max_list, &times, "repeat: argument 'times'"))
        return -1;
    value l = val_list(I, 0);
    if (l.k == V_NIL)
        return -1;
    for (long t = 0; t < times; t++) {
        if (a[0].k == V_LIST) {
            for (size_t i = 0; i < AS_LIST(a[0])->n; i++) {
                val_ref(AS_LIST(a[0])->items[i]);
                if (val_list_push(I, AS_LIST(l), AS_LIST(a[0])->items[i])) {
                    val_unref(I, l);
                    return -1;
                }
            }
        } else {
            val_ref(a[0]);
            if (val_list_push(I, AS_LIST(l), a[0])) {
                val_unref(I, l);
                return -1;
            }
        }
    }
    *out = l;
    return 0;
}

static int b_keys(interp *I, value *a, int n, value *out)
{
    (void)n;
    vrec *r = AS_REC(a[0]);
    value l = val_list(I, r->n);
    if (l.k == V_NIL)
        return -1;
    for (size_t i = 0; i < r->n; i++)
        if (val_list_push(I, AS_LIST(l), val_cstr(I, r->keys[i]))) {
            val_unref(I, l);
            return -1;
        }
    *out = l;
    return 0;
}

static int b_has(interp *I, value *a, int n, value *out)
{
    (void)n;
    const char *k = interp_intern(I, AS_STR(a[1])->s, AS_STR(a[1])->len);
    *out = val_bool(k && val_rec_get(AS_REC(a[0]), k));
    return 0;
}

/* ---- strings and printing ------------------------------------------------------- */

static int b_str(interp *I, value *a, int n, value *out)
{
    (void)n;
    bytebuf b;
    bytebuf_init(&b);
    val_print(I, a[0], &b, 0);
    if (b.failed) {
        bytebuf_free(&b);
        return err_at(I, NULL, ERR_MEMORY, "out of memory");
    }
    *out = val_str(I, b.data ? (char *)b.data : "", b.len);
    bytebuf_free(&b);
    return out->k == V_NIL ? -1 : 0;
}

/* format("x = {} and {:.3f}", a, b): {} prints a value as print would;
 * {:SPEC} applies a printf-style spec (d, f, e, g, x with width/precision)
 * to a number; {{ and }} are literal braces. */
static int do_format(interp *I, const char *fmt, size_t flen, value *args, int nargs, bytebuf *b)
{
    int k = 0;
    for (size_t i = 0; i < flen; i++) {
        char c = fmt[i];
        if (c == '{' && i + 1 < flen && fmt[i + 1] == '{') {
            bytebuf_byte(b, '{');
            i++;
            continue;
        }
        if (c == '}' && i + 1 < flen && fmt[i + 1] == '}') {
            bytebuf_byte(b, '}');
            i++;
            continue;
        }
        if (c != '{') {
            bytebuf_byte(b, (unsigned char)c);
            continue;
        }
        size_t j = i + 1;
        while (j < flen && fmt[j] != '}')
            j++;
        if (j == flen)
            return err_at(I, NULL, ERR_VALUE, "format: '{' at offset %zu is not closed", i);
        if (k >= nargs)
            return err_at(I, NULL, ERR_VALUE, "format: more '{}' placeholders than values (%d given)", nargs);
        value v = args[k++];
        if (j == i + 1) {
            val_print(I, v, b, 0);
        } else {
            if (fmt[i + 1] != ':' || j - i - 2 > 20)
                return err_at(I, NULL, ERR_VALUE, "format: bad placeholder '%.*s' (use {} or {:.3f})",
                              (int)(j - i + 1), fmt + i);
            char spec[32];
            size_t sl = j - i - 2;
            memcpy(spec + 1, fmt + i + 2, sl);
            spec[0] = '%';
            spec[sl + 1] = 0;
            char conv = spec[sl];
            if (!strchr("dfegxs", conv) || strspn(spec + 1, "0123456789.-+ ") != sl - 1)
                return err_at(I, NULL, ERR_VALUE, "format: bad spec '%s' (conversions: d f e g x s)", spec + 1);
            if (conv == 's') {
                val_print(I, v, b, 0);
            } else if (v.k != V_NUM) {
                return err_at(I, NULL, ERR_TYPE, "format: '{:%s}' needs a number, got %s", spec + 1,
                              val_type_name(v));
            } else if (conv == 'd' || conv == 'x') {
                /* a long long holds only whole numbers up to 2^63: say so rather than cast */
                if (!(fabs(v.u.n) < 9223372036854775808.0)) {
                    char got[40];
                    val_fmt_number(v.u.n, got, sizeof got);
                    return err_at(I, NULL, ERR_VALUE, "format: '{:%s}' needs a number below 2^63 in size, got %s",
                                  spec + 1, isnan(v.u.n) ? "nan" : isinf(v.u.n) ? (v.u.n < 0 ? "-inf" : "inf") : got);
                }
                spec[sl] = 0;
                char sp2[40];
                snprintf(sp2, sizeof sp2, "%sll%c", spec, conv);
                bytebuf_printf(b, sp2, (long long)v.u.n);
            } else {
                char sp2[40];
                snprintf(sp2, sizeof sp2, "%s", spec);
                bytebuf_printf(b, sp2, v.u.n);
            }
        }
        i = j;
    }
    if (k < nargs)
        return err_at(I, NULL, ERR_VALUE, "format: %d value%s given but only %d placeholder%s", nargs,
                      nargs == 1 ? "" : "s", k, k == 1 ? "" : "s");
    return 0;
}

static int b_format(interp *I, value *a, int n, value *out)
{
    if (n < 1 || a[0].k != V_STR)
        return err_at(I, NULL, ERR_TYPE, "format expects a format string first");
    bytebuf b;
    bytebuf_init(&b);
    int rc = do_format(I, AS_STR(a[0])->s, AS_STR(a[0])->len, a + 1, n - 1, &b);
    if (rc == 0 && b.failed) /* the buffer's growth was refused by the allocation hook */
        rc = mem_engine_error(I, "format", "out of memory");
    if (rc == 0)
        *out = val_str(I, b.data ? (char *)b.data : "", b.len);
    bytebuf_free(&b);
    return rc;
}

static int b_print(interp *I, value *a, int n, value *out)
{
    bytebuf b;
    bytebuf_init(&b);
    for (int i = 0; i < n; i++) {
        if (i)
            bytebuf_byte(&b, ' ');
        val_print(I, a[i], &b, 0);
    }
    bytebuf_byte(&b, '\n');
    if (b.failed) { /* the buffer's growth was refused by the allocation hook */
        bytebuf_free(&b);
        return mem_engine_error(I, "print", "out of memory");
    }
    errno = 0;
    int bad = b.data && fwrite(b.data, 1, b.len, I->out) != b.len;
    bad |= fflush(I->out) != 0 || ferror(I->out);
    int e = errno;
    bytebuf_free(&b);
    *out = val_nil();
    if (bad) {
        clearerr(I->out); /* each failed print reports itself */
        return err_at(I, NULL, ERR_IO, "print: cannot write to standard output%s%s", e ? ": " : "",
                      e ? strerror(e) : "");
    }
    return 0;
}

static int b_type(interp *I, value *a, int n, value *out)
{
    (void)n;
    *out = val_cstr(I, val_type_name(a[0]));
    return out->k == V_NIL ? -1 : 0;
}

static int b_error(interp *I, value *a, int n, value *out)
{
    (void)n;
    (void)out;
    return err_at(I, NULL, ERR_VALUE, "%s", AS_STR(a[0])->s);
}

static int b_assert(interp *I, value *a, int n, value *out)
{
    (void)n;
    *out = val_nil();
    if (!val_truthy(a[0]))
        return err_at(I, NULL, ERR_VALUE, "assertion failed%s%s", a[1].k == V_STR ? ": " : "",
                      a[1].k == V_STR ? AS_STR(a[1])->s : "");
    return 0;
}

/* ---- randomness ---------------------------------------------------------------- */

/* random(i, seed) is the i-th number of the stream `seed`: a pure function
 * (counter-based), so scripts are reproducible and order-independent. The
 * default seed is the global --seed. */
static uint64_t seed_of(interp *I, value s)
{
    if (s.k == V_NUM)
        return (uint64_t)(int64_t)s.u.n ^ 0x5eedull; /* declared int: whole and at most 2^53 */
    return I->seed;
}

static int b_random(interp *I, value *a, int n, value *out)
{
    (void)n;
    uint64_t h = rng_hash3(seed_of(I, a[1]), (uint64_t)a[0].u.n, 0x72616e64ull, 0);
    *out = val_num(rng_to_unit(h));
    return 0;
}

static int b_randoms(interp *I, value *a, int n, value *out)
{
    (void)n;
    long k;
    if (builtin_get_int(I, a[0], 0, (long)I->lim.max_list, &k, "randoms: argument 'n'"))
        return -1;
    value l = val_list(I, (size_t)k);
    if (l.k == V_NIL)
        return -1;
    uint64_t s = seed_of(I, a[1]);
    for (long i = 0; i < k; i++) {
        uint64_t h = rng_hash3(s, (uint64_t)i, 0x72616e64ull, 0);
        if (val_list_push(I, AS_LIST(l), val_num(rng_to_unit(h)))) {
            val_unref(I, l);
            return -1;
        }
    }
    *out = l;
    return 0;
}

static int b_seed(interp *I, value *a, int n, value *out)
{
    (void)a;
    (void)n;
    *out = val_num((double)I->seed);
    return 0;
}

/* ---- table ---------------------------------------------------------------------- */

static const bparam p_x[] = {{"x", "num+inf+nan|list+inf+nan|field|image", NULL}};
static const bparam p_xy[] = {{"x", "any", NULL}, {"y", "any", NULL}};
static const bparam p_yx[] = {{"y", "num+inf+nan|field", NULL}, {"x", "num+inf+nan|field", NULL}};
static const bparam p_clamp[] = {{"x", "any", NULL}, {"lo", "any", "0"}, {"hi", "any", "1"}};
static const bparam p_lerp[] = {{"a", "any", NULL}, {"b", "any", NULL}, {"t", "any", NULL}};
static const bparam p_none[] = {{"_unused", "nil", "nil"}};
static const bparam p_vec[] = {{"v", "vec+inf+nan", NULL}};
static const bparam p_vv[] = {{"a", "vec+inf+nan", NULL}, {"b", "vec+inf+nan", NULL}};
static const bparam p_any[] = {{"value", "any", NULL}};
static const bparam p_range[] = {{"start", "num", NULL}, {"stop", "num", "nil"}, {"step", "num", "nil"}};
static const bparam p_linspace[] = {{"from", "num", NULL}, {"to", "num", NULL}, {"n", "int", NULL}};
static const bparam p_listfn[] = {{"list", "list+inf+nan", NULL}, {"f", "func", NULL}};
static const bparam p_fold[] = {{"list", "list+inf+nan", NULL}, {"init", "any", NULL}, {"f", "func", NULL}};
static const bparam p_list[] = {{"list", "list+inf+nan", NULL}};
static const bparam p_repeat[] = {{"value", "any", NULL}, {"times", "int>=0", NULL}};
static const bparam p_rec[] = {{"record", "rec", NULL}};
static const bparam p_has[] = {{"record", "rec", NULL}, {"key", "str", NULL}};
static const bparam p_var[] = {{"_", "nil", "nil"}};
static const bparam p_msg[] = {{"message", "str", NULL}};
static const bparam p_assert[] = {{"cond", "any", NULL}, {"message", "str", "nil"}};
static const bparam p_random[] = {{"i", "int[0,9007199254740992]", NULL}, {"seed", "int", "nil"}};
static const bparam p_randoms[] = {{"n", "int>=0", NULL}, {"seed", "int", "nil"}};

static const builtin core[] = {
    BUILTIN("sqrt", b_sqrt, p_x, "Square root; element-wise on lists, per colour channel on images, symbolic on fields."),
    BUILTIN("exp", b_exp, p_x, "e^x."),
    BUILTIN("log", b_log, p_x, "Natural logarithm."),
    BUILTIN("sin", b_sin, p_x, "Sine (radians)."),
    BUILTIN("cos", b_cos, p_x, "Cosine (radians)."),
    BUILTIN("tan", b_tan, p_x, "Tangent (radians)."),
    BUILTIN("asin", b_asin, p_x, "Arc sine."),
    BUILTIN("acos", b_acos, p_x, "Arc cosine."),
    BUILTIN("atan", b_atan, p_x, "Arc tangent."),
    BUILTIN("abs", b_abs, p_x, "Absolute value."),
    BUILTIN("floor", b_floor, p_x, "Largest whole number ≤ x."),
    BUILTIN("ceil", b_ceil, p_x, "Smallest whole number ≥ x."),
    BUILTIN("round", b_round, p_x, "Nearest whole number (halves round up)."),
    BUILTIN("sign", b_sign, p_x, "-1, 0 or 1."),
    BUILTIN("pow", b_pow, p_xy, "x^y (same as the ^ operator)."),
    BUILTIN("atan2", b_atan2, p_yx, "Angle of the point (x, y) in radians, in (-pi, pi]."),
    BUILTIN_VAR("min", b_min, p_var, "Smallest of the arguments, or of one list."),
    BUILTIN_VAR("max", b_max, p_var, "Largest of the arguments, or of one list."),
    BUILTIN("clamp", b_clamp, p_clamp, "min(max(x, lo), hi)."),
    BUILTIN("lerp", b_lerp, p_lerp, "a + (b - a) * t; element-wise on vectors."),
    BUILTIN("dot", b_dot, p_vv, "Dot product of two vectors."),
    BUILTIN("norm", b_length, p_vec, "Euclidean length of a vector."),
    BUILTIN("len", b_len, p_any, "Length of a list, string or record."),
    BUILTIN("range", b_range, p_range, "range(n) is [0, 1, …, n-1]; range(a, b, step) counts from a up to (not including) b."),
    BUILTIN("linspace", b_linspace, p_linspace, "n evenly spaced numbers from `from` to `to` inclusive."),
    BUILTIN("map", b_map, p_listfn, "[f(x) for x in list]."),
    BUILTIN("filter", b_filter, p_listfn, "The items x of list for which f(x) is true."),
    BUILTIN("fold", b_fold, p_fold, "f(…f(f(init, x0), x1)…, xn)."),
    BUILTIN("sum", b_sum, p_list, "Sum of a list (numbers, vectors, images or fields)."),
    BUILTIN_VAR("concat", b_concat, p_var, "Concatenation of lists."),
    BUILTIN("reverse", b_reverse, p_list, "The list in reverse order."),
    BUILTIN("repeat", b_repeat, p_repeat, "A list repeated `times` times (a single value becomes a list of copies)."),
    BUILTIN("keys", b_keys, p_rec, "The field names of a record, in order."),
    BUILTIN("has", b_has, p_has, "Whether a record has a field."),
    BUILTIN("str", b_str, p_any, "The printed form of a value, as a string."),
    BUILTIN_VAR("format", b_format, p_var, "format(\"n = {} ({:.2f})\", a, b): {} prints a value, {:SPEC} a number with a printf spec (d f e g x)."),
    BUILTIN_VAR("print", b_print, p_var, "Print values separated by spaces, then a newline."),
    BUILTIN("type", b_type, p_any, "The type name of a value: \"number\", \"list\", \"image\"…"),
    BUILTIN("error", b_error, p_msg, "Stop with an error message."),
    BUILTIN("assert", b_assert, p_assert, "Stop with an error if cond is false."),
    BUILTIN("random", b_random, p_random, "The i-th uniform number in [0, 1) of the stream `seed` (default: --seed). Pure: same i, same number."),
    BUILTIN("randoms", b_randoms, p_randoms, "A list of n uniform numbers in [0, 1): random(0..n-1, seed)."),
    BUILTIN("seed", b_seed, p_none, "The global seed (--seed, default 1)."),
};

int builtin_core_init(interp *I)
{
    env *root = I->globals;
    while (root->parent)
        root = root->parent;
    const char *pi = interp_intern(I, "pi", 2), *tau = interp_intern(I, "tau", 3), *inf = interp_intern(I, "inf", 3);
    if (!pi || !tau || !inf || val_env_define(I, root, pi, val_num(3.14159265358979323846)) ||
        val_env_define(I, root, tau, val_num(6.28318530717958647692)) || val_env_define(I, root, inf, val_num(INFINITY)))
        return -1;
    return BUILTIN_REGISTER(I, core);
}
