/* fuzz_script.c — libFuzzer harness: run arbitrary text as a frac script
 * with every amount of work capped, so a run takes well under a millisecond
 * on typical inputs and any crash, sanitizer report, leak or hang is a
 * finding. See tests/fuzz/README.md (make fuzz-script, make fuzz-smoke).
 *
 * Caps (the interpreter's own limits, set small): 4 MiB of interpreter
 * memory, call depth 40, 1024 pixels per image, 2000 points, 1024 voxels,
 * lists of 1e4, fit()'s time budget 0.05 s (also without time:, so
 * fit(time: 1e6) returns and the script goes on), one thread, and a
 * CPU-time budget of 0.5 s per input after which the interpreter's
 * interrupt flag is raised (the script ends with "interrupted", not a
 * libFuzzer timeout). tests/unit/test_fuzz_script.c runs this file's
 * LLVMFuzzerTestOneInput without libFuzzer to check the caps.
 *
 * Files: the harness is linked with -Wl,--wrap=fileio_write_atomic,--wrap=
 * fileio_read_all, so nothing touches the disk. Writes go to a small
 * in-memory table (at most 8 files of 1 MiB, cleared per input) and reads
 * are served from it, so save() then load() round-trips inside one input
 * and every other path reads as "no such file".
 *
 * FRAC_FUZZ_TIMES=FILE appends one line per input to FILE: the CPU time it
 * took (user + system, microseconds), its size in bytes, and 1 if the budget
 * interrupted it — to find the inputs that cost the most (tests/fuzz/README.md).
 *
 * Skips of once-known crashes, now fixed (the parser's nesting limit, the
 * stack check, the declared contract): off by default, so the fuzzer
 * tests those fixes too; FRAC_FUZZ_SKIP_KNOWN=1 turns them back on (what
 * the first campaigns, in tests/fuzz/README.md, ran with):
 *   - more than 64 nested brackets, more than 400 operator characters on
 *     one line, more than 200 do / not / if / fn in the input (C stack
 *     overflow in the recursive parser and evaluator);
 * Known UB kept out by source text (float -> int casts of NaN / 1e300):
 *   - format() with a "{:d}" spec, random / randoms (seed:), raymarch
 *     with a non-finite camera: inputs containing "{:d" or "seed" or
 *     "raymarch" together with "nan"/"inf"/"0/0" or a huge exponent. */
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>

#include "fileio.h"
#include "session.h"
#include "state.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);
const char *__asan_default_options(void);

/* A smaller quarantine: the interpreter frees many small blocks per input
 * and recycling the default 256 MB quarantine cost a quarter of the time. */
const char *__asan_default_options(void) { return "quarantine_size_mb=16"; }

/* ---- in-memory files ---------------------------------------------------- */

#define MFILES 8
#define MFILE_MAX ((size_t)1 << 20)
static struct {
    char path[512];
    unsigned char *data;
    size_t n;
} mfiles[MFILES];
static int nmfiles;

static void mfiles_clear(void)
{
    for (int i = 0; i < nmfiles; i++)
        free(mfiles[i].data);
    nmfiles = 0;
}

rt_code __wrap_fileio_write_atomic(const char *path, const void *data, size_t n, rt_error *e);
rt_code __wrap_fileio_read_all(const char *path, size_t max_bytes, unsigned char **data,
                               size_t *n, rt_error *e);

rt_code __wrap_fileio_write_atomic(const char *path, const void *data, size_t n, rt_error *e)
{
    if (strlen(path) >= sizeof mfiles[0].path)
        return rt_fail(e, RT_EIO, "cannot write %.40s...: path too long (fuzz)", path);
    int i = 0;
    while (i < nmfiles && strcmp(mfiles[i].path, path) != 0)
        i++;
    if (i == MFILES || n > MFILE_MAX)
        return rt_fail(e, RT_EIO, "cannot write %s: fuzz file table full", path);
    unsigned char *copy = malloc(n ? n : 1);
    if (!copy)
        return rt_fail(e, RT_ENOMEM, "out of memory");
    memcpy(copy, data, n);
    if (i == nmfiles) {
        nmfiles++;
        snprintf(mfiles[i].path, sizeof mfiles[i].path, "%s", path);
    } else {
        free(mfiles[i].data);
    }
    mfiles[i].data = copy;
    mfiles[i].n = n;
    return RT_OK;
}

rt_code __wrap_fileio_read_all(const char *path, size_t max_bytes, unsigned char **data,
                               size_t *n, rt_error *e)
{
    for (int i = 0; i < nmfiles; i++) {
        if (strcmp(mfiles[i].path, path) != 0)
            continue;
        if (mfiles[i].n > max_bytes)
            return rt_fail(e, RT_EIO, "%s is too large", path);
        unsigned char *d = rt_malloc(mfiles[i].n + 1); /* freed by the runtime (rt_free) */
        if (!d)
            return rt_fail(e, RT_ENOMEM, "out of memory");
        memcpy(d, mfiles[i].data, mfiles[i].n);
        d[mfiles[i].n] = 0;
        *data = d;
        *n = mfiles[i].n;
        return RT_OK;
    }
    return rt_fail(e, RT_EIO, "cannot open %s: No such file or directory", path);
}

