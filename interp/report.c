/* report.c — counting engine work and the end-of-run line (report.h). */
#include "report.h"

#include <string.h>
#include <time.h>

double report_clock(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

void report_work(interp *I, const char *engine, const char *unit, double amount, double t0)
{
    double dt = report_clock() - t0;
    int k = 0;
    while (k < I->nwork && !(strcmp(I->work[k].engine, engine) == 0 && strcmp(I->work[k].unit, unit) == 0))
        k++;
    if (k == I->nwork) {
        if (k == WORK_MAX) { /* full: the last entry collects the rest */
            k = WORK_MAX - 1;
            I->work[k].engine = "other";
            I->work[k].unit = "units";
        } else {
            I->work[k].engine = engine;
            I->work[k].unit = unit;
            I->work[k].amount = 0;
            I->work[k].seconds = 0;
            I->nwork++;
        }
    }
    I->work[k].amount += amount;
    I->work[k].seconds += dt;
}

/* 10.5 M, 164 k, 12.0: three significant digits with an SI prefix. */
static void si(char *buf, size_t n, double x)
{
    static const char *pre[] = {"", " k", " M", " G", " T"};
    int p = 0;
    while (x >= 1000 && p < 4)
        x /= 1000, p++;
    snprintf(buf, n, x >= 100 || p == 0 ? "%.0f%s" : x >= 10 ? "%.1f%s" : "%.2f%s", x, pre[p]);
}

void report_print(const interp *I, double wall, FILE *f)
{
    fprintf(f, "frac: done in %.2f s", wall);
    for (int k = 0; k < I->nwork; k++) {
        char amt[32], rate[32];
        si(amt, sizeof amt, I->work[k].amount);
        double s = I->work[k].seconds;
        fprintf(f, "; %s: %s %s in %.2f s", I->work[k].engine, amt, I->work[k].unit, s);
        if (s > 0) {
            si(rate, sizeof rate, I->work[k].amount / s);
            fprintf(f, " (%s/s)", rate);
        }
    }
    fputc('\n', f);
}
