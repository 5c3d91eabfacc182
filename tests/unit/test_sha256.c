/* test_sha256.c — SHA-256 against the FIPS 180-2 example vectors (appendix B)
 * and against /usr/bin/sha256sum on a file (skipped, saying so, without it). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "sha256.h"

static void vector(const char *msg, const char *want)
{
    char hex[65];
    sha256_hex(msg, strlen(msg), hex);
    CHECK(strcmp(hex, want) == 0, "sha256(\"%s\") = %s, want %s", msg, hex, want);
}

int main(void)
{
    /* FIPS 180-2 appendix B.1, B.2, and the empty message */
    vector("abc", "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    vector("", "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    vector("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq",
           "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");

    /* B.3: one million 'a', fed in uneven pieces to exercise the buffering */
    sha256_ctx c;
    sha256_init(&c);
    char a[997];
    memset(a, 'a', sizeof a);
    size_t left = 1000000;
    for (size_t k = 1; left; k = k % 997 + 1) {
        size_t n = k < left ? k : left;
        sha256_update(&c, a, n);
        left -= n;
    }
    unsigned char d[32];
    sha256_final(&c, d);
    char hex[65];
    for (int i = 0; i < 32; i++)
        snprintf(hex + 2 * i, 3, "%02x", d[i]);
    CHECK(strcmp(hex, "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0") == 0,
          "million a: %s", hex);

    /* every length 0..200 (padding crosses the 56-byte boundary) against sha256sum */
    if (access("/usr/bin/sha256sum", X_OK) != 0) {
        printf("test_sha256: sha256sum comparison skipped: /usr/bin/sha256sum is not installed\n");
    } else {
        char path[] = "/tmp/frac-sha-XXXXXX";
        int fd = mkstemp(path);
        CHECK(fd >= 0, "mkstemp");
        unsigned char buf[200];
        for (int i = 0; i < 200; i++)
            buf[i] = (unsigned char)(i * 37 + 11);
        for (size_t n = 0; fd >= 0 && n <= 200; n += 7) {
            FILE *f = fopen(path, "wb");
            fwrite(buf, 1, n, f);
            fclose(f);
            char cmd[128], line[128] = "";
            snprintf(cmd, sizeof cmd, "/usr/bin/sha256sum %s", path);
            FILE *p = popen(cmd, "r");
            if (!p || !fgets(line, sizeof line, p))
                line[0] = 0;
            if (p)
                pclose(p);
            sha256_hex(buf, n, hex);
            CHECK(strncmp(line, hex, 64) == 0, "%zu bytes: ours %s, sha256sum %.64s", n, hex, line);
        }
        if (fd >= 0) {
            close(fd);
            unlink(path);
        }
    }
    return check_done("test_sha256");
}
