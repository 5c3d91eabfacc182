/* test_interp_counts.c — the interpreter's structural claims (issue 15),
 * seen through its counters (interp_counts in state.h), not through time:
 *
 *   - names resolved at compile time: resolved code, run as resolve.c saw
 *     it, never searches a scope by name (count.name_searches stays 0 for
 *     every program below, which print what they computed, checked against
 *     values worked out by hand);
 *   - the cases where a search is legitimate (the REPL's open top level, an
 *     input that stopped half-way) give right answers;
 *   - lazy range: a loop over range(9e7) that breaks early (by an error,
 *     the only early exit the language has) makes no list and no scope per
 *     item it did not reach;
 *   - push/append amortised O(1): the item array of a list built by
 *     x = concat(x, [i]) or a comprehension is reallocated ~log2(n) times;
 *   - builtin parameter types compiled once: calling a builtin 1,000 times
 *     compiles its declaration's types only on the first call;
 *   - scopes: what a call and a loop iteration make (count.scopes), and
 *     that they come from the pool (count.scope_allocs).
 *
 * Linked with the interpreter's objects (Makefile: as the fuzz harness). */
#include <string.h>

#include "check.h"
#include "session.h"
#include "state.h"
#include "test_session.h"

typedef struct run {
    interp_counts d; /* the counts the program's run added */
    int rc;
    char out[512];   /* what print() wrote */
    char err[1024];  /* the error message, if it failed */
} run;

static void counts_sub(interp_counts *d, const interp_counts *a, const interp_counts *b)
{
    d->name_searches = a->name_searches - b->name_searches;
    d->scopes = a->scopes - b->scopes;
    d->scope_allocs = a->scope_allocs - b->scope_allocs;
    d->list_grows = a->list_grows - b->list_grows;
    d->types_compiled = a->types_compiled - b->types_compiled;
}

/* Run one or more inputs in one session (REPL entries when repl is set);
 * the counts are those of the last input alone, from parse to end. */
static void run_inputs(run *r, int repl, const char *const *texts, int n)
{
    memset(r, 0, sizeof *r);
    interp st;
    FILE *f;
    r->rc = test_session(&st, repl, &f);
    if (!f)
        return;
    CHECK(r->rc == 0, "session_setup");
    for (int i = 0; i < n && r->rc == 0; i++) {
        interp_counts before = st.count;
        r->rc = session_run_lines(&st, repl ? "<repl>" : "<test>", texts[i], strlen(texts[i]), 1, 0, NULL);
        counts_sub(&r->d, &st.count, &before);
        if (r->rc && st.err.active) {
            snprintf(r->err, sizeof r->err, "%s", st.err.msg);
            if (repl && i + 1 < n) { /* the REPL reports and goes on */
                err_clear(&st);
                r->rc = 0;
            }
        }
    }
    fflush(f);
    rewind(f);
    size_t got = fread(r->out, 1, sizeof r->out - 1, f);
    r->out[got] = 0;
    fclose(f);
    interp_free(&st);
}

static void run_script(run *r, const char *text)
{
    run_inputs(r, 0, &text, 1);
}

/* A script that must print `want` without a single search by name. */
static void resolved(const char *what, const char *text, const char *want)
{
    run r;
    run_script(&r, text);
    CHECK(r.rc == 0, "%s: ran (%s)", what, r.err);
    CHECK(strcmp(r.out, want) == 0, "%s: printed '%s', expected '%s'", what, r.out, want);
    CHECK(r.d.name_searches == 0, "%s: %ld searches by name", what, r.d.name_searches);
}

