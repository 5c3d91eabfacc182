/* ist.c — Iterated Shuffle Transformation: the list construction of seed 002
 * §4.1 and its O(K) closed form for equal lengths and one M (SEEDS.md 002).
 * The readings where the paper is silent are documented in ist.h. */
#include "ist.h"
#include "rt_alloc.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rng.h"

static int imod(long a, int n)
{
    long r = a % n;
    return (int)(r < 0 ? r + n : r);
}

/* ---- validation and set-up ---------------------------------------------- */

static rt_code validate(const ist_spec *s, rt_error *e)
{
    if (s->n < 1)
        return rt_fail(e, RT_EINVAL, "IST needs at least 1 base interval, got %d", s->n);
    if (s->k < 0 || s->k > IST_MAX_K)
        return rt_fail(e, RT_EINVAL, "IST iterations K = %d; expected 0..%d", s->k, IST_MAX_K);
    if (s->axis != IST_TRANSLATION && s->axis != IST_CYCLIC)
        return rt_fail(e, RT_EINVAL, "IST axis type %d; expected translation (0) or cyclic (1)",
                       (int)s->axis);
    if (s->bounds) {
        for (int i = 0; i <= s->n; i++)
            if (!isfinite(s->bounds[i]))
                return rt_fail(e, RT_EINVAL, "IST bound %d is %g; expected a finite number", i,
                               s->bounds[i]);
        for (int i = 0; i < s->n; i++)
            if (!(s->bounds[i + 1] > s->bounds[i]))
                return rt_fail(e, RT_EINVAL,
                               "IST bounds must increase: bound %d = %g is not greater than bound %d = %g",
                               i + 1, s->bounds[i + 1], i, s->bounds[i]);
    }
    for (int i = 0; i < s->n; i++) {
        int m = s->m_each ? s->m_each[i] : s->m;
        if (m < 0 || m > 1000)
            return rt_fail(e, RT_EINVAL, "IST crossing count M of interval %d is %d; expected 0..1000",
                           i, m);
    }
    /* on a cyclic axis the 2M+1 pieces of an interval must go to 2M+1
     * different intervals (ist.h) */
    if (s->axis == IST_CYCLIC)
        for (int i = 0; i < s->n; i++) {
            int m = s->m_each ? s->m_each[i] : s->m;
            if (2 * m + 1 > s->n) {
                if (s->m_each)
                    return rt_fail(e, RT_EINVAL,
                                   "IST on a cyclic axis needs 2M+1 <= N, but interval %d has M = %d with N = %d (its pieces would wrap onto one interval twice)",
                                   i, m, s->n);
                return rt_fail(e, RT_EINVAL,
                               "IST on a cyclic axis needs 2M+1 <= N, got M = %d with N = %d (the pieces would wrap onto one interval twice)",
                               m, s->n);
            }
        }
    return RT_OK;
}

/* Largest |coordinate| of the axis and one ulp there. */
static double axis_ulp(const ist_spec *s, double *big)
{
    double a = s->bounds ? s->bounds[0] : 0, b = s->bounds ? s->bounds[s->n] : (double)s->n;
    double x = fmax(fabs(a), fabs(b));
    *big = x;
    return nextafter(x, INFINITY) - x;
}

int ist_k_limit(const ist_spec *s)
{
    int mmax = 0;
    double hmin = INFINITY, big;
    for (int i = 0; i < s->n; i++) {
        int m = s->m_each ? s->m_each[i] : s->m;
        mmax = m > mmax ? m : mmax;
        double h = s->bounds ? s->bounds[i + 1] - s->bounds[i] : 1.0;
        hmin = h < hmin ? h : hmin;
    }
    if (mmax == 0 || s->n < 1)
        return IST_MAX_K;
    double floor_w = IST_MIN_ULPS * axis_ulp(s, &big), w = hmin;
    int k = 0;
    while (k < IST_MAX_K && w / (2 * mmax + 1) >= floor_w) {
        w /= 2 * mmax + 1;
        k++;
    }
    return k;
}

/* Sub-intervals narrower than IST_MIN_ULPS ulps cannot be told apart in
 * double precision, so F^{-1} would stop being one-to-one (ist.h). */
static rt_code check_width(const ist_spec *s, double w, rt_error *e)
{
    double big, ulp = axis_ulp(s, &big);
    if (w >= IST_MIN_ULPS * ulp)
        return RT_OK;
    return rt_fail(e, RT_EINVAL,
                   "IST iterations K = %d make sub-intervals %.3g wide, under %d ulps (%.3g) of coordinates up to %g, so double precision cannot keep F one-to-one; at most K = %d for this axis",
                   s->k, w, IST_MIN_ULPS, IST_MIN_ULPS * ulp, big, ist_k_limit(s));
}

/* B^K if it is at most 2^52 (so sub-interval indices are exact in a double),
 * else 0. */
