/* tempfiles.h — for the tests of atomic writes (test_fileio.c,
 * test_fileio_fsync.c): how many temp files a write left behind. */
#ifndef FRAC_TEST_TEMPFILES_H
#define FRAC_TEST_TEMPFILES_H

#include <dirent.h>
#include <string.h>

/* Entries of dir whose names contain ".tmp". */
static inline int count_temps(const char *dir)
{
    DIR *d = opendir(dir);
    int k = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strstr(e->d_name, ".tmp"))
            k++;
    if (d)
        closedir(d);
    return k;
}

#endif