/* ---- skipping known crashes ------------------------------------------- */

static int skip_known = 0;

static int has(const char *text, const char *s) { return strstr(text, s) != NULL; }

/* Bracket nesting, operators per line and block keywords per input: a cheap
 * over-estimate of the parser's and evaluator's recursion depth. */
static int too_deep(const char *t, size_t n)
{
    int depth = 0, ops = 0, words = 0;
    for (size_t i = 0; i < n; i++) {
        char c = t[i];
        if (c == '(' || c == '[' || c == '{') {
            if (++depth > 64)
                return 1;
        } else if (c == ')' || c == ']' || c == '}') {
            if (depth > 0)
                depth--;
        } else if (strchr("+-*/^<>=!|%", c)) {
            if (++ops > 400)
                return 1;
        } else if ((c >= 'a' && c <= 'z') && (i == 0 || !(t[i - 1] >= 'a' && t[i - 1] <= 'z'))) {
            /* do / not / if / fn / let / else / then: at most 200 keywords per
             * input is far below any depth that matters for new findings */
            if ((!strncmp(t + i, "do", 2) || !strncmp(t + i, "not", 3) || !strncmp(t + i, "if", 2) ||
                 !strncmp(t + i, "fn", 2)) && ++words > 200)
                return 1;
        } else if (c == '\n') {
            ops = 0;
        }
    }
    return 0;
}

static int known_ub(const char *t)
{
    if (!(has(t, "nan") || has(t, "inf") || has(t, "/0") || has(t, "/ 0") || has(t, "e3") ||
          has(t, "e4") || has(t, "e5") || has(t, "e6") || has(t, "e7") || has(t, "e8") ||
          has(t, "e9") || has(t, "**") || has(t, "^")))
        return 0;
    return has(t, "{:d") || has(t, "seed") || has(t, "random") || has(t, "raymarch");
}

/* ---- the per-input work budget ----------------------------------------- */

#define FUZZ_CPU_US 500000   /* CPU time per input before the interrupt flag is raised */
#define FUZZ_FIT_SECONDS 0.05 /* fit()'s time budget: a tenth of the input's */

static volatile sig_atomic_t stop_flag;
static FILE *devnull; /* where print() goes */
static FILE *times;   /* FRAC_FUZZ_TIMES=FILE: one line per input, "CPU-microseconds bytes interrupted" */

static long cpu_us(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) * 1000000L + ru.ru_utime.tv_usec + ru.ru_stime.tv_usec;
}

static void on_vtalrm(int sig)
{
    (void)sig;
    stop_flag = 1;
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    const char *skip = getenv("FRAC_FUZZ_SKIP_KNOWN");
    skip_known = skip && skip[0] == '1';
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_vtalrm;
    sigaction(SIGVTALRM, &sa, NULL);
    devnull = fopen("/dev/null", "w");
    const char *tf = getenv("FRAC_FUZZ_TIMES");
    if (tf && *tf)
        times = fopen(tf, "a");
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 16384)
        return 0;
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = 0;
    size_t len = strlen(text);
    if (skip_known && (too_deep(text, len) || known_ub(text))) {
        free(text);
        return 0;
    }
    interp st;
    interp_init(&st);
    st.lim.max_memory = 4u << 20;
    st.lim.max_depth = 40;
    st.lim.max_pixels = 1024;
    st.lim.max_points = 2e3;
    st.lim.max_voxels = 1024;
    st.lim.max_list = 1e4;
    st.lim.max_fit_seconds = FUZZ_FIT_SECONDS;
    st.threads = 1;
    st.quiet = 1;
    st.progress = 0;
    st.out_dir = "fuzz-out";
    stop_flag = 0;
    st.interrupt = &stop_flag;
    st.out = devnull ? devnull : stdout;
    long t0 = times ? cpu_us() : 0;
    struct itimerval budget = {{0, 0}, {0, FUZZ_CPU_US}}, off = {{0, 0}, {0, 0}};
    setitimer(ITIMER_VIRTUAL, &budget, NULL);
    if (session_setup(&st) == 0)
        session_run(&st, "<fuzz>", text, len, 0, NULL);
    setitimer(ITIMER_VIRTUAL, &off, NULL);
    interp_free(&st);
    mfiles_clear();
    free(text);
    if (times)
        fprintf(times, "%ld %zu %d\n", cpu_us() - t0, size, (int)stop_flag);
    return 0;
}
