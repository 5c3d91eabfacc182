/* test_fileio_fsync.c — fileio_write_atomic syncs the data before the
 * rename, and a failed fsync is an I/O error that leaves the old file. Built
 * with -Wl,--wrap=fsync (see the Makefile): __wrap_fsync below sees every
 * fsync the runtime makes and can fail it. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "check.h"
#include "fileio.h"
#include "tempfiles.h"

int __real_fsync(int fd);
int __wrap_fsync(int fd);

static char target[300];
static int calls, fail, files_synced, old_at_file_sync;

static int holds(const char *path, const char *text)
{
    char buf[64] = {0};
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    return n == strlen(text) && memcmp(buf, text, n) == 0;
}

int __wrap_fsync(int fd)
{
    calls++;
    struct stat st;
    if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
        files_synced++;
        old_at_file_sync = holds(target, "old"); /* not renamed over yet */
    }
    if (fail) {
        errno = EIO;
        return -1;
    }
    return __real_fsync(fd);
}

int main(void)
{
    char root[] = "/tmp/frac-fsync-XXXXXX";
    CHECK(mkdtemp(root) != NULL, "mkdtemp");
    snprintf(target, sizeof target, "%s/out.txt", root);
    FILE *f = fopen(target, "wb");
    if (f) {
        fputs("old", f);
        fclose(f);
    }
    rt_error e = {0};
    /* a good write: the temp file is synced while the target still holds
     * the old text, then the folder (after the rename) */
    CHECK(fileio_write_atomic(target, "new", 3, &e) == RT_OK, "write: %s", e.msg);
    CHECK(files_synced == 1 && old_at_file_sync, "the data synced before the rename (%d file syncs)", files_synced);
    CHECK(calls == 2, "the file and its folder synced: %d calls", calls);
    CHECK(holds(target, "new"), "the new text is there");
    /* a failed fsync: an I/O error, the old file kept, no temp file left */
    fail = 1;
    CHECK(fileio_write_atomic(target, "newer", 5, &e) == RT_EIO, "a failed fsync is an I/O error");
    CHECK(strstr(e.msg, "cannot write '") && strstr(e.msg, strerror(EIO)), "message: %s", e.msg);
    CHECK(holds(target, "new"), "the file before the failed write is kept");
    CHECK(count_temps(root) == 0, "no temp file left");
    unlink(target);
    rmdir(root);
    return check_done("test_fileio_fsync");
}
