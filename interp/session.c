/* session.c — interpreter setup and the run-a-source entry point. */
#include "session.h"

#include <stdio.h>
#include <string.h>

#include "builtin.h"
#include "eval.h"
#include "parser.h"
#include "resolve.h"

int session_setup(interp *I)
{
    env *root = val_env_new(I, NULL);
    if (!root)
        return -1;
    I->globals = root; /* builtins register into the root */
    if (builtin_core_init(I) || builtin_image_init(I) || bind_all_init(I))
        return -1;
    /* `frame` and `clock` (--frames; 0 outside it): read-only, like the
     * builtins they sit beside (resolve.c refuses assignments to them) */
    const char *fr = interp_intern(I, "frame", 5), *ck = interp_intern(I, "clock", 5);
    if (fr && ck && (val_env_lookup(root, fr) || val_env_lookup(root, ck)))
        return err_pos(I, -1, 0, 0, ERR_RUNTIME, "internal: a builtin named '%s' would be hidden by the --frames name",
                       val_env_lookup(root, fr) ? "frame" : "clock"); /* not silently: rename the builtin */
    if (!fr || !ck || val_env_define(I, root, fr, val_num((double)I->frame)) ||
        val_env_define(I, root, ck, val_num(I->clock)))
        return -1;
    I->globals = val_env_new(I, root);
    val_heap_unref(I, &root->h); /* the global scope holds it now */
    return I->globals ? 0 : -1;
}

void session_set_frame(interp *I)
{
    env *root = I->globals ? I->globals->parent : NULL;
    value *fv = root ? val_env_lookup(root, interp_intern(I, "frame", 5)) : NULL;
    value *cv = root ? val_env_lookup(root, interp_intern(I, "clock", 5)) : NULL;
    if (fv && cv) /* numbers: nothing to release */
        *fv = val_num((double)I->frame), *cv = val_num(I->clock);
}

int session_run(interp *I, const char *name, const char *text, size_t len, int check_only, value *last)
{
    return session_run_lines(I, name, text, len, 1, check_only, last);
}

int session_run_lines(interp *I, const char *name, const char *text, size_t len, int first_line,
                      int check_only, value *last)
{
    int src = interp_add_source(I, name, text, len);
    if (src < 0)
        return -1;
    I->srcs[src].first_line = first_line;
    node *prog;
    if (parse_source(I, src, &prog))
        return -1;
    if ((check_only ? resolve_check : resolve_program)(I, prog, I->globals)) {
        err_state *e = &I->err;
        if (e->active && e->src < 0 && (e->kind == ERR_MEMORY || e->kind == ERR_LIMIT)) {
            /* the checker's tables or the slot pass were refused memory
             * where no call was at hand: say so at the script's start */
            static const char what[] = "checking the script: ";
            size_t l = strnlen(e->msg, sizeof e->msg - sizeof what);
            memmove(e->msg + sizeof what - 1, e->msg, l);
            memcpy(e->msg, what, sizeof what - 1);
            e->msg[sizeof what - 1 + l] = 0;
            e->src = src, e->line = first_line, e->col = 1;
        }
        return -1;
    }
    {
        /* collect params (for `check --params` and to validate -D names) */
        for (int i = 0; i < prog->nkids; i++) {
            const node *s = prog->kids[i];
            if (s->kind != N_PARAM)
                continue;
            if (I->nparams == I->cap_params) {
                int nc = I->cap_params ? I->cap_params * 2 : 16;
                void *np = mem_realloc(I, I->params, (size_t)nc * sizeof *I->params);
                if (!np) { /* refused by the hook, which knows no place: the param's */
                    I->err.src = s->src, I->err.line = s->line, I->err.col = s->col;
                    return -1;
                }
                I->params = np;
                I->cap_params = nc;
            }
            I->params[I->nparams].name = s->str;
            I->params[I->nparams].decl = s;
            I->nparams++;
        }
    }
    if (I->depth == 0 && !I->is_repl) {
        for (int k = 0; k < I->noverrides; k++) {
            int found = 0;
            const char *cands[256];
            int nc = 0;
            for (int p = 0; p < I->nparams; p++) {
                found |= I->params[p].name == I->overrides[k].name;
                if (nc < 256)
                    cands[nc++] = I->params[p].name;
            }
            if (!found) {
                const char *s = interp_suggest_name(I->overrides[k].name, cands, (size_t)nc);
                return err_pos(I, -1, 0, 0, ERR_USAGE, "-D %s: the script has no param '%s'%s%s%s",
                               I->overrides[k].name, I->overrides[k].name, s ? " (did you mean '" : "",
                               s ? s : "", s ? "'?)" : "");
            }
        }
    }
    if (check_only)
        return 0;
    return eval_block(I, I->globals, prog, last);
}

int session_report(interp *I)
{
    if (!I->err.active) { /* called on a failure: one that recorded no error is still not a success */
        fflush(stdout);
        fprintf(stderr, "frac: internal error: an operation failed without saying why (please report this with the script)\n");
        return err_kind_exit(ERR_MEMORY); /* 70, as for a runtime failure */
    }
    fflush(stdout);
    diag_print(I, stderr, &I->err);
    return err_kind_exit(I->err.kind);
}
