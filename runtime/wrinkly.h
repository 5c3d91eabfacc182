/* wrinkly.h — wrinkly curves and surfaces (seed 002 §5, eq. 7-11) and their
 * adaptive tessellation (§5.2) into a coloured triangle mesh.
 *
 * Control points ("wrinkly control points") carry a position, a height h
 * (displacement along the unit normal, world units), a colour and an
 * opacity. Curves are 2-D (pos[0], pos[1]); surfaces are a grid of nu × nv
 * points, pts[j*nu + i], i along u, j along v.
 *
 * Base curve (§5.1, our exact construction). Control point p_i owns the
 * parameter interval [i, i+1) (the paper's [i-1, i) with 1-based i). Its
 * cubic Bézier runs from the midpoint m_i = (p_{i-1}+p_i)/2 to
 * m_{i+1} = (p_i+p_{i+1})/2; the inner Bézier points lie on the segments
 * p_{i-1}p_i and p_ip_{i+1}: b1 = m_i + λ(p_i - m_i), b2 = m_{i+1} + λ(p_i - m_{i+1}).
 * The tangent at each joint is along p_{i+1} - p_i from both sides, so the
 * curve is G1 (in fact C1). λ = `tension` (default 2/3, which makes the base
 * curve the uniform quadratic B-spline). The base point at the centre
 * u = i + 1/2 is ((4 - 3λ)(m_i + m_{i+1}) + 6λ p_i)/8, i.e.
 * (p_{i-1} + 6p_i + p_{i+1})/8 for λ = 2/3; the IST keeps u = i + 1/2 fixed,
 * so the wrinkly curve passes through that point displaced by h_i·N
 * (the fixed point q_i of §5.3, with H(i+1/2) as built below).
 * Open ends (translation axis): positions use a reflected phantom point
 * p_{-1} = 2p_0 - p_1 (and p_n = 2p_{n-1} - p_{n-2}), so the curve runs half a
 * segment beyond the first and last control points' midpoints symmetrically;
 * heights, colours and opacities use a repeated phantom (p_{-1} = p_0) so they
 * never overshoot. Cyclic axes wrap.
 * The height function H and the colour/opacity functions are built the same
 * way from the scalars (eq. 8). The point is eq. (10)/(11):
 *     R(u) = P(u) + H(F^{-1}(u)) N(u),   R(u,v) = P(u,v) + H(F_u^{-1}(u), F_v^{-1}(v)) N(u,v)
 * where the attributes flagged in `shuffle` use F^{-1} and the others use
 * (u, v) directly, and an axis with ist = 0 is plain spline interpolation
 * (Fig. 10 e, f). N is the unit normal of the base: (-P'_y, P'_x)/|P'| for
 * curves, P_u × P_v/|P_u × P_v| for surfaces.
 *
 * Adaptive sampling (§5.2). For each base interval A_i of each axis a level
 * K_i: the smallest K_i at which EVERY level-K_i sub-interval of A_i, its
 * heights included, projects to at most the target — `pixel` pixels with a
 * camera (curves lie in z = 0 then), `tol` world units without one (else
 * K_i = k for every interval). With K_i rounds F^{-1} is a rigid shift on
 * each level-K_i sub-interval (width w = 1/B^{K_i}, B = 2M+1), so over one
 * R = P + H(F^{-1}(u))·N has length at most
 *     w · max (|J P'| + |H'|max |J N| + |H|max |J N'|)
 * with J the projection's Jacobian (the identity without a camera). The
 * max runs over 17 samples per curve interval (7×7 per surface patch, per
 * axis), J taken exactly at the base point and at it displaced by ±max|h|
 * along N (0 behind the camera); N' by central differences. |H'|max and
 * |H|max are the hodograph and convex-hull bounds of the height's Bézier
 * values over every interval that can feed A_i after K_i rounds (|j - i|
 * <= K_i·M; on a surface, every patch of the other axis within kmax·M);
 * a crack band w_c adds 1.5/w_c · (max H - min H) to |H'|. So the choice
 * is from the maximum, never the mean, and the measured longest
 * sub-interval is typically 1/3 to 1/2 of the target (tests/unit/
 * test_wrinkly.c, test_lod). On a surface K_i of a u interval is the
 * largest over its column of patches, so all rows share one set of u
 * samples: the mesh is a conforming tensor grid, no T-junctions. Jitter
 * and `extra` do not change the levels; extra rounds stop where double
 * precision does (ist_k_limit). An axis with M = 0 stays at level 0.
 * K = max K_i (eq. 12), capped by kmax. Samples: ist_sample_positions (the
 * ((S/S_i+1)/2)-th sub-interval and every (S/S_i)-th after it), at the
 * centre or, with jitter, at a seeded random point inside it (Fig. 8b);
 * `extra` > 0 evaluates F^{-1} with K + extra rounds for the same samples
 * (structural jitter, Fig. 8c). A translation axis also gets its two end
 * points (which the IST keeps fixed). Samples are joined into quads, two
 * triangles each, counter-clockwise seen from the side N points to; vertex
 * normals are central differences of the displaced grid; vertex colour is
 * (r, g, b, opacity).
 *
 * Cracks at base-interval joints (§6, Fig. 11 d, the paper's open problem).
 * F^{-1} jumps farthest at u = i (digits 00…0 against (2M)(2M)…), so the
 * displacement steps there. Remedy (crack_band = w > 0): within distance w
 * (parameter units) of a joint, every shuffled attribute is blended toward
 * its unshuffled spline value with weight s = smoothstep(dist / w) (s = 0 at
 * the joint): A = s·A(F_u^{-1}(u), F_v^{-1}(v)) + (1 - s)·A(u, v), with
 * s = s_u·s_v on surfaces. At a joint both sides then meet the same spline
 * value, so the step closes; w = 0 switches it off (side-by-side renders).
 */
