/* ifs.c — IFS and RIFS objects: validation and alias tables.
 * IFS: seed 003 §2; RIFS conditions (i) rows sum to 1, (ii) irreducible:
 * seed 001 §2. Alias method: Walker (1977), Vose (1991). */
#include "ifs.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------- alias tables ---------- */

rt_code ifs_alias_build(ifs_alias *a, const double *w, int n, rt_error *e)
{
    a->n = 0;
    a->thresh = NULL;
    a->sel = NULL;
    double sum = 0;
    for (int i = 0; i < n; i++)
        sum += w[i];
    if (n < 1 || !(sum > 0))
        return rt_fail(e, RT_EINVAL, "probabilities are all 0");
    double *q = rt_malloc(sizeof *q * (size_t)n);
    int *small = rt_malloc(sizeof *small * (size_t)n);
    int *large = rt_malloc(sizeof *large * (size_t)n);
    a->thresh = rt_malloc(sizeof *a->thresh * (size_t)n);
    a->sel = rt_malloc(sizeof *a->sel * 2 * (size_t)n);
    if (!q || !small || !large || !a->thresh || !a->sel) {
        rt_free(q);
        rt_free(small);
        rt_free(large);
        ifs_alias_free(a);
        return rt_fail(e, RT_ENOMEM, "out of memory for an alias table");
    }
    /* Vose: scaled masses q_i = n w_i / sum; "small" columns (q < 1) are
     * topped up by a "large" one, which becomes their alias. */
    int ns = 0, nl = 0;
    for (int i = 0; i < n; i++) {
        q[i] = w[i] * n / sum;
        if (q[i] < 1)
            small[ns++] = i;
        else
            large[nl++] = i;
    }
    while (ns > 0 && nl > 0) {
        int s = small[--ns], l = large[nl - 1];
        double t = ldexp(q[s], 32);
        a->thresh[s] = t >= 4294967295.0 ? 0xffffffffu : (uint32_t)t;
        a->sel[2 * s] = (uint32_t)l;
        a->sel[2 * s + 1] = (uint32_t)s;
        q[l] = (q[l] + q[s]) - 1;
        if (q[l] < 1) {
            nl--;
            small[ns++] = l;
        }
    }
    /* Leftovers keep all of their own column (mass 1 up to rounding): alias
     * = self, so the comparison result does not matter. A leftover "small"
     * entry here has q within rounding of 1, never a true 0: zero entries
     * are only pushed to small and consumed first while a large exists. */
    while (nl > 0) {
        int l = large[--nl];
        a->thresh[l] = 0xffffffffu;
        a->sel[2 * l] = a->sel[2 * l + 1] = (uint32_t)l;
    }
    while (ns > 0) {
        int s = small[--ns];
        a->thresh[s] = 0xffffffffu;
        a->sel[2 * s] = a->sel[2 * s + 1] = (uint32_t)s;
    }
    a->n = n;
    rt_free(q);
    rt_free(small);
    rt_free(large);
    return RT_OK;
}

void ifs_alias_free(ifs_alias *a)
{
    rt_free(a->thresh);
    rt_free(a->sel);
    memset(a, 0, sizeof *a);
}

double ifs_alias_prob(const ifs_alias *a, int i)
{
    /* Column c is picked for the r>>32 values v with floor(v n / 2^32) = c. */
    double total = 0;
    for (int c = 0; c < a->n; c++) {
        uint64_t v0 = ((uint64_t)c << 32) / (uint64_t)a->n;
        if (((v0 * (uint64_t)a->n) >> 32) < (uint64_t)c)
            v0++;
        uint64_t v1 = ((uint64_t)(c + 1) << 32) / (uint64_t)a->n;
        if (((v1 * (uint64_t)a->n) >> 32) < (uint64_t)(c + 1))
            v1++;
        double pc = (double)(v1 - v0) * 0x1.0p-32;
        double keep = (double)a->thresh[c] * 0x1.0p-32;
        if (a->sel[2 * c + 1] == (uint32_t)i)
            total += pc * keep;
        if (a->sel[2 * c] == (uint32_t)i)
            total += pc * (1 - keep);
    }
    return total;
}

