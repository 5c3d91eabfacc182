/* camera.c — perspective camera frame, rays and projection. */
#include "camera.h"

#include <math.h>

static void sub3(const double a[3], const double b[3], double r[3])
{
    r[0] = a[0] - b[0];
    r[1] = a[1] - b[1];
    r[2] = a[2] - b[2];
}

static void cross3(const double a[3], const double b[3], double r[3])
{
    double x = a[1] * b[2] - a[2] * b[1];
    double y = a[2] * b[0] - a[0] * b[2];
    double z = a[0] * b[1] - a[1] * b[0];
    r[0] = x;
    r[1] = y;
    r[2] = z;
}

static double norm3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0) {
        v[0] /= l;
        v[1] /= l;
        v[2] /= l;
    }
    return l;
}

int camera_setup(camera *c)
{
    sub3(c->target, c->eye, c->fwd);
    if (norm3(c->fwd) < 1e-12)
        return -1;
    cross3(c->fwd, c->up, c->right);
    if (norm3(c->right) < 1e-12)
        return -1;
    cross3(c->right, c->fwd, c->upv);
    norm3(c->upv);
    double fov = c->fov > 0 && c->fov < 179 ? c->fov : 45;
    c->tan_half = tan(fov * 3.14159265358979323846 / 360.0);
    return 0;
}

void camera_orbit(camera *c, const double target[3], double dist, double az, double el, double fov)
{
    double a = az * 3.14159265358979323846 / 180.0, e = el * 3.14159265358979323846 / 180.0;
    for (int i = 0; i < 3; i++)
        c->target[i] = target[i];
    c->eye[0] = target[0] + dist * cos(e) * sin(a);
    c->eye[1] = target[1] + dist * sin(e);
    c->eye[2] = target[2] + dist * cos(e) * cos(a);
    c->up[0] = 0;
    c->up[1] = 1;
    c->up[2] = 0;
    c->fov = fov;
    camera_setup(c);
}

void camera_ray(const camera *c, int w, int h, double sx, double sy, double dir[3])
{
    double aspect = (double)w / (double)h;
    double nx = (2.0 * sx / w - 1.0) * aspect * c->tan_half;
    double ny = (1.0 - 2.0 * sy / h) * c->tan_half;
    for (int i = 0; i < 3; i++)
        dir[i] = c->fwd[i] + nx * c->right[i] + ny * c->upv[i];
    norm3(dir);
}

int camera_project(const camera *c, int w, int h, const double p[3], double *sx, double *sy, double *z)
{
    double d[3];
    sub3(p, c->eye, d);
    double zz = d[0] * c->fwd[0] + d[1] * c->fwd[1] + d[2] * c->fwd[2];
    *z = zz;
    if (zz <= 1e-9)
        return -1;
    double xr = d[0] * c->right[0] + d[1] * c->right[1] + d[2] * c->right[2];
    double yu = d[0] * c->upv[0] + d[1] * c->upv[1] + d[2] * c->upv[2];
    double aspect = (double)w / (double)h;
    double nx = xr / (zz * c->tan_half * aspect);
    double ny = yu / (zz * c->tan_half);
    *sx = (nx + 1.0) * 0.5 * w;
    *sy = (1.0 - ny) * 0.5 * h;
    return 0;
}

int camera_frame_sphere(camera *c, const double ctr[3], double r, int w, int h, double az, double el, double fov)
{
    double far = 0;
    for (int i = 0; i < 3; i++) {
        if (!isfinite(ctr[i]))
            return -1;
        far += ctr[i] * ctr[i];
    }
    if (!isfinite(r))
        return -1;
    if (!(r > 0))
        r = fmax(1.0, 1e-3 * sqrt(far));
    if (!(fov > 0 && fov < 179))
        fov = 45; /* as camera_setup */
    double half = 0.5 * fov * 3.14159265358979323846 / 180.0;
    if (w > 0 && h > 0 && w < h)
        half = atan(tan(half) * w / h); /* the horizontal half-angle is the smaller */
    camera_orbit(c, ctr, 1.05 * r / sin(half), az, el, fov);
    return camera_setup(c);
}

int camera_frame_box(camera *c, const double lo[3], const double hi[3], int w, int h, double az, double el,
                     double fov)
{
    double ctr[3], r = 0;
    for (int i = 0; i < 3; i++) {
        if (!isfinite(lo[i]) || !isfinite(hi[i]))
            return -1;
        ctr[i] = 0.5 * (lo[i] + hi[i]);
        r += 0.25 * (hi[i] - lo[i]) * (hi[i] - lo[i]);
    }
    return camera_frame_sphere(c, ctr, sqrt(r), w, h, az, el, fov);
}
