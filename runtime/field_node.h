/* field_node.h — the field graph node, shared by field.c (nodes, printing,
 * compiler) and field_sdf.c (distance analysis). Internal to the runtime:
 * nothing outside these files looks inside a node. */
#ifndef FIELD_NODE_H
#define FIELD_NODE_H

#include "field.h"
#include "noise.h"

enum {
    FK_CONST,
    FK_COORD,
    FK_UNARY,
    FK_BINARY,
    FK_SELECT,
    FK_CLAMP,
    FK_LERP,
    FK_WARP,
    FK_EXTERNAL,
    FK_PERLIN,
    FK_FBM,
    FK_TURB,
    FK_DENSITY,
    FK_SUNION,
    FK_BIAS,
    FK_GAIN,
    FK_SMOOTHSTEP,
    FK_STEP,
    FK_AFFINE,
    FK_SDF, /* density_sdf of shape at level k[0] */
};

struct field {
    int refs;
    int kind;
    int op;      /* unop/binop, or coordinate axis */
    int nkids;
    field *kid[4];
    double k[2]; /* constant value; DMF / noise parameters */
    int octaves;
    uint64_t seed;
    noise_perm *perm;      /* noise nodes */
    density_shape shape;   /* FK_DENSITY, FK_SDF */
    rt_field_fn fn;        /* FK_EXTERNAL */
    void *ctx;
    void (*release)(void *ctx);
    char name[32];
    field *next; /* work list of field_unref */
};

#endif
