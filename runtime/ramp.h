/* ramp.h — colour ramps (palettes): piecewise-linear RGBA over [0, 1].
 *
 * Used for marble veins and wood grain (seed 000), for colouring chaos-game
 * densities and map indices, and for field slices. Stops are sorted by
 * position; values before the first stop take its colour, after the last
 * stop the last colour.
 */
#ifndef RAMP_H
#define RAMP_H

#define RAMP_MAX_STOPS 64

typedef struct ramp {
    int n;                        /* 1 .. RAMP_MAX_STOPS */
    double pos[RAMP_MAX_STOPS];   /* non-decreasing */
    float rgba[RAMP_MAX_STOPS][4];
} ramp;

/* Colour at t (NaN gives the first stop's colour). */
void ramp_eval(const ramp *r, double t, float out[4]);
/* A grey ramp from black to white. */
ramp ramp_grey(void);

#endif