static uint64_t pow_small(int b, int k)
{
    uint64_t s = 1;
    for (int i = 0; i < k; i++) {
        if (s > ((uint64_t)1 << 52) / (uint64_t)b)
            return 0;
        s *= (uint64_t)b;
    }
    return s;
}

static void ist_zero(ist *t) { memset(t, 0, sizeof *t); }

static void fast_init(ist *t);


void ist_free(ist *t)
{
    rt_free(t->bounds);
    rt_free(t->ms);
    rt_free(t->start);
    rt_free(t->x);
    rt_free(t->len);
    rt_free(t->cum);
    rt_free(t->total);
    rt_free(t->label);
    rt_free(t->slot);
    rt_free(t->owner);
    rt_free(t->by_x);
    rt_free(t->ftab);
    ist_zero(t);
}

rt_code ist_init(ist *t, const ist_spec *s, rt_error *e)
{
    ist_zero(t);
    rt_code rc = validate(s, e);
    if (rc)
        return rc;
    t->n = s->n;
    t->k = s->k;
    t->axis = s->axis;
    t->bounds = rt_malloc(sizeof(double) * (size_t)(s->n + 1));
    t->ms = rt_malloc(sizeof(int) * (size_t)s->n);
    if (!t->bounds || !t->ms) {
        ist_free(t);
        return rt_fail(e, RT_ENOMEM, "out of memory for an IST of %d intervals", s->n);
    }
    for (int i = 0; i <= s->n; i++)
        t->bounds[i] = s->bounds ? s->bounds[i] : (double)i;
    int one_m = 1;
    for (int i = 0; i < s->n; i++) {
        t->ms[i] = s->m_each ? s->m_each[i] : s->m;
        if (t->ms[i] != t->ms[0])
            one_m = 0;
    }
    /* equal lengths: a_i = a_0 + i·h exactly */
    double a0 = t->bounds[0], h = t->bounds[1] - t->bounds[0];
    int equal = 1;
    for (int i = 0; i <= s->n; i++)
        if (t->bounds[i] != a0 + (double)i * h)
            equal = 0;
    if (one_m && equal && t->ms[0] > 0) { /* every sub-interval is h/B^K wide */
        rc = check_width(s, h / pow(2 * t->ms[0] + 1, s->k), e);
        if (rc) {
            ist_free(t);
            return rc;
        }
    }
    uint64_t sk = pow_small(2 * t->ms[0] + 1, s->k);
    int can_close = one_m && equal && sk != 0;
    if ((s->method == IST_CLOSED || s->method == IST_CLOSED_DIGITS) && !can_close) {
        ist_free(t);
        return rt_fail(e, RT_EINVAL,
                       "IST closed form needs equal base intervals, one crossing count and (2M+1)^K <= 2^52");
    }
    if (can_close && s->method != IST_LISTS) {
        t->closed = 1;
        t->m = t->ms[0];
        t->b = 2 * t->m + 1;
        t->s = sk;
        t->a0 = a0;
        t->h = h;
        if (s->method != IST_CLOSED_DIGITS)
            fast_init(t);
        return RT_OK;
    }
    rc = ist_build_lists(t, e);
    if (!rc && !(one_m && equal)) { /* the narrowest source piece and destination slot */
        double w = INFINITY;
        for (int i = 0; i < t->n; i++)
            for (size_t r = t->start[i]; r < t->start[i + 1]; r++) {
                double d = t->len[r] * ((t->bounds[i + 1] - t->bounds[i]) / t->total[i]);
                w = fmin(w, fmin(t->len[r], d));
            }
        rc = check_width(s, w, e);
    }
    if (rc)
        ist_free(t);
    return rc;
}

/* ---- the list construction (§4.1) ---------------------------------------- */

/* One way a piece can arrive in a list: piece t of (every entry of) L_j goes
 * to list i with order key d; f is its share of the entry, c where it starts. */
typedef struct slotdef {
    int i, j, t;
    long d;
    double f, c;
} slotdef;

static int slot_cmp(const void *pa, const void *pb)
{
    const slotdef *a = pa, *b = pb;
    if (a->i != b->i)
        return a->i < b->i ? -1 : 1;
    if (a->d != b->d)
        return a->d < b->d ? -1 : 1;
    return (a->t > b->t) - (a->t < b->t);
}

static int target_of(const ist *t, int j, int piece, long *d)
{
    long g = (long)j - t->ms[j] + piece;
    if (t->axis == IST_CYCLIC) {
        *d = t->ms[j] - piece;
        return imod(g, t->n);
    }
    if (g < 0 || g >= t->n) { /* beyond an end: the piece stays (ist.h) */
        *d = 0;
        return j;
    }
    *d = t->ms[j] - piece;
    return (int)g;
}

