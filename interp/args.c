/* args.c — argument helpers shared by the bindings, so every builtin reads
 * seeds, sizes, number lists and file paths the same way and reports the
 * same messages. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "builtin.h"

int arg_seed(interp *I, value v, uint64_t *seed, const char *what)
{
    if (v.k == V_NIL) {
        *seed = I->seed;
        return 0;
    }
    if (v.k != V_NUM || !(v.u.n >= 0) || v.u.n != floor(v.u.n) || v.u.n > 9007199254740992.0)
        return err_at(I, NULL, ERR_VALUE, "%s%sseed must be a whole number >= 0, got %g", what ? what : "",
                      what ? ": " : "", v.k == V_NUM ? v.u.n : NAN);
    *seed = (uint64_t)v.u.n;
    return 0;
}

int arg_size2(interp *I, value v, int *w, int *h, const char *what)
{
    double s[2];
    if (v.k == V_NUM)
        s[0] = s[1] = v.u.n;
    else if (get_vec(I, v, s, 2, what))
        return -1;
    if (s[0] != floor(s[0]) || s[1] != floor(s[1]) || s[0] < 1 || s[1] < 1 || s[0] > 1e6 || s[1] > 1e6)
        return err_at(I, NULL, ERR_VALUE, "%s must be whole numbers of pixels between 1 and 1000000, got [%g, %g]",
                      what, s[0], s[1]);
    *w = (int)s[0];
    *h = (int)s[1];
    return 0;
}

int num_list_value(interp *I, const double *x, size_t n, value *out)
{
    value l = val_list(I, n);
    if (l.k == V_NIL)
        return -1;
    for (size_t i = 0; i < n; i++)
        if (list_push(I, AS_LIST(l), val_num(x[i]))) {
            val_unref(I, l);
            return -1;
        }
    *out = l;
    return 0;
}

void script_relative_path(interp *I, const char *p, char *buf, size_t n)
{
    const char *dir = I->cur && I->cur->src >= 0 ? I->srcs[I->cur->src].dir : ".";
    if (p[0] == '/' || strcmp(dir, ".") == 0)
        snprintf(buf, n, "%s", p);
    else
        snprintf(buf, n, "%s/%s", dir, p);
}
