/* affine.c — affine maps: composition, application, operator norm. */
#include "affine.h"

#include <math.h>
#include <string.h>

affine affine_identity(int dim)
{
    affine a;
    memset(&a, 0, sizeof a);
    a.dim = dim;
    a.m[0][0] = a.m[1][1] = a.m[2][2] = 1;
    return a;
}

affine affine_from_2d(double a, double b, double c, double d, double e, double f)
{
    affine r = affine_identity(2);
    r.m[0][0] = a;
    r.m[0][1] = b;
    r.m[1][0] = c;
    r.m[1][1] = d;
    r.t[0] = e;
    r.t[1] = f;
    return r;
}

affine affine_from_3d(const double m9[9], const double t3[3])
{
    affine r = affine_identity(3);
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            r.m[i][j] = m9[3 * i + j];
        r.t[i] = t3[i];
    }
    return r;
}

affine affine_compose(const affine *a, const affine *b)
{
    affine r;
    r.dim = a->dim > b->dim ? a->dim : b->dim;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            double s = 0;
            for (int k = 0; k < 3; k++)
                s += a->m[i][k] * b->m[k][j];
            r.m[i][j] = s;
        }
        double s = a->t[i];
        for (int k = 0; k < 3; k++)
            s += a->m[i][k] * b->t[k];
        r.t[i] = s;
    }
    return r;
}

void affine_apply(const affine *a, const double in[3], double out[3])
{
    double o[3];
    for (int i = 0; i < 3; i++)
        o[i] = a->m[i][0] * in[0] + a->m[i][1] * in[1] + a->m[i][2] * in[2] + a->t[i];
    out[0] = o[0];
    out[1] = o[1];
    out[2] = o[2];
}

double affine_det(const affine *a)
{
    const double(*m)[3] = a->m;
    if (a->dim == 2)
        return m[0][0] * m[1][1] - m[0][1] * m[1][0];
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

double affine_contraction(const affine *a)
{
    const double(*m)[3] = a->m;
    if (a->dim == 2) {
        /* Largest singular value of a 2×2 matrix in closed form. */
        double p = m[0][0] * m[0][0] + m[0][1] * m[0][1] + m[1][0] * m[1][0] + m[1][1] * m[1][1];
        double q = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        double disc = p * p - 4 * q * q;
        return sqrt(0.5 * (p + sqrt(disc > 0 ? disc : 0)));
    }
    /* Largest eigenvalue of the symmetric M^T M: power iteration from a
     * start vector with all components, enough steps for 1e-12 relative. */
    double s[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            s[i][j] = m[0][i] * m[0][j] + m[1][i] * m[1][j] + m[2][i] * m[2][j];
    double v[3] = {1, 0.7548776662, 0.5698402910}, lambda = 0;
    for (int it = 0; it < 500; it++) {
        double w[3];
        for (int i = 0; i < 3; i++)
            w[i] = s[i][0] * v[0] + s[i][1] * v[1] + s[i][2] * v[2];
        double n = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        if (n == 0)
            return 0;
        for (int i = 0; i < 3; i++)
            v[i] = w[i] / n;
        if (fabs(n - lambda) <= 1e-15 * n) {
            lambda = n;
            break;
        }
        lambda = n;
    }
    return sqrt(lambda);
}

int affine_invert(const affine *a, affine *inv)
{
    double d = affine_det(a);
    if (fabs(d) < 1e-300)
        return -1;
    const double(*m)[3] = a->m;
    affine r = affine_identity(a->dim);
    if (a->dim == 2) {
        r.m[0][0] = m[1][1] / d;
        r.m[0][1] = -m[0][1] / d;
        r.m[1][0] = -m[1][0] / d;
        r.m[1][1] = m[0][0] / d;
    } else {
        r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / d;
        r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / d;
        r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / d;
        r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / d;
        r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / d;
        r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / d;
        r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / d;
        r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / d;
        r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / d;
    }
    for (int i = 0; i < 3; i++)
        r.t[i] = -(r.m[i][0] * a->t[0] + r.m[i][1] * a->t[1] + r.m[i][2] * a->t[2]);
    *inv = r;
    return 0;
}
