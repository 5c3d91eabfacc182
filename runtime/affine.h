/* affine.h — affine maps of the plane and of space.
 *
 * One type for both: x' = M x + t with M 3×3. A 2-D map uses the top-left
 * 2×2 block and t[0], t[1]; the rest is identity/zero. Column orders of the
 * literature, all mapped onto this type:
 *   Fractint 2-D  (a b c d e f p):  x' = a x + b y + e,  y' = c x + d y + f
 *   seed 001      (a b c d e f g h o q r s):  M = [[a b c][d e f][g h o]], t = (q r s)
 *   Fractint 3-D  (a b c d e f g h i j k l p):  M = [[a b c][d e f][g h i]], t = (j k l)
 */
#ifndef AFFINE_H
#define AFFINE_H

typedef struct affine {
    int dim;        /* 2 or 3 */
    double m[3][3]; /* row-major: x'_i = sum_j m[i][j] x_j + t[i] */
    double t[3];
} affine;

affine affine_identity(int dim);
/* Fractint 2-D order a b c d e f. */
affine affine_from_2d(double a, double b, double c, double d, double e, double f);
/* 9 matrix entries row-major + 3 translation entries. */
affine affine_from_3d(const double m9[9], const double t3[3]);

/* r = a ∘ b, i.e. r(x) = a(b(x)). Dimension is the larger of the two. */
affine affine_compose(const affine *a, const affine *b);
void affine_apply(const affine *a, const double in[3], double out[3]);
double affine_det(const affine *a);
/* Operator 2-norm of the linear part (largest singular value): the map's
 * Lipschitz constant, < 1 for a contraction. */
double affine_contraction(const affine *a);
/* Inverse; returns -1 if the matrix is singular (|det| < 1e-300). */
int affine_invert(const affine *a, affine *inv);

#endif
