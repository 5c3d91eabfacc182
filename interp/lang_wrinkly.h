/* lang_wrinkly.h — what the wrinkly-curve, surface, IST and rasteriser
 * bindings share (bind_wrinkly.c defines it; bind_ist.c and bind_raster.c
 * use it): limits, levels of detail and surface values. */
#ifndef LANG_WRINKLY_H
#define LANG_WRINKLY_H

#include "camera.h"
#include "mesh.h"
#include "state.h"
#include "wrinkly.h"

#define MAX_CONTROL 100000 /* control points per axis */
#define MAX_M 50           /* crossing count of curves and surfaces (wrinkly.c) */
#define MAX_KMAX 20
#define TY_LOD_K "int[0,20]"

/* Level of detail: iterations (fixed K) or tolerance (world length of a
 * sub-interval); kmax caps K. */
typedef struct lod {
    int k, kmax;
    double tol;
    int fixed; /* iterations given */
} lod;

typedef struct surf_obj {
    wrinkly_point *pts;
    int nu, nv;
    wrinkly_axis au, av;
    wrinkly_opts style;
} surf_obj;

/* iterations, tolerance and kmax as declared (int[0,20], num>0, int[0,20]);
 * tol_slot: the argument to blame when both iterations and tolerance are
 * given (-1: the call). */
int lang_get_lod(interp *I, value iterations, value tolerance, value kmax, int tol_slot, lod *l, const char *what);
/* The surface of a wrinkly_surface value, NULL for any other value. */
surf_obj *lang_as_surf(value v);
/* Tessellate after checking the vertex count (--max-points) and the memory
 * the engine needs (--max-memory). cam may be NULL. */
int lang_surf_mesh(interp *I, const surf_obj *so, const camera *cam, int w, int h, double pixel, const lod *l,
                   mesh **out, const char *what);

#endif