static void test_no_search(void)
{
    resolved("fib", "fn fib(n) = if n < 2 then n else fib(n - 1) + fib(n - 2)\nprint(fib(20))\n", "6765\n");
    /* sum of i^2, i < 1000 = 999 * 1000 * 1999 / 6 */
    resolved("range loop", "let s = 0\nfor i in range(1000) do\n  s = s + i * i\nend\nprint(s)\n", "332833500\n");
    resolved("closure",
             "fn adder(k) = x => x + k\nlet s = 0\nfor i in range(10) do\n  let f = adder(i)\n"
             "  s = s + f(1)\nend\nprint(s)\n",
             "55\n");
    /* nested closures reading names one, two and three scopes out */
    resolved("nested closures",
             "fn outer(a) do\n  fn mid(b) do\n    fn inner(c) = a * 100 + b * 10 + c\n    inner\n  end\n  mid\n"
             "end\nprint(outer(1)(2)(3))\n",
             "123\n");
    /* the inner x hides the outer one; the outer one is unchanged */
    resolved("shadowing",
             "let x = 1\nfn f() do\n  let x = 2\n  fn g() = x\n  g() * 10\nend\nlet y = do\n  let x = 5\n"
             "  x + 1\nend\nprint(f(), x, y)\n",
             "20 1 6\n");
    resolved("let in loops",
             "let s = 0\nfor i in range(4) do\n  let y = i * 2\n  let z = y + 1\n  for j in range(3) do\n"
             "    let w = z * j\n    s = s + w\n  end\nend\nprint(s)\n",
             /* sum over i < 4 of (2i + 1) * (0 + 1 + 2) = 16 * 3 */
             "48\n");
    resolved("comprehensions",
             "let k = 10\nlet a = [x * x for x in range(7) if x % 2 == 0]\n"
             "let b = [[x + y + k for y in range(2)] for x in range(2)]\nprint(a, b)\n",
             "[0, 4, 16, 36] [[10, 11], [11, 12]]\n");
    resolved("mutual recursion",
             "fn even(n) = if n == 0 then true else odd(n - 1)\nfn odd(n) = if n == 0 then false else even(n - 1)\n"
             "print(even(10), odd(7), even(3))\n",
             "true true false\n");
    resolved("defined after use", "fn a(n) = b(n) + 1\nfn b(n) = n * 2\nprint(a(3))\n", "7\n");
    resolved("defaults and named arguments",
             "fn f(a, b = a + 1) = a * 10 + b\nprint(f(2), f(b: 1, a: 3), f(4, 5))\n", "23 31 45\n");
    resolved("builtins and constants", "print(sqrt(16) + floor(pi), len([1, 2, 3]))\n", "7 3\n");
    resolved("import",
             "import \"colours\"\nimport \"colours\" as c\nlet k = len(fire) + len(c.ocean)\n"
             "print(k, red, palette_at(greys, 0.5))\n",
             "9 [1, 0, 0] [0.5, 0.5, 0.5]\n");
    /* a top level of more than 16 names has a hash index (value.c) */
    {
        char text[2048], want[64];
        size_t at = 0;
        for (int i = 0; i < 40; i++)
            at += (size_t)snprintf(text + at, sizeof text - at, "let v%d = %d\n", i, i);
        at += (size_t)snprintf(text + at, sizeof text - at, "v7 = v39 + v3\nlet t = 0\n");
        at += (size_t)snprintf(text + at, sizeof text - at, "for i in range(3) do\n  t = t + v7 + v0\nend\n");
        snprintf(text + at, sizeof text - at, "print(v7, t)\n");
        snprintf(want, sizeof want, "42 126\n");
        resolved("a large top level", text, want);
    }
    resolved("if and blocks",
             "fn sign(x) = if x < 0 then do\n  let m = -1\n  m\nend elif x == 0 then 0 else 1\n"
             "print(sign(-3), sign(0), sign(2))\n",
             "-1 0 1\n");
}

/* Where a search by name is legitimate: the REPL's top level is open
 * (later inputs add and redefine names), so a function's uses of its names
 * are not bound to slots; and an input that stopped half-way left fewer
 * names than its slots expected. Both must still give the right values. */
static void test_repl(void)
{
    const char *a[] = {"let x = 1\nfn f() = x * 2\n", "let x = 20\nprint(f(), x)\n"};
    run r;
    run_inputs(&r, 1, a, 2);
    CHECK(r.rc == 0 && strcmp(r.out, "40 20\n") == 0, "REPL redefinition: '%s' (%s)", r.out, r.err);
    /* f's body reads the top-level x by name: open scopes are searched */
    CHECK(r.d.name_searches > 0, "REPL: searches by name expected, %ld", r.d.name_searches);
    /* an input that failed after defining its first name */
    const char *b[] = {"let p = 3\nlet q = p + assert(false, \"half-way\")\n", "let q = 4\nlet r = p + q\nprint(p, q, r)\n"};
    run_inputs(&r, 1, b, 2);
    CHECK(r.rc == 0 && strcmp(r.out, "3 4 7\n") == 0, "REPL after a failed input: '%s' (%s)", r.out, r.err);
}