/* ---------- maps ---------- */

rt_code ifs_check_maps(const affine *maps, int n, int allow_expanding, int *dim, double *maxc,
                       int *worst, char *warn, rt_error *e)
{
    if (warn)
        warn[0] = 0;
    if (n < 1)
        return rt_fail(e, RT_EINVAL, "IFS has no maps");
    if (n > IFS_MAX_MAPS)
        return rt_fail(e, RT_EINVAL, "IFS has %d maps (at most %d)", n, IFS_MAX_MAPS);
    for (int i = 0; i < n; i++) {
        if (maps[i].dim != 2 && maps[i].dim != 3)
            return rt_fail(e, RT_EINVAL, "map %d has dimension %d (expected 2 or 3)", i + 1,
                           maps[i].dim);
        if (maps[i].dim != maps[0].dim)
            return rt_fail(e, RT_EINVAL,
                           "map %d is %d-D but map 1 is %d-D (all maps need the same dimension)",
                           i + 1, maps[i].dim, maps[0].dim);
    }
    double mc = -1;
    int w = 0;
    for (int i = 0; i < n; i++) {
        double c = affine_contraction(&maps[i]);
        if (!(c <= mc)) { /* also NaN */
            mc = c;
            w = i;
        }
    }
    *dim = maps[0].dim;
    *maxc = mc;
    *worst = w;
    if (!(mc < 1)) {
        char msg[256];
        snprintf(msg, sizeof msg, "map %d is not contractive: its norm is %.6g (expected < 1)",
                 w + 1, mc);
        if (!allow_expanding || !isfinite(mc))
            return rt_fail(e, RT_EINVAL, "%s", msg);
        if (warn)
            memcpy(warn, msg, strlen(msg) + 1);
    }
    return RT_OK;
}

static affine *copy_maps(const affine *maps, int n)
{
    affine *m = rt_malloc(sizeof *m * (size_t)n);
    if (m)
        memcpy(m, maps, sizeof *m * (size_t)n);
    return m;
}

/* ---------- IFS ---------- */

rt_code ifs_build(ifs *out, const affine *maps, int n, const double *p, int flags, rt_error *e)
{
    memset(out, 0, sizeof *out);
    int dim, worst;
    double maxc;
    char warn[256];
    rt_code rc;
    /* dimension and count first, probabilities next, contraction last (so a
     * probability typo is reported before a norm). */
    if ((rc = ifs_check_maps(maps, n, 1, &dim, &maxc, &worst, warn, e)))
        return rc;
    double *q = rt_malloc(sizeof *q * (size_t)n);
    if (!q)
        return rt_fail(e, RT_ENOMEM, "out of memory for an IFS");
    if (p) {
        double sum = 0;
        for (int i = 0; i < n; i++) {
            if (!(p[i] >= 0) || !isfinite(p[i])) {
                rt_free(q);
                return rt_fail(e, RT_EINVAL, "probability %d is %.6g (expected >= 0)", i + 1, p[i]);
            }
            sum += p[i];
        }
        if (!(fabs(sum - 1) <= IFS_SUM_TOL) && !(flags & IFS_NORMALISE)) {
            rt_free(q);
            return rt_fail(e, RT_EINVAL,
                           "probabilities sum to %.10g, not 1 (use normalize: true to rescale them)", sum);
        }
        if (!(sum > 0)) {
            rt_free(q);
            return rt_fail(e, RT_EINVAL, "probabilities are all 0");
        }
        for (int i = 0; i < n; i++)
            q[i] = p[i] / sum;
    } else {
        /* default weights: |det|, floored at IFS_DET_FLOOR of the largest */
        double big = 0, sum = 0;
        for (int i = 0; i < n; i++) {
            q[i] = fabs(affine_det(&maps[i]));
            if (!isfinite(q[i]))
                q[i] = 0;
            if (q[i] > big)
                big = q[i];
        }
        double floor_w = big > 0 ? IFS_DET_FLOOR * big : 1;
        for (int i = 0; i < n; i++) {
            if (q[i] < floor_w)
                q[i] = floor_w;
            sum += q[i];
        }
        for (int i = 0; i < n; i++)
            q[i] /= sum;
    }
    if (!(maxc < 1) && !(flags & IFS_ALLOW_EXPANDING)) {
        rt_free(q);
        return rt_fail(e, RT_EINVAL, "%s", warn);
    }
    out->maps = copy_maps(maps, n);
    if (!out->maps) {
        rt_free(q);
        return rt_fail(e, RT_ENOMEM, "out of memory for an IFS");
    }
    if ((rc = ifs_alias_build(&out->alias, q, n, e))) {
        rt_free(q);
        rt_free(out->maps);
        out->maps = NULL;
        return rc;
    }
    out->n = n;
    out->dim = dim;
    out->p = q;
    out->max_contraction = maxc;
    out->worst_map = worst;
    memcpy(out->warning, warn, sizeof out->warning);
    return RT_OK;
}