/* qsort has no context argument in C11: sort (x, index) pairs instead. */
typedef struct xi {
    double x;
    size_t i;
} xi;

static int xi_cmp(const void *pa, const void *pb)
{
    const xi *a = pa, *b = pb;
    if (a->x != b->x)
        return (a->x > b->x) - (a->x < b->x);
    return (a->i > b->i) - (a->i < b->i);
}

rt_code ist_build_lists(ist *t, rt_error *e)
{
    if (t->x)
        return RT_OK;
    int n = t->n;
    size_t nslot = 0;
    for (int j = 0; j < n; j++)
        nslot += (size_t)(2 * t->ms[j] + 1);
    slotdef *sl = rt_malloc(sizeof *sl * nslot);
    size_t *sstart = rt_malloc(sizeof(size_t) * (size_t)(n + 1));
    size_t *cnt = rt_calloc((size_t)n, sizeof(size_t)), *cnt2 = rt_calloc((size_t)n, sizeof(size_t));
    double *x0 = NULL, *l0 = NULL, *x1 = NULL, *l1 = NULL;
    uint64_t *b0 = NULL, *b1 = NULL;
    uint32_t *s1 = NULL, *o1 = NULL;
    size_t *st0 = rt_malloc(sizeof(size_t) * (size_t)(n + 1)), *st1 = rt_malloc(sizeof(size_t) * (size_t)(n + 1));
    rt_code rc = RT_OK;
    if (!sl || !sstart || !cnt || !cnt2 || !st0 || !st1) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory building IST lists");
        goto done;
    }
    /* the pieces of one round: shares in proportion to the target lengths */
    size_t q = 0;
    for (int j = 0; j < n; j++) {
        int np = 2 * t->ms[j] + 1;
        double w = 0;
        for (int p = 0; p < np; p++) {
            long d;
            int i = target_of(t, j, p, &d);
            w += t->bounds[i + 1] - t->bounds[i];
        }
        double c = 0;
        for (int p = 0; p < np; p++) {
            long d;
            int i = target_of(t, j, p, &d);
            double f = (t->bounds[i + 1] - t->bounds[i]) / w;
            sl[q++] = (slotdef){i, j, p, d, f, c};
            c += f;
        }
    }
    qsort(sl, nslot, sizeof *sl, slot_cmp);
    for (int i = 0, s = 0; i <= n; i++) {
        while ((size_t)s < nslot && sl[s].i < i)
            s++;
        sstart[i] = (size_t)s;
    }
    /* entry counts per list, refusing before anything large is allocated */
    for (int i = 0; i < n; i++)
        cnt[i] = 1;
    for (int k = 1; k <= t->k; k++) {
        size_t tot = 0;
        for (int i = 0; i < n; i++) {
            size_t c = 0;
            for (size_t s = sstart[i]; s < sstart[i + 1]; s++)
                c += cnt[sl[s].j];
            cnt2[i] = c;
            tot += c;
            if (c > IST_MAX_ENTRIES || tot > IST_MAX_ENTRIES) {
                rc = rt_fail(e, RT_EINVAL,
                             "IST lists would hold more than %zu small intervals at round %d of K = %d; "
                             "lower K",
                             IST_MAX_ENTRIES, k, t->k);
                goto done;
            }
        }
        memcpy(cnt, cnt2, sizeof(size_t) * (size_t)n);
    }
    size_t ne = 0;
    for (int i = 0; i < n; i++)
        ne += cnt[i];
    int want_label = t->k <= 9;
    for (int i = 0; i < n; i++)
        if (t->ms[i] > 31)
            want_label = 0;
    x0 = rt_malloc(sizeof(double) * ne);
    l0 = rt_malloc(sizeof(double) * ne);
    x1 = rt_malloc(sizeof(double) * ne);
    l1 = rt_malloc(sizeof(double) * ne);
    b0 = rt_calloc(ne, sizeof(uint64_t));
    b1 = rt_calloc(ne, sizeof(uint64_t));
    s1 = rt_calloc(ne, sizeof(uint32_t));
    o1 = rt_calloc(ne, sizeof(uint32_t));
    if (!x0 || !l0 || !x1 || !l1 || !b0 || !b1 || !s1 || !o1) {
        rc = rt_fail(e, RT_ENOMEM, "out of memory for %zu IST list entries", ne);
        goto done;
    }
    /* L_i^0 = {A_i} */
    for (int i = 0; i < n; i++) {
        st0[i] = (size_t)i;
        x0[i] = t->bounds[i];
        l0[i] = t->bounds[i + 1] - t->bounds[i];
        o1[i] = (uint32_t)i;
    }
    st0[n] = (size_t)n;
    for (int k = 1; k <= t->k; k++) {
        size_t w = 0;
        for (int i = 0; i < n; i++) {
            st1[i] = w;
            for (size_t s = sstart[i]; s < sstart[i + 1]; s++) {
                const slotdef *d = &sl[s];
                for (size_t r = st0[d->j]; r < st0[d->j + 1]; r++) {
                    x1[w] = x0[r] + l0[r] * d->c;
                    l1[w] = l0[r] * d->f;
                    b1[w] = (b0[r] << 6) | (uint64_t)d->t;
                    s1[w] = (uint32_t)(s - sstart[i]);
                    o1[w] = (uint32_t)i;
                    w++;
                }
            }
        }
        st1[n] = w;
        double *tx = x0; x0 = x1; x1 = tx;
        double *tl = l0; l0 = l1; l1 = tl;
        uint64_t *tb = b0; b0 = b1; b1 = tb;
        size_t *ts = st0; st0 = st1; st1 = ts;
    }
    /* keep the final level */
    t->ne = st0[n];
    t->start = st0;
    st0 = NULL;
    t->x = x0;
    t->len = l0;
    x0 = l0 = NULL;
    t->label = want_label ? b0 : NULL;
    if (want_label)
        b0 = NULL;
    t->slot = s1;
    t->owner = o1;
    s1 = NULL;
    o1 = NULL;
    t->cum = rt_malloc(sizeof(double) * (t->ne ? t->ne : 1));
    t->total = rt_malloc(sizeof(double) * (size_t)n);
    t->by_x = rt_malloc(sizeof(size_t) * (t->ne ? t->ne : 1));
    xi *tmp = rt_malloc(sizeof(xi) * (t->ne ? t->ne : 1));
    if (!t->cum || !t->total || !t->by_x || !tmp) {
        rt_free(tmp);
        rc = rt_fail(e, RT_ENOMEM, "out of memory for %zu IST list entries", t->ne);
        goto done;
    }
    if (t->k == 0) /* the round loop never ran: slots and owners are trivial */
        for (int i = 0; i < n; i++)
            t->owner[i] = (uint32_t)i, t->slot[i] = 0;
    for (int i = 0; i < n; i++) {
        double c = 0;
        for (size_t r = t->start[i]; r < t->start[i + 1]; r++) {
            t->cum[r] = c;
            c += t->len[r];
        }
        t->total[i] = c;
    }
    for (size_t r = 0; r < t->ne; r++)
        tmp[r] = (xi){t->x[r], r};
    qsort(tmp, t->ne, sizeof *tmp, xi_cmp);
    for (size_t r = 0; r < t->ne; r++)
        t->by_x[r] = tmp[r].i;
    rt_free(tmp);