/* Lazy range: no list, and the loop stops where it stops. An error is the
 * only way out of a loop early; an assertion failing at i = 5 does it. */
static void test_lazy_range(void)
{
    run r;
    run_script(&r, "let s = 0\nfor i in range(9e7) do\n  s = s + i\n  if i == 5 then print(s) else 0\n"
                   "  assert(i < 5, \"stop\")\nend\n");
    CHECK(r.rc != 0 && strstr(r.err, "stop") != NULL, "stopped by the assertion: '%s'", r.err);
    CHECK(strcmp(r.out, "15\n") == 0, "ran six iterations: '%s'", r.out);
    CHECK(r.d.list_grows == 0, "range(9e7): %ld list growths", r.d.list_grows);
    /* one scope for the loop's iterations (reused), a few for the calls */
    CHECK(r.d.scopes < 20, "%ld scopes", r.d.scopes);
    /* a materialised range would be one list of 1e9 items: so would a
     * comprehension's result be, but it is only as long as what it keeps */
    run_script(&r, "let a = [i for i in range(9e7) if i < 3 or assert(false, \"stop\")]\n");
    CHECK(r.rc != 0 && strstr(r.err, "stop") != NULL, "comprehension stopped: '%s'", r.err);
    CHECK(r.d.list_grows <= 1, "comprehension over range(9e7): %ld list growths", r.d.list_grows);
}

/* concat(x, [i]) into x, and val_list_push: doublings, so ~log2(n). */
static void test_append(void)
{
    long grows[2];
    const int sizes[2] = {1000, 64000};
    for (int k = 0; k < 2; k++) {
        char text[256];
        snprintf(text, sizeof text,
                 "let s = []\nfor i in range(%d) do\n  s = concat(s, [i])\nend\nprint(len(s), s[%d])\n", sizes[k],
                 sizes[k] - 1);
        run r;
        run_script(&r, text);
        char want[64];
        snprintf(want, sizeof want, "%d %d\n", sizes[k], sizes[k] - 1);
        CHECK(r.rc == 0 && strcmp(r.out, want) == 0, "concat %d: '%s' (%s)", sizes[k], r.out, r.err);
        grows[k] = r.d.list_grows;
        /* 1,000 items: 1, 2, 4, … 1024 is 11 doublings; the literal [i] and
         * [] are made at their size */
        CHECK(r.d.list_grows <= 2 + (k ? 16 : 10), "concat %d: %ld reallocations", sizes[k], r.d.list_grows);
        CHECK(r.d.name_searches == 0, "concat %d: %ld searches", sizes[k], r.d.name_searches);
    }
    /* 64× the items, 6 more doublings (log2 64), not 64× the reallocations */
    CHECK(grows[1] - grows[0] >= 5 && grows[1] - grows[0] <= 7, "reallocations %ld then %ld", grows[0], grows[1]);
    /* a comprehension with a filter grows its result as it fills (value.c) */
    run r;
    run_script(&r, "let a = [i for i in range(100000) if i % 2 == 0]\nprint(len(a))\n");
    CHECK(r.rc == 0 && strcmp(r.out, "50000\n") == 0, "filtered comprehension: '%s' (%s)", r.out, r.err);
    /* 8, 16, … 65536: 13 growths */
    CHECK(r.d.list_grows >= 12 && r.d.list_grows <= 14, "filtered comprehension: %ld reallocations",
          r.d.list_grows);
}

/* Builtin parameter types are compiled on a builtin's first call only
 * (norm's v is declared "vec+inf+nan", round's x a union of four types). */
static void test_types_once(void)
{
    run one, many;
    run_script(&one, "let s = 0\nfor i in range(1) do\n  s = s + round(norm([i, 2 * i]) / 2)\nend\nprint(s)\n");
    run_script(&many, "let s = 0\nfor i in range(1000) do\n  s = s + round(norm([i, 2 * i]) / 2)\nend\nprint(s)\n");
    CHECK(one.rc == 0 && strcmp(one.out, "0\n") == 0, "once: '%s' (%s)", one.out, one.err);
    /* round(i * sqrt(5) / 2) summed over i < 1000 (Python: sum(floor(i * sqrt(5) / 2 + 0.5))) */
    CHECK(many.rc == 0 && strcmp(many.out, "558456\n") == 0, "1000 times: '%s' (%s)", many.out, many.err);
    CHECK(one.d.types_compiled >= 2, "the first calls compile norm's and round's types: %ld",
          one.d.types_compiled);
    CHECK(many.d.types_compiled == one.d.types_compiled, "1000 calls compiled %ld types, one call %ld",
          many.d.types_compiled, one.d.types_compiled);
}