void ifs_free(ifs *f)
{
    rt_free(f->maps);
    rt_free(f->p);
    ifs_alias_free(&f->alias);
    memset(f, 0, sizeof *f);
}

/* ---------- RIFS ---------- */

/* Append ", " + text to a message buffer without overflowing it. */
static void msg_append(char *buf, size_t cap, const char *text)
{
    size_t len = strlen(buf);
    if (len + strlen(text) + 8 >= cap) {
        if (len + 5 < cap && !strstr(buf, ", …"))
            memcpy(buf + len, ", …", sizeof ", …");
        return;
    }
    if (len)
        memcpy(buf + len, ", ", 3), len += 2;
    memcpy(buf + len, text, strlen(text) + 1);
}

static void row_name(char *buf, size_t cap, int order, int n, int r)
{
    if (order == 1)
        snprintf(buf, cap, "%d", r + 1);
    else
        snprintf(buf, cap, "(%d, %d)", r / n + 1, r % n + 1);
}

/* Tarjan's strongly connected components, iterative. Nodes 0..V-1 with
 * out-edges given by succ(node, k) for k < n (value -1 = no edge).
 * comp[v] receives the component id; returns the number of components, or
 * -1 on allocation failure. Components are numbered in reverse topological
 * order (a sink component gets a lower id than any component leading to it). */
typedef struct graph {
    int V, n, order;
    const double *P;
    const unsigned char *used; /* order 2: rows in use */
} graph;

static int graph_succ(const graph *g, int v, int k)
{
    if (g->used && !g->used[v])
        return -1;
    if (!(g->P[(size_t)v * (size_t)g->n + (size_t)k] > 0))
        return -1;
    if (g->order == 1)
        return k;
    int w = (v % g->n) * g->n + k;
    return g->used[w] ? w : -1;
}

