/* args.c — argument helpers shared by the bindings, so every builtin reads
 * seeds, sizes, number lists and file paths the same way and reports the
 * same messages. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "builtin.h"
#include "lang_objects.h"

int lang_arg_seed(interp *I, value v, uint64_t *seed, const char *what)
{
    if (v.k == V_NIL) {
        *seed = I->seed;
        return 0;
    }
    if (v.k != V_NUM || !(v.u.n >= 0) || v.u.n != floor(v.u.n) || v.u.n > 9007199254740992.0)
        return err_value(I, v, ERR_VALUE, "%s%sseed must be a whole number >= 0, got %g", what ? what : "",
                      what ? ": " : "", v.k == V_NUM ? v.u.n : NAN);
    *seed = (uint64_t)v.u.n;
    return 0;
}

int lang_arg_size2(interp *I, value v, int *w, int *h, const char *what)
{
    double s[2];
    if (v.k == V_NUM)
        s[0] = s[1] = v.u.n;
    else if (builtin_get_vec(I, v, s, 2, what))
        return -1;
    if (s[0] != floor(s[0]) || s[1] != floor(s[1]) || s[0] < 1 || s[1] < 1 || s[0] > 1e6 || s[1] > 1e6)
        return err_value(I, v, ERR_VALUE, "%s must be whole numbers of pixels between 1 and 1000000, got [%g, %g]",
                      what, s[0], s[1]);
    *w = (int)s[0];
    *h = (int)s[1];
    return 0;
}

int lang_num_list_value(interp *I, const double *x, size_t n, value *out)
{
    value l = val_list(I, n);
    if (l.k == V_NIL)
        return -1;
    for (size_t i = 0; i < n; i++)
        if (val_list_push(I, AS_LIST(l), val_num(x[i]))) {
            val_unref(I, l);
            return -1;
        }
    *out = l;
    return 0;
}

int lang_join_path(interp *I, const node *at, const char *dir, const char *p, size_t plen, char *buf, size_t n,
                   const char *what)
{
    const char *sep = what && *what ? ": " : "";
    if (memchr(p, 0, plen))
        return err_at(I, at, ERR_VALUE, "%s%sthe file name contains a NUL byte (\\0)", what, sep);
    if (p[0] == '/' || !dir || strcmp(dir, ".") == 0)
        dir = NULL;
    size_t need = dir ? strlen(dir) + 1 + plen : plen;
    if (need >= n)
        return err_at(I, at, ERR_IO, "%s%spath too long: '%.40s…' (%zu bytes; the limit is %zu)", what, sep, p, need,
                      n - 1);
    if (dir)
        snprintf(buf, n, "%s/%.*s", dir, (int)plen, p);
    else
        snprintf(buf, n, "%.*s", (int)plen, p);
    return 0;
}

int lang_script_path(interp *I, value v, char *buf, size_t n, const char *what)
{
    const char *dir = I->cur ? I->srcs[I->cur->src].dir : ".";
    return lang_join_path(I, NULL, dir, AS_STR(v)->s, AS_STR(v)->len, buf, n, what);
}
