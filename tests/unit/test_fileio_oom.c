/* test_fileio_oom.c — an out-of-memory inside an engine is a runtime failure
 * (exit 70, "out of memory"), not a script error (65).
 *
 * Runs the real frac (BUILD/frac, found beside this program's folder) under
 * RLIMIT_AS on a small 1-bit PNG that decodes to a 16384×16384 float image
 * (4 GiB): the decoder's image allocation fails. Skipped under
 * AddressSanitizer, which cannot run with an address-space limit. */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "deflate.h"
#include "fileio.h"

#if defined(__SANITIZE_ADDRESS__)
#define UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define UNDER_ASAN 1
#endif
#endif

#ifndef UNDER_ASAN
static void chunk(bytebuf *b, const char *type, const unsigned char *d, size_t n)
{
    bytebuf_u32be(b, (uint32_t)n);
    size_t at = b->len;
    bytebuf_append(b, type, 4);
    bytebuf_append(b, d, n);
    bytebuf_u32be(b, deflate_crc32(0, b->data + at, n + 4));
}

/* A w×h 1-bit greyscale PNG, all black. */
static int make_png(const char *path, uint32_t w, uint32_t h)
{
    size_t row = w / 8 + 1, n = row * h;
    unsigned char *raw = calloc(n, 1); /* filter 0, black pixels */
    bytebuf z, png;
    bytebuf_init(&z);
    bytebuf_init(&png);
    rt_error e;
    if (!raw || deflate_zlib(raw, n, 1, &z, &e))
        return -1;
    free(raw);
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    bytebuf_append(&png, sig, 8);
    unsigned char ihdr[13] = {0};
    for (int i = 0; i < 4; i++) {
        ihdr[i] = (unsigned char)(w >> (24 - 8 * i));
        ihdr[4 + i] = (unsigned char)(h >> (24 - 8 * i));
    }
    ihdr[8] = 1; /* bit depth 1, colour type 0 */
    chunk(&png, "IHDR", ihdr, 13);
    chunk(&png, "IDAT", z.data, z.len);
    chunk(&png, "IEND", NULL, 0);
    int rc = png.failed || z.failed || fileio_write_atomic(path, png.data, png.len, &e) ? -1 : 0;
    bytebuf_free(&z);
    bytebuf_free(&png);
    return rc;
}
#endif

int main(int argc, char **argv)
{
    (void)argc;
#ifdef UNDER_ASAN
    (void)argv;
    printf("test_fileio_oom: skipped under AddressSanitizer\n");
    return check_done("test_fileio_oom");
#else
    /* BUILD/tests/test_fileio_oom -> BUILD/frac */
    char frac[4096];
    snprintf(frac, sizeof frac, "%s", argv[0]);
    char *slash = strrchr(frac, '/');
    if (!slash)
        return 1;
    *slash = 0;
    slash = strrchr(frac, '/');
    snprintf(slash ? slash + 1 : frac, sizeof frac - (size_t)(slash ? slash + 1 - frac : 0), "frac");
    if (access(frac, X_OK) != 0) {
        printf("test_fileio_oom: no %s, skipped\n", frac);
        return check_done("test_fileio_oom");
    }
    char dir[] = "/tmp/frac_oom_XXXXXX";
    if (!mkdtemp(dir))
        return 1;
    char png[256], script[300];
    snprintf(png, sizeof png, "%s/big.png", dir);
    CHECK(make_png(png, 16384, 16384) == 0, "made the PNG");
    snprintf(script, sizeof script, "load(\"%s\")", png);

    int fds[2];
    if (pipe(fds) != 0)
        return 1;
    pid_t pid = fork();
    if (pid == 0) {
        struct rlimit rl = {(rlim_t)3 << 30, (rlim_t)3 << 30};
        setrlimit(RLIMIT_AS, &rl);
        dup2(fds[1], 2);
        close(fds[0]);
        close(fds[1]);
        /* limits raised so that only the address space can run out */
        execl(frac, frac, "--quiet", "--threads", "1", "--max-pixels", "1e9", "--max-memory", "100000", "-e",
              script, (char *)NULL);
        _exit(127);
    }
    close(fds[1]);
    char err[4096];
    size_t n = 0;
    ssize_t r;
    while (n + 1 < sizeof err && (r = read(fds[0], err + n, sizeof err - 1 - n)) > 0)
        n += (size_t)r;
    err[n] = 0;
    close(fds[0]);
    int st = 0;
    waitpid(pid, &st, 0);
    CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 70, "exit %d, expected 70; stderr: %s",
          WIFEXITED(st) ? WEXITSTATUS(st) : -WTERMSIG(st), err);
    /* the image's block: 16384² · 16 B = 2^32, the 2 MiB that let it start on a
     * huge page (rt_calloc_huge) and the 32 bytes of headers */
    CHECK(strstr(err, "error: load: out of memory (allocating 4297064480 bytes)") != NULL, "stderr: %s", err);
    unlink(png);
    rmdir(dir);
    return check_done("test_fileio_oom");
#endif
}