static int tarjan(const graph *g, int *comp)
{
    int V = g->V;
    int *idx = rt_malloc(sizeof *idx * (size_t)V), *low = rt_malloc(sizeof *low * (size_t)V);
    int *stk = rt_malloc(sizeof *stk * (size_t)V), *cs = rt_malloc(sizeof *cs * (size_t)V);
    int *ck = rt_malloc(sizeof *ck * (size_t)V);
    unsigned char *on = rt_calloc((size_t)V, 1);
    int ncomp = -1;
    if (!idx || !low || !stk || !cs || !ck || !on)
        goto done;
    for (int v = 0; v < V; v++)
        idx[v] = -1;
    int counter = 0, sp = 0;
    ncomp = 0;
    for (int root = 0; root < V; root++) {
        if (idx[root] >= 0 || (g->used && !g->used[root]))
            continue;
        int csp = 0;
        cs[csp] = root;
        ck[csp++] = 0;
        idx[root] = low[root] = counter++;
        stk[sp++] = root;
        on[root] = 1;
        while (csp > 0) {
            int v = cs[csp - 1];
            if (ck[csp - 1] < g->n) {
                int k = ck[csp - 1]++;
                int w = graph_succ(g, v, k);
                if (w < 0)
                    continue;
                if (idx[w] < 0) {
                    idx[w] = low[w] = counter++;
                    stk[sp++] = w;
                    on[w] = 1;
                    cs[csp] = w;
                    ck[csp++] = 0;
                } else if (on[w] && idx[w] < low[v]) {
                    low[v] = idx[w];
                }
                continue;
            }
            if (low[v] == idx[v]) {
                int w;
                do {
                    w = stk[--sp];
                    on[w] = 0;
                    comp[w] = ncomp;
                } while (w != v);
                ncomp++;
            }
            csp--;
            if (csp > 0) {
                int u = cs[csp - 1];
                if (low[v] < low[u])
                    low[u] = low[v];
            }
        }
    }
done:
    rt_free(idx);
    rt_free(low);
    rt_free(stk);
    rt_free(cs);
    rt_free(ck);
    rt_free(on);
    return ncomp;
}

void rifs_free(rifs *r)
{
    if (r->row)
        for (int i = 0; i < r->rows; i++)
            ifs_alias_free(&r->row[i]);
    rt_free(r->row);
    rt_free(r->maps);
    rt_free(r->P);
    memset(r, 0, sizeof *r);
}

/* Order 1: the first (i, j) in row-major order with j unreachable from i. */
static rt_code check_irreducible1(const rifs *r, rt_error *e)
{
    int n = r->n;
    int *queue = rt_malloc(sizeof *queue * (size_t)n);
    unsigned char *seen = rt_malloc((size_t)n);
    if (!queue || !seen) {
        rt_free(queue);
        rt_free(seen);
        return rt_fail(e, RT_ENOMEM, "out of memory checking a RIFS");
    }
    rt_code rc = RT_OK;
    for (int i = 0; i < n && !rc; i++) {
        memset(seen, 0, (size_t)n);
        int qh = 0, qt = 0;
        queue[qt++] = i;
        seen[i] = 1;
        /* reachable in >= 0 steps: i reaches itself trivially; that is
         * enough, since some other state must also reach i when n > 1 */
        while (qh < qt) {
            int v = queue[qh++];
            for (int k = 0; k < n; k++)
                if (r->P[(size_t)v * n + k] > 0 && !seen[k]) {
                    seen[k] = 1;
                    queue[qt++] = k;
                }
        }
        for (int j = 0; j < n; j++)
            if (!seen[j]) {
                rc = rt_fail(e, RT_EINVAL, "matrix is not irreducible: state %d cannot reach state %d",
                             i + 1, j + 1);
                break;
            }
    }
    rt_free(queue);
    rt_free(seen);
    return rc;
}