/* What calls and iterations make. A call of a function whose body makes
 * no closure keeps its scope on the C stack (compile.c: no heap scope at
 * all); one whose body does gets a scope per call, from the pool. A loop
 * reuses its iteration's scope unless a closure kept it. */
static void test_scopes(void)
{
    run small, big;
    run_script(&small, "fn fib(n) = if n < 2 then n else fib(n - 1) + fib(n - 2)\nprint(fib(10))\n");
    run_script(&big, "fn fib(n) = if n < 2 then n else fib(n - 1) + fib(n - 2)\nprint(fib(20))\n");
    CHECK(strcmp(small.out, "55\n") == 0 && strcmp(big.out, "6765\n") == 0, "fib: '%s' '%s'", small.out, big.out);
    /* fib(20) makes 21891 calls, fib(10) 177: none makes a heap scope (the
     * first call of each function, which compiles its body, does) */
    CHECK(big.d.scopes == small.d.scopes, "fib: %ld heap scopes for 177 calls, %ld for 21891", small.d.scopes,
          big.d.scopes);
    /* a body with a lambda in it (never called here): one scope per call */
    run_script(&small, "fn f(n) = if n < 0 then (x => x + n) else if n < 2 then n else f(n - 1) + f(n - 2)\n"
                       "print(f(10))\n");
    run_script(&big, "fn f(n) = if n < 0 then (x => x + n) else if n < 2 then n else f(n - 1) + f(n - 2)\n"
                     "print(f(20))\n");
    CHECK(strcmp(small.out, "55\n") == 0 && strcmp(big.out, "6765\n") == 0, "f: '%s' '%s'", small.out, big.out);
    CHECK(big.d.scopes - small.d.scopes == 21891 - 177, "scopes per call: %ld more for %d more calls",
          big.d.scopes - small.d.scopes, 21891 - 177);
    /* the pool holds them: allocations bounded by the depth, not the calls */
    CHECK(big.d.scope_allocs - small.d.scope_allocs <= 10, "scopes allocated: %ld then %ld", small.d.scope_allocs,
          big.d.scope_allocs);
    /* a local scope that outgrows its room (4 names) moves to the heap, and
     * loops and blocks inside it point to it while they run */
    resolved("a call's scope grows",
             "fn g(a, b) do\n  let c = a + b\n  let d = c * 2\n  let e = d + 1\n  let t = 0\n"
             "  for i in range(3) do\n    t = t + e + i\n  end\n  let u = do\n    let w = t\n    w + a\n  end\n"
             "  [a, b, c, d, e, t, u]\nend\nprint(g(1, 2), g(2, 3))\n",
             /* g(1, 2): c 3, d 6, e 7, t = 3 * 7 + 3 = 24, u 25 */
             "[1, 2, 3, 6, 7, 24, 25] [2, 3, 5, 10, 11, 36, 38]\n");
    run_script(&small, "let s = 0\nfor i in range(10) do\n  s = s + i\nend\nprint(s)\n");
    run_script(&big, "let s = 0\nfor i in range(10000) do\n  s = s + i\nend\nprint(s)\n");
    CHECK(strcmp(small.out, "45\n") == 0 && strcmp(big.out, "49995000\n") == 0, "loops: '%s' '%s'", small.out,
          big.out);
    CHECK(big.d.scopes == small.d.scopes, "a loop's scopes: %ld for 10 iterations, %ld for 10000", small.d.scopes,
          big.d.scopes);
    /* a closure made in the body keeps its iteration's scope: one each */
    run_script(&big, "let fs = [i for i in range(0)]\nfor i in range(100) do\n  fs = concat(fs, [() => i])\nend\n"
                     "print(fs[7](), fs[99](), len(fs))\n");
    CHECK(strcmp(big.out, "7 99 100\n") == 0, "closures in a loop: '%s' (%s)", big.out, big.err);
    CHECK(big.d.scopes >= 100, "closures in a loop: %ld scopes", big.d.scopes);
}

int main(void)
{
    test_no_search();
    test_repl();
    test_lazy_range();
    test_append();
    test_types_once();
    test_scopes();
    return check_done("test_interp_counts");
}