done:
    rt_free(sl);
    rt_free(sstart);
    rt_free(cnt);
    rt_free(cnt2);
    rt_free(x0);
    rt_free(l0);
    rt_free(x1);
    rt_free(l1);
    rt_free(b0);
    rt_free(b1);
    rt_free(s1);
    rt_free(o1);
    rt_free(st0);
    rt_free(st1);
    if (rc && t->x) { /* undo a partial final level, keep the spec */
        rt_free(t->start); rt_free(t->x); rt_free(t->len); rt_free(t->cum); rt_free(t->total);
        rt_free(t->label); rt_free(t->slot); rt_free(t->owner); rt_free(t->by_x);
        t->start = NULL; t->x = t->len = t->cum = t->total = NULL;
        t->label = NULL; t->slot = t->owner = NULL; t->by_x = NULL; t->ne = 0;
    }
    return rc;
}

/* ---- evaluation ------------------------------------------------------------ */

/* Bring u into [a, b) on a cyclic axis; *shift is what was subtracted. */
static int locate(const ist *t, double u, double *uw, double *shift)
{
    double a = t->bounds[0], b = t->bounds[t->n];
    *shift = 0;
    if (t->axis == IST_CYCLIC) {
        double p = b - a;
        if (u < a || u >= b) {
            double q = floor((u - a) / p);
            *shift = q * p;
            u -= *shift;
            if (u >= b)
                u = a; /* rounding put it on the far end: the same point */
            if (u < a)
                u = a;
        }
    } else if (!(u >= a && u < b)) {
        return -1; /* identity outside a translation axis (and NaN) */
    }
    *uw = u;
    return 0;
}

