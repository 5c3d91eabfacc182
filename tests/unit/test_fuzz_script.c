/* test_fuzz_script.c — the script fuzz harness's caps, run without
 * libFuzzer: this file includes tests/fuzz/fuzz_script.c and calls its
 * LLVMFuzzerTestOneInput directly (linked like the harness, with the file
 * functions wrapped; see the Makefile). What print() writes is captured by
 * pointing the harness's output stream at a temporary file. */
#include "../fuzz/fuzz_script.c"

#include "check.h"

/* Run one input; its printed output into out (NUL-terminated). */
static void run_input(const char *script, char *out, size_t cap, long *cpu)
{
    FILE *f = tmpfile();
    CHECK(f != NULL, "tmpfile");
    if (!f)
        return;
    devnull = f;
    long t0 = cpu_us();
    LLVMFuzzerTestOneInput((const uint8_t *)script, strlen(script));
    *cpu = cpu_us() - t0;
    rewind(f);
    size_t n = fread(out, 1, cap - 1, f);
    out[n] = 0;
    fclose(f);
    devnull = NULL;
}

int main(void)
{
    int argc = 0;
    char **argv = NULL;
    LLVMFuzzerInitialize(&argc, &argv);
    if (devnull)
        fclose(devnull);
    char out[256];
    long cpu = 0;
    /* fit asked for a day (and a million generations) stops at the
     * harness's fit budget, so the script goes on to print; without the cap
     * the 0.5 s CPU budget interrupts fit and nothing after it runs */
    run_input("let t = [[0,1,1,0],[1,1,1,1],[1,0,0,1],[1,1,1,1]]\n"
              "let f = fit(t, maps: 2, time: 1e6, iterations: 1000000)\n"
              "print(\"after fit\")\n",
              out, sizeof out, &cpu);
    CHECK(strcmp(out, "after fit\n") == 0, "the script went on after fit: '%s'", out);
    CHECK(!stop_flag, "not interrupted by the 0.5 s budget");
    CHECK(cpu < FUZZ_CPU_US, "%ld us of CPU", cpu);
    /* the same without time: (iterations alone would run for minutes) */
    run_input("let t = [[0,1,1,0],[1,1,1,1],[1,0,0,1],[1,1,1,1]]\n"
              "print(type(fit(t, maps: 2, iterations: 1000000)))\n",
              out, sizeof out, &cpu);
    CHECK(strcmp(out, "ifs\n") == 0, "fit returned an IFS: '%s'", out);
    CHECK(!stop_flag && cpu < FUZZ_CPU_US, "%ld us of CPU, interrupted %d", cpu, (int)stop_flag);
    /* the 0.5 s budget still ends everything else */
    run_input("let x = 0\nfor i in range(1000) do\n for j in range(1000) do\n  for k in range(1000) do\n"
              "   x = x + 1\n  end\n end\nend\nprint(x)\n",
              out, sizeof out, &cpu);
    CHECK(stop_flag && out[0] == 0, "an endless loop is interrupted: '%s'", out);
    return check_done("test_fuzz_script");
}