#ifndef WRINKLY_H
#define WRINKLY_H

#include <stddef.h>
#include <stdint.h>

#include "camera.h"
#include "mesh.h"
#include "rt.h"

typedef struct wrinkly_point {
    double pos[3];
    double h;
    double rgb[3];
    double opacity;
} wrinkly_point;

enum { WRINKLY_HEIGHT = 1, WRINKLY_COLOUR = 2, WRINKLY_OPACITY = 4 };

typedef struct wrinkly_axis {
    int cyclic; /* 0 translation (open), 1 cyclic (closed) */
    int ist;    /* 1: shuffle along this axis; 0: plain spline */
    int m;      /* crossing count M >= 0 (also sets the sampling base 2M+1) */
} wrinkly_axis;

typedef struct wrinkly_opts {
    double tension;         /* λ in (0, 1]; default 2/3 */
    unsigned shuffle;       /* WRINKLY_* bits: attributes that follow the IST */
    const camera *cam;      /* set up (camera_setup); NULL: world tolerance or fixed k */
    int width, height;      /* image size for cam */
    double pixel;           /* target projected sub-interval size, pixels (default 1) */
    double tol;             /* world-space sub-interval size when cam is NULL */
    int k;                  /* level of every interval when neither cam nor tol */
    int kmax;               /* cap on K (default 8) */
    int extra;              /* extra IST rounds (structural jitter) */
    int jitter;             /* 1: random point inside each sampled sub-interval */
    uint64_t seed;
    double crack_band;      /* 0: off; else half-width of the blend band at joints */
    int normal;             /* surfaces: WRINKLY_NORMAL_* (which side N and the heights face) */
    int split;              /* surfaces: the mesh is the builtin's result, so its rows may be split
                             * across shards (par.h; 0: always computed in full) */
} wrinkly_opts;

/* Orientation of a surface's normal N (and so of its heights and winding).
 * The flux of the base surface about its centroid c, Φ = ∫ (P - c)·(P_u × P_v)
 * du dv, says which way P_u × P_v faces: Φ > 0 outward, Φ < 0 inward (for a
 * closed surface Φ is 3× the enclosed volume). Against the reach
 * ρ = ∫ |P - c| |P_u × P_v| du dv (Φ = ρ for a sphere about its centre, and
 * |Φ| <= ρ always) a surface is body-like when |Φ| >= ρ/4: a sphere, a
 * torus (≈ 0.7), a cap, a tube up to ~20 radii long; a flat sheet (Φ = 0) or
 * a wavy terrain is not, and a sheet has no outward side (|Φ| <= 1e-6 ρ).
 *  AUTO:    outward if body-like, else P_u × P_v (the default);
 *  OUTWARD: N points away from the body (error if Φ = 0: no side is outward);
 *  INWARD:  the opposite;
 *  UV:      N = P_u × P_v as the paper writes it, whatever the grid order.
 * Triangles wind counter-clockwise seen from the side N points to, so a
 * closed outward mesh has positive signed volume. */