static int find_interval(const ist *t, double u)
{
    if (t->closed) {
        int i = (int)floor((u - t->a0) / t->h);
        return i < 0 ? 0 : i >= t->n ? t->n - 1 : i;
    }
    int lo = 0, hi = t->n - 1; /* last i with bounds[i] <= u */
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (t->bounds[mid] <= u)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

/* Slot p of interval i on a translation axis with one M (the sorted slot
 * list of ist_build_lists, in closed form): sets the next interval and the
 * piece index. Order: left neighbours, own pieces held back at the left end,
 * the own centre piece, own pieces held back at the right end, right
 * neighbours. */
static inline void slot_translation(int n, int m, int i, int p, int *j, int *piece)
{
    int l = i < m ? i : m, r = n - 1 - i < m ? n - 1 - i : m;
    if (p < l) {
        int d = p - l;
        *j = i + d;
        *piece = m - d;
    } else if (p < m) {
        *j = i;
        *piece = p - l;
    } else if (p == m) {
        *j = i;
        *piece = m;
    } else {
        int q = p - m - 1;
        if (q < m - r) {
            *j = i;
            *piece = n - i + m + q;
        } else {
            int d = q - (m - r) + 1;
            *j = i + d;
            *piece = m - d;
        }
    }
}

/* The inverse of slot_translation: piece `piece` of interval j lands in
 * interval *i at slot *p. */
static inline void unslot_translation(int n, int m, int j, int piece, int *i, int *p)
{
    int g = j - m + piece;
    if (g < 0 || g >= n) {
        *i = j;
        int l = j < m ? j : m;
        *p = piece < m ? l + piece : m + 1 + (piece - (n - j + m));
        return;
    }
    *i = g;
    int l = g < m ? g : m, r = n - 1 - g < m ? n - 1 - g : m;
    int d = j - g;
    if (d < 0)
        *p = d + l;
    else if (d == 0)
        *p = m;
    else
        *p = 2 * m - r + d;
}

/* r in [0, 1), an offset in units of h, as one of the t->s slots of an
 * interval (the slot number) and the remainder within that slot, in slots */
static inline uint64_t slot_of(const ist *t, double r, double *rem)
{
    double y = r * (double)t->s;
    uint64_t idx = (uint64_t)y;
    if (idx >= t->s)
        idx = t->s - 1;
    *rem = y - (double)idx;
    return idx;
}

static double inv_closed(const ist *t, int i, double r)
{
    double rem;
    uint64_t idx = slot_of(t, r, &rem);
    uint64_t b = (uint64_t)t->b, src = 0;
    int j;
    /* away from the ends of a translation axis (K·M intervals) the slots are
     * those of a cyclic axis and no wrap happens */
    int interior = t->axis == IST_CYCLIC ||
                   ((long)i >= (long)t->k * t->m && (long)i + (long)t->k * t->m <= (long)t->n - 1);
    if (interior && t->s <= UINT32_MAX) { /* 32-bit division is much cheaper */
        uint32_t id32 = (uint32_t)idx, b32 = (uint32_t)t->b, s32 = 0, m2 = (uint32_t)(2 * t->m);
        long sumd = 0;
        for (int q = 0; q < t->k; q++) {
            uint32_t p = id32 % b32;
            id32 /= b32;
            sumd += (long)p;
            s32 = s32 * b32 + m2 - p;
        }
        sumd -= (long)t->k * t->m;
        j = t->axis == IST_CYCLIC ? imod((long)i + sumd, t->n) : (int)((long)i + sumd);
        src = s32;
    } else if (interior) {
        long sumd = 0;
        for (int q = 0; q < t->k; q++) { /* digits p_K, p_{K-1}, …, p_1 */
            uint64_t p = idx % b;
            idx /= b;
            sumd += (long)p - t->m;
            src = src * b + (uint64_t)(2 * t->m) - p; /* t_m = 2M - p_m */
        }
        j = imod((long)i + sumd, t->n);
    } else {
        int dig[IST_MAX_K];
        for (int q = t->k - 1; q >= 0; q--) {
            dig[q] = (int)(idx % b);
            idx /= b;
        }
        int pc[IST_MAX_K];
        j = i;
        for (int q = 0; q < t->k; q++)
            slot_translation(t->n, t->m, j, dig[q], &j, &pc[q]);
        for (int q = t->k - 1; q >= 0; q--) /* source digits t_K … t_1 */
            src = src * b + (uint64_t)pc[q];
    }
    return t->a0 + (double)j * t->h + t->h * (((double)src + rem) / (double)t->s);
}

static double fwd_closed(const ist *t, int j, double r)
{
    double rem;
    uint64_t idx = slot_of(t, r, &rem);
    uint64_t b = (uint64_t)t->b;
    int dig[IST_MAX_K]; /* source digits s_1..s_K = t_K..t_1 */
    for (int q = t->k - 1; q >= 0; q--) {
        dig[q] = (int)(idx % b);
        idx /= b;
    }
    uint64_t dst = 0, pw = 1;
    int i = j;
    for (int q = 0; q < t->k; q++) { /* t_K first: gives p_K, the last digit */
        int p;
        if (t->axis == IST_CYCLIC) {
            i = imod((long)i - (t->m - dig[q]), t->n);
            p = 2 * t->m - dig[q];
        } else {
            unslot_translation(t->n, t->m, i, dig[q], &i, &p);
        }
        dst += (uint64_t)p * pw;
        pw *= b;
    }
    return t->a0 + (double)i * t->h + t->h * (((double)dst + rem) / (double)t->s);
}

/* Digit-group tables of the fast path (ist.h). The per-digit loop of
 * inv_closed takes the digits p of idx least significant first and
 * accumulates src = src·B + (2M - p) and Σ p; over a group of g digits
 * that is src = src·B^g + rc(group) with rc the digit-reversed complement,
 * so the integers, and hence the doubles, are the same. Without memory the
 * slow path stays in use. */
static void fill_groups(uint32_t *tab, uint32_t b, int d)
{
    uint32_t nv = 1;
    for (int q = 0; q < d; q++)
        nv *= b;
    for (uint32_t v = 0; v < nv; v++) {
        uint32_t x = v, rc = 0, sum = 0;
        for (int q = 0; q < d; q++) {
            uint32_t p = x % b;
            x /= b;
            sum += p;
            rc = rc * b + (b - 1 - p);
        }
        tab[v] = rc | sum << 16; /* rc < B^g <= 4096, sum < B^g */
    }
}

/* For the ends of a translation axis: the partial sums of p - M over the
 * digits of a group, most significant first, and their least and greatest
 * value over the prefixes of length 0 .. d-1 (int8 each; |values| <= d·M
 * <= 21 for B <= 15). */
static void fill_prefix(uint32_t *tab, uint32_t b, int d)
{
    uint32_t nv = 1;
    for (int q = 0; q < d; q++)
        nv *= b;
    int m = (int)(b - 1) / 2;
    for (uint32_t v = 0; v < nv; v++) {
        int dig[32], mn = 0, mx = 0, sum = 0;
        uint32_t x = v;
        for (int q = 0; q < d; q++) {
            dig[q] = (int)(x % b);
            x /= b;
        }
        for (int q = d - 1; q >= 0; q--) {
            mn = sum < mn ? sum : mn;
            mx = sum > mx ? sum : mx;
            sum += dig[q] - m;
        }
        tab[v] = (uint32_t)(uint8_t)(int8_t)mn | (uint32_t)(uint8_t)(int8_t)mx << 8 |
                 (uint32_t)(uint8_t)(int8_t)sum << 16;
    }
}

static void fast_init(ist *t)
{
    if (t->b < 3 || t->k < 1 || t->s > UINT32_MAX)
        return;
    uint32_t b = (uint32_t)t->b, bg = b; /* b <= 2001 */
    int g = 1;
    while (g < t->k && bg <= 4096 / b) {
        bg *= b;
        g++;
    }
    int r = t->k % g, topd = r ? r : g;
    uint32_t btop = 1;
    for (int q = 0; q < topd; q++)
        btop *= b;
    int dig = t->axis == IST_TRANSLATION && b <= 15;
    size_t ne = (size_t)bg + (r ? btop : 0) + (dig ? 2 * (size_t)bg + (r ? btop : 0) : 0);
    uint32_t *tab = rt_malloc(sizeof(uint32_t) * ne);
    if (!tab)
        return;
    fill_groups(tab, b, g);
    t->ftop = tab;
    if (r) {
        t->ftop = tab + bg;
        fill_groups(t->ftop, b, r);
    }
    t->fdig = NULL;
    if (dig) {
        t->fdig = tab + bg + (r ? btop : 0);
        for (uint32_t v = 0; v < bg; v++) {
            uint32_t x = v, pk = 0;
            for (int q = 0; q < g; q++) {
                pk |= (x % b) << (4 * q);
                x /= b;
            }
            t->fdig[v] = pk;
        }
        t->fpre = t->fdig + bg;
        t->fpretop = t->fpre;
        fill_prefix(t->fpre, b, g);
        if (r) {
            t->fpretop = t->fpre + bg;
            fill_prefix(t->fpretop, b, r);
        }
    }
    t->ftab = tab;
    t->fg = g;
    t->ftopd = topd;
    t->fdiv = (t->k - topd) / g;
    t->fbg = bg;
    t->fmul = (uint32_t)((((uint64_t)1) << 32) / bg);
    t->fbtop = btop;
    /* x/h and x·(1/h) are the same correctly rounded number when 1/h is an
     * exact power of two */
    int ex;
    double mant = frexp(t->h, &ex), ih = 1.0 / t->h;
    t->fh2 = mant == 0.5 && isnormal(ih) && ih * t->h == 1.0;
    t->fih = ih;
}

/* x = q·B^g + lo with the reciprocal of B^g: the estimate is q or q - 1
 * (x·floor(2^32/B^g)/2^32 > x/B^g - 1), and one step corrects it. */
static inline uint32_t split_group(const ist *t, uint32_t x, uint32_t *lo)
{
    uint32_t q = (uint32_t)(((uint64_t)x * t->fmul) >> 32);
    uint32_t l = x - q * t->fbg;
    if (l >= t->fbg) {
        q++;
        l -= t->fbg;
    }
    *lo = l;
    return q;
}

/* ist_inv for a closed form with tables: the same floating-point operations
 * as ist_inv/inv_closed in the same order, integer digit work grouped. */
static inline double inv_fast(const ist *t, double u)
{
    double uw, shift;
    if (locate(t, u, &uw, &shift))
        return u;
    int n = t->n;
    double v = t->fh2 ? (uw - t->a0) * t->fih : (uw - t->a0) / t->h;
    /* (int)floor(v) clamped to [0, n-1]; v >= 0 unless NaN */
    int i = v >= 0 ? (v < (double)n ? (int)v : n - 1) : 0;
    double a = t->a0 + (double)i * t->h;
    double r = t->fh2 ? (uw - a) * t->fih : (uw - a) / t->h;
    if (r < 0)
        r = 0;
    double y = r * (double)t->s;
    uint32_t x = y < (double)t->s ? (uint32_t)y : (uint32_t)(t->s - 1);
    double rem = y - (double)x;
    long km = (long)t->k * t->m;
    uint32_t src = 0;
    int j;
    if (t->axis == IST_CYCLIC || ((long)i >= km && (long)i + km <= (long)n - 1)) {
        uint32_t sum = 0, lo, e;
        for (int q = 0; q < t->fdiv; q++) {
            x = split_group(t, x, &lo);
            e = t->ftab[lo];
            src = src * t->fbg + (e & 0xffff);
            sum += e >> 16;
        }
        e = t->ftop[x];
        src = src * t->fbtop + (e & 0xffff);
        sum += e >> 16;
        long jj = (long)i + (long)sum - km;
        if (jj < 0 || jj >= n) /* only on a cyclic axis */
            jj = imod(jj, n);
        j = (int)jj;
    } else if (t->fdig) {
        /* near an end of a translation axis: the same group sums, plus the
         * range of intervals the slot walk visits (prefix sums composed
         * from the least significant group up); if it keeps M away from
         * both ends every step is a cyclic one and j = i + Σ(p - M). */
        uint32_t grp[IST_MAX_K], sum = 0, e, pe;
        for (int q = 0; q < t->fdiv; q++) {
            x = split_group(t, x, &grp[q]);
            e = t->ftab[grp[q]];
            src = src * t->fbg + (e & 0xffff);
            sum += e >> 16;
        }
        e = t->ftop[x];
        src = src * t->fbtop + (e & 0xffff);
        sum += e >> 16;
        int mn = 1 << 20, mx = -(1 << 20); /* no prefix yet: the final j is not constrained */
        for (int q = 0; q <= t->fdiv; q++) {
            pe = q < t->fdiv ? t->fpre[grp[q]] : t->fpretop[x];
            int gmn = (int8_t)(uint8_t)pe, gmx = (int8_t)(uint8_t)(pe >> 8), gs = (int8_t)(uint8_t)(pe >> 16);
            mn = gs + mn < gmn ? gs + mn : gmn;
            mx = gs + mx > gmx ? gs + mx : gmx;
        }
        if (i + mn >= t->m && i + mx <= n - 1 - t->m) {
            j = (int)((long)i + (long)sum - km);
        } else { /* the slot walk of inv_closed, digits most significant first */
            uint32_t pw = 1, b = (uint32_t)t->b;
            src = 0;
            j = i;
            for (int q = t->fdiv; q >= 0; q--) {
                uint32_t pk = t->fdig[q == t->fdiv ? x : grp[q]];
                for (int d = (q == t->fdiv ? t->ftopd : t->fg) - 1; d >= 0; d--) {
                    int pc;
                    slot_translation(n, t->m, j, (int)(pk >> (4 * d) & 15), &j, &pc);
                    src += (uint32_t)pc * pw;
                    pw *= b;
                }
            }
        }
    } else {
        return inv_closed(t, i, r) + shift;
    }
    return t->a0 + (double)j * t->h + t->h * (((double)src + rem) / (double)t->s) + shift;
}

void ist_inv_block(const ist *t, size_t n, const double *u, double *out)
{
    if (t->ftab) {
        for (size_t q = 0; q < n; q++)
            out[q] = inv_fast(t, u[q]);
    } else {
        for (size_t q = 0; q < n; q++)
            out[q] = ist_inv(t, u[q]);
    }
}

double ist_inv(const ist *t, double u)
{
    if (t->ftab)
        return inv_fast(t, u);
    double uw, shift;
    if (locate(t, u, &uw, &shift))
        return u;
    int i = find_interval(t, uw);
    if (t->closed) {
        double r = (uw - (t->a0 + (double)i * t->h)) / t->h;
        if (r < 0)
            r = 0;
        return inv_closed(t, i, r) + shift;
    }
    double a = t->bounds[i], w = t->bounds[i + 1] - a;
    double pos = (uw - a) / w * t->total[i];
    size_t lo = t->start[i], hi = t->start[i + 1] - 1; /* last entry with cum <= pos */
    while (lo < hi) {
        size_t mid = lo + (hi - lo + 1) / 2;
        if (t->cum[mid] <= pos)
            lo = mid;
        else
            hi = mid - 1;
    }
    double off = pos - t->cum[lo];
    if (off < 0)
        off = 0;
    return t->x[lo] + off + shift;
}

double ist_fwd(const ist *t, double u)
{
    double uw, shift;
    if (locate(t, u, &uw, &shift))
        return u;
    if (t->closed) {
        int j = find_interval(t, uw);
        double r = (uw - (t->a0 + (double)j * t->h)) / t->h;
        if (r < 0)
            r = 0;
        return fwd_closed(t, j, r) + shift;
    }
    size_t lo = 0, hi = t->ne - 1; /* last entry (by source) starting at or before uw */
    while (lo < hi) {
        size_t mid = lo + (hi - lo + 1) / 2;
        if (t->x[t->by_x[mid]] <= uw)
            lo = mid;
        else
            hi = mid - 1;
    }
    size_t r = t->by_x[lo];
    int i = (int)t->owner[r];
    double a = t->bounds[i], w = t->bounds[i + 1] - a;
    double off = uw - t->x[r];
    if (off < 0)
        off = 0;
    return a + (t->cum[r] + off) * (w / t->total[i]) + shift;
}

/* ---- printing (Fig. 2 notation) ------------------------------------------- */

rt_code ist_print(ist *t, bytebuf *out, rt_error *e)
{
    if (t->k > 9)
        return rt_fail(e, RT_EINVAL, "IST printing needs K <= 9, got K = %d", t->k);
    int bmax = 0;
    for (int i = 0; i < t->n; i++) {
        if (t->ms[i] > 31)
            return rt_fail(e, RT_EINVAL, "IST printing needs M <= 31, interval %d has M = %d", i,
                           t->ms[i]);
        if (2 * t->ms[i] + 1 > bmax)
            bmax = 2 * t->ms[i] + 1;
    }
    rt_code rc = ist_build_lists(t, e);
    if (rc)
        return rc;
    int compact = t->n <= 10 && bmax <= 10;
    for (int i = 0; i < t->n; i++) {
        bytebuf_printf(out, "L%d:", i);
        for (size_t r = t->start[i]; r < t->start[i + 1]; r++) {
            if (r > t->start[i] && t->slot[r] != t->slot[r - 1])
                bytebuf_printf(out, " |");
            /* source base interval: the list the entry came from at round 0
             * is recovered from its position x */
            int j = find_interval(t, t->x[r]);
            uint64_t lab = t->label ? t->label[r] : 0;
            bytebuf_printf(out, compact ? " %d" : " %d:", j);
            for (int q = t->k - 1; q >= 0; q--) {
                int d = (int)((lab >> (6 * q)) & 63);
                if (compact)
                    bytebuf_printf(out, "%d", d);
                else
                    bytebuf_printf(out, q == t->k - 1 ? "%d" : ".%d", d);
            }
        }
        bytebuf_printf(out, "\n");
    }
    if (out->failed)
        return rt_fail(e, RT_ENOMEM, "out of memory printing IST lists");
    return RT_OK;
}

/* ---- adaptive sampling (§5.2, eq. 12-14) ---------------------------------- */

uint64_t ist_sample_index(int b, int k, int ki, uint64_t m)
{
    uint64_t step = 1;
    for (int q = ki; q < k; q++)
        step *= (uint64_t)b;
    return (step - 1) / 2 + m * step;
}

size_t ist_sample_positions(const ist *t, const int *ki, int jitter, uint64_t seed, double *out,
                            size_t cap)
{
    size_t w = 0;
    for (int i = 0; i < t->n; i++) {
        int b = 2 * t->ms[i] + 1;
        int kk = ki[i] < 0 ? 0 : ki[i] > t->k ? t->k : ki[i];
        uint64_t si = pow_small(b, kk);
        uint64_t step = pow_small(b, t->k - kk);
        if (!si || !step)
            return (size_t)-1; /* too many: the caller's K is unreasonable */
        double a = t->bounds[i], len = t->bounds[i + 1] - a;
        double sub = len / ((double)si * (double)step);
        rng r;
        rng_init(&r, seed, (uint64_t)i);
        for (uint64_t m = 0; m < si; m++, w++) {
            if (w >= cap)
                continue;
            uint64_t idx = (step - 1) / 2 + m * step;
            double c = jitter ? rng_uniform(&r) : 0.5;
            out[w] = a + ((double)idx + c) * sub;
        }
    }
    return w;
}