static rt_code check_irreducible2(rifs *r, const unsigned char *used, rt_error *e)
{
    int n = r->n, V = n * n;
    /* an edge into an unused pair */
    for (int v = 0; v < V; v++) {
        if (!used[v])
            continue;
        for (int k = 0; k < n; k++) {
            int w = (v % n) * n + k;
            if (r->P[(size_t)v * n + k] > 0 && !used[w])
                return rt_fail(e, RT_EINVAL,
                               "pair (%d, %d) can be followed by map %d, but row (%d, %d) is all zero",
                               v / n + 1, v % n + 1, k + 1, w / n + 1, w % n + 1);
        }
    }
    int *comp = rt_malloc(sizeof *comp * (size_t)V);
    if (!comp)
        return rt_fail(e, RT_ENOMEM, "out of memory checking a RIFS");
    graph g = {V, n, 2, r->P, used};
    int nc = tarjan(&g, comp);
    if (nc < 0) {
        rt_free(comp);
        return rt_fail(e, RT_ENOMEM, "out of memory checking a RIFS");
    }
    /* closed components: no edge leaves them */
    unsigned char *open = rt_calloc((size_t)nc + 1, 1);
    if (!open) {
        rt_free(comp);
        return rt_fail(e, RT_ENOMEM, "out of memory checking a RIFS");
    }
    for (int v = 0; v < V; v++) {
        if (!used[v])
            continue;
        for (int k = 0; k < n; k++) {
            int w = graph_succ(&g, v, k);
            if (w >= 0 && comp[w] != comp[v])
                open[comp[v]] = 1;
        }
    }
    int first = -1, second = -1; /* smallest pair of the first two closed classes */
    for (int v = 0; v < V; v++) {
        if (!used[v] || open[comp[v]])
            continue;
        if (first < 0)
            first = v;
        else if (comp[v] != comp[first] && second < 0)
            second = v;
    }
    rt_code rc = RT_OK;
    if (first < 0) {
        rc = rt_fail(e, RT_EINVAL, "matrix has no used pair (every row is all zero)");
    } else if (second >= 0) {
        rc = rt_fail(e, RT_EINVAL, "matrix is not irreducible: pair (%d, %d) cannot reach pair (%d, %d)",
                     first / n + 1, first % n + 1, second / n + 1, second % n + 1);
    } else {
        unsigned char *occurs = rt_calloc((size_t)n, 1);
        if (!occurs) {
            rc = rt_fail(e, RT_ENOMEM, "out of memory checking a RIFS");
        } else {
            for (int v = 0; v < V; v++)
                if (used[v] && comp[v] == comp[first])
                    occurs[v % n] = 1;
            for (int k = 0; k < n; k++)
                if (!occurs[k]) {
                    rc = rt_fail(e, RT_EINVAL, "map %d never occurs in the recurrent pairs", k + 1);
                    break;
                }
            rt_free(occurs);
        }
        r->start = first;
    }
    rt_free(open);
    rt_free(comp);
    return rc;
}

