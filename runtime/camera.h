/* camera.h — a perspective pinhole camera shared by every renderer
 * (ray marcher, textured objects, IFS 3-D views, the rasteriser).
 *
 * World space is right-handed with +y up. The camera looks from `eye` toward
 * `target`; `fov` is the vertical field of view in degrees. Pixel (px, py)
 * with py = 0 at the top maps to normalised device coordinates
 * ndc_x = (2(px+0.5)/w - 1) * aspect * tan(fov/2), ndc_y = (1 - 2(py+0.5)/h) * tan(fov/2).
 */
#ifndef CAMERA_H
#define CAMERA_H

typedef struct camera {
    double eye[3], target[3], up[3];
    double fov; /* degrees, vertical */
    /* derived by camera_setup: */
    double fwd[3], right[3], upv[3];
    double tan_half;
} camera;

/* Compute the orthonormal frame. Returns 0 on success, -1 if eye == target
 * or up is parallel to the view direction. */
int camera_setup(camera *c);

/* Orbit camera: looking at target from distance dist, azimuth az (degrees,
 * around +y, 0 = looking along -z from +z) and elevation el (degrees). */
void camera_orbit(camera *c, const double target[3], double dist, double az, double el, double fov);

/* Unit ray direction through pixel centre (px + 0.5 offset applied by caller
 * via sx, sy in pixel units: sx = px + 0.5 for the centre). */
void camera_ray(const camera *c, int w, int h, double sx, double sy, double dir[3]);

/* Project world point p to pixel coordinates (sx, sy) and view depth z
 * (distance along the view direction). Returns 0 if the point is in front of
 * the camera (z > 1e-9), -1 otherwise. */
int camera_project(const camera *c, int w, int h, const double p[3], double *sx, double *sy, double *z);

/* The one default framing of every renderer (view, rasterize, chaos_fset in
 * 3-D, raymarch (its box lo..hi), textured (camera_frame_sphere), the REPL's
 * previews): an orbit camera (camera_orbit's azimuth az and elevation el,
 * vertical field of view fov degrees) looking at the centre of the box
 * [lo, hi], from the distance at which the box's bounding sphere,
 * widened by 5 %, fits inside both the vertical and the horizontal field of
 * view of a w × h image: dist = 1.05 r / sin(min(fov_v, fov_h) / 2). Every
 * point of the box then projects inside the image, at least
 * 1 − tan(asin(sin(θ)/1.05)) / tan(θ) of the half-width from the border
 * (θ the smaller half-angle; 5.3 % at θ = 20°). A box of zero size is framed
 * as a sphere of radius 1 (or 1e-3 of its distance from the origin if
 * larger). Returns -1 if a corner is not finite, 0 otherwise. */
int camera_frame_box(camera *c, const double lo[3], const double hi[3], int w, int h, double az, double el,
                     double fov);

/* The same framing for an object known by a bounding sphere (centre ctr,
 * radius r; r <= 0 as a box of zero size): camera_frame_box frames its box's
 * bounding sphere through this, so both share the one formula. textured()
 * frames its object's sphere with it. Returns -1 if ctr or r is not finite. */
int camera_frame_sphere(camera *c, const double ctr[3], double r, int w, int h, double az, double el, double fov);

#endif