enum { WRINKLY_NORMAL_AUTO = 0, WRINKLY_NORMAL_OUTWARD, WRINKLY_NORMAL_INWARD, WRINKLY_NORMAL_UV };

void wrinkly_opts_default(wrinkly_opts *o);

/* ---- curves (2-D) ---- */
typedef struct wrinkly_curve {
    const wrinkly_point *pts;
    int n;
    wrinkly_axis ax;
} wrinkly_curve;

/* Base curve P(u) and P'(u) (eq. 7). */
void wrinkly_curve_base(const wrinkly_curve *c, double tension, double u, double p[2], double dp[2]);
/* Attribute function built like H (eq. 8): which = 0 height, 1..3 rgb, 4 opacity. */
double wrinkly_curve_attr(const wrinkly_curve *c, double tension, int which, double u);

typedef struct wrinkly_polyline {
    size_t n;
    double *xy;  /* n × 2 */
    double *u;   /* parameter of each point */
    float *rgba; /* n × 4 */
    int closed;  /* last point joins the first */
    int k;       /* K used */
} wrinkly_polyline;

/* Sample R(u) (eq. 10) adaptively into a polyline. */
rt_code wrinkly_curve_sample(const wrinkly_curve *c, const wrinkly_opts *o, wrinkly_polyline *out,
                             rt_error *e);
void wrinkly_polyline_free(wrinkly_polyline *p);
/* The level K_i of each of the c->n base intervals that wrinkly_curve_sample
 * uses (so a caller can size the output first: Σ (2M+1)^{K_i}, plus the two
 * ends of an open curve). RT_ENOMEM when the level-of-detail bounds find no
 * memory (ki is then not set). */
rt_code wrinkly_curve_levels(const wrinkly_curve *c, const wrinkly_opts *o, int *ki, rt_error *e);

/* ---- surfaces ---- */
typedef struct wrinkly_surface {
    const wrinkly_point *pts; /* nu * nv, pts[j*nu + i] */
    int nu, nv;
    wrinkly_axis au, av;
} wrinkly_surface;

/* Base surface P(u, v) and its unit normal (zero if undefined). */
void wrinkly_surface_base(const wrinkly_surface *s, double tension, double u, double v, double p[3],
                          double n[3]);
/* Attribute function of a surface built like H (eq. 8), unshuffled, at
 * (u, v): which = 0 height, 1..3 rgb, 4 opacity (R uses it at
 * (F_u^{-1}(u), F_v^{-1}(v)) for the shuffled attributes). */
double wrinkly_surface_attr(const wrinkly_surface *s, double tension, int which, double u, double v);

/* Φ and ρ of the base surface (above), by the midpoint rule on 5×5 cells
 * per patch. */
void wrinkly_surface_flux(const wrinkly_surface *s, double tension, double *flux, double *reach);
/* The sign (+1 or -1) that o->normal applies to P_u × P_v; 0 after an error
 * (OUTWARD/INWARD on a surface with no outward side). */
int wrinkly_surface_side(const wrinkly_surface *s, const wrinkly_opts *o, rt_error *e);

typedef struct wrinkly_info {
    int k[2];          /* K on u and v */
    int side;          /* +1: N = P_u × P_v, -1: N = P_v × P_u */
    size_t samples[2]; /* vertices along u and v */
    size_t vertices, triangles;
} wrinkly_info;

/* The levels K_i of the nu base intervals along u and the nv along v that
 * wrinkly_surface_mesh uses (vertices along u: Σ (2M_u+1)^{ku[i]}, plus 2
 * on an open axis; likewise v). RT_ENOMEM when the level-of-detail bounds
 * find no memory (ku, kv are then not all set). */
rt_code wrinkly_surface_levels(const wrinkly_surface *s, const wrinkly_opts *o, int *ku, int *kv, rt_error *e);

/* Tessellate eq. (11) into out (initialised here; free with mesh_free).
 * Parallel over rows of vertices; byte-identical for any thread count. */
rt_code wrinkly_surface_mesh(const wrinkly_surface *s, const wrinkly_opts *o, const rt_run *run,
                             mesh *out, wrinkly_info *info, rt_error *e);

#endif