rt_code rifs_build(rifs *out, const affine *maps, int n, int order, const double *P, int flags,
                   rt_error *e)
{
    memset(out, 0, sizeof *out);
    int dim, worst;
    double maxc;
    char warn[256];
    rt_code rc;
    if (order != 1 && order != 2)
        return rt_fail(e, RT_EINVAL, "Markov order %d is not supported (expected 1 or 2)", order);
    if ((rc = ifs_check_maps(maps, n, 1, &dim, &maxc, &worst, warn, e)))
        return rc;
    int rows = order == 1 ? n : n * n;
    size_t cells = (size_t)rows * (size_t)n;
    char name[32];
    /* entries >= 0 */
    for (size_t c = 0; c < cells; c++)
        if (!(P[c] >= 0) || !isfinite(P[c])) {
            row_name(name, sizeof name, order, n, (int)(c / (size_t)n));
            if (order == 1)
                return rt_fail(e, RT_EINVAL, "matrix entry (%d, %d) is %.6g (expected >= 0)",
                               (int)(c / (size_t)n) + 1, (int)(c % (size_t)n) + 1, P[c]);
            return rt_fail(e, RT_EINVAL, "matrix entry row %s, column %d is %.6g (expected >= 0)",
                           name, (int)(c % (size_t)n) + 1, P[c]);
        }
    out->P = rt_malloc(sizeof *out->P * cells);
    unsigned char *used = rt_malloc((size_t)rows);
    if (!out->P || !used) {
        rt_free(used);
        rifs_free(out);
        return rt_fail(e, RT_ENOMEM, "out of memory for a RIFS");
    }
    /* row sums: collect every bad row in one message */
    char bad[400] = "";
    int nbad = 0;
    for (int r = 0; r < rows; r++) {
        double sum = 0;
        for (int k = 0; k < n; k++)
            sum += P[(size_t)r * n + k];
        used[r] = sum > 0;
        if (!(sum > 0)) {
            if (order == 1) {
                rt_free(used);
                rifs_free(out);
                return rt_fail(e, RT_EINVAL, "row %d is all zero (the chain cannot leave state %d)",
                               r + 1, r + 1);
            }
            for (int k = 0; k < n; k++)
                out->P[(size_t)r * n + k] = 0;
            continue;
        }
        if (!(fabs(sum - 1) <= IFS_SUM_TOL) && !(flags & RIFS_NORMALISE)) {
            char item[96];
            row_name(name, sizeof name, order, n, r);
            snprintf(item, sizeof item, "row %s sums to %.10g", name, sum);
            msg_append(bad, sizeof bad, item);
            nbad++;
        }
        for (int k = 0; k < n; k++)
            out->P[(size_t)r * n + k] = P[(size_t)r * n + k] / sum;
    }
    if (nbad) {
        rt_free(used);
        rifs_free(out);
        return rt_fail(e, RT_EINVAL, "%s (each row must sum to 1%s)", bad,
                       order == 2 ? ", or be all zero for an unused pair" : "");
    }
    out->n = n;
    out->order = order;
    out->rows = rows;
    rc = order == 1 ? check_irreducible1(out, e) : check_irreducible2(out, used, e);
    if (!rc && !(maxc < 1) && !(flags & RIFS_ALLOW_EXPANDING))
        rc = rt_fail(e, RT_EINVAL, "%s", warn);
    if (!rc) {
        out->maps = copy_maps(maps, n);
        out->row = rt_calloc((size_t)rows, sizeof *out->row);
        if (!out->maps || !out->row)
            rc = rt_fail(e, RT_ENOMEM, "out of memory for a RIFS");
    }
    for (int r = 0; !rc && r < rows; r++)
        if (used[r])
            rc = ifs_alias_build(&out->row[r], out->P + (size_t)r * n, n, e);
    rt_free(used);
    if (rc) {
        rifs_free(out);
        return rc;
    }
    out->dim = dim;
    out->max_contraction = maxc;
    out->worst_map = worst;
    memcpy(out->warning, warn, sizeof out->warning);
    return RT_OK;
}

rt_code rifs_stationary(const rifs *r, double *pi, rt_error *e)
{
    int n = r->n, S = r->rows;
    double *a = rt_malloc(sizeof *a * (size_t)S), *b = rt_malloc(sizeof *b * (size_t)S);
    if (!a || !b) {
        rt_free(a);
        rt_free(b);
        return rt_fail(e, RT_ENOMEM, "out of memory for a stationary distribution");
    }
    for (int s = 0; s < S; s++)
        a[s] = 0;
    a[r->start] = 1;
    /* power iteration on the lazy chain (P + I)/2: same stationary
     * distribution, no periodicity */
    for (int it = 0; it < 100000; it++) {
        for (int s = 0; s < S; s++)
            b[s] = 0.5 * a[s];
        for (int s = 0; s < S; s++) {
            if (a[s] == 0)
                continue;
            for (int k = 0; k < n; k++) {
                int t = r->order == 1 ? k : (s % n) * n + k;
                b[t] += 0.5 * a[s] * r->P[(size_t)s * n + k];
            }
        }
        double d = 0;
        for (int s = 0; s < S; s++) {
            d += fabs(b[s] - a[s]);
            a[s] = b[s];
        }
        if (d < 1e-15)
            break;
    }
    for (int k = 0; k < n; k++)
        pi[k] = 0;
    for (int s = 0; s < S; s++)
        pi[s % n] += a[s];
    rt_free(a);
    rt_free(b);
    return RT_OK;
}
