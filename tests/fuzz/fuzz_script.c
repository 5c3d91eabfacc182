/* fuzz_script.c — libFuzzer harness: run arbitrary text as a frac script
 * with small limits, so any crash, sanitizer report, leak or hang is found.
 * Not part of `make test`. Build and run (clang):
 *   make fuzz            # builds build-fuzz/fuzz_script and runs it 60 s
 * Seeds: the examples and language tests (tests/fuzz/corpus is made from
 * them by the make rule). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "session.h"
#include "state.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096)
        return 0;
    char *text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = 0;
    interp st;
    interp_init(&st);
    st.lim.max_memory = 64u << 20;
    st.lim.max_depth = 200;
    st.lim.max_pixels = 4096;
    st.lim.max_points = 1e4;
    st.lim.max_voxels = 4096;
    st.lim.max_list = 1e5;
    st.quiet = 1;
    st.progress = 0;
    st.out_dir = "/tmp/frac-fuzz-out";
    FILE *devnull = fopen("/dev/null", "w");
    st.out = devnull ? devnull : stdout;
    if (session_setup(&st) == 0)
        session_run(&st, "<fuzz>", text, strlen(text), 0, NULL);
    interp_free(&st);
    if (devnull)
        fclose(devnull);
    free(text);
    return 0;
}
