#include "render/pixel_projection.h"

#include <mujoco/mujoco.h>

#include <cmath>

namespace exotwin {

CameraView MakeCameraView(const mjvGLCamera_& cam, int width, int height) {
  CameraView v;
  for (int i = 0; i < 3; ++i) {
    v.pos[i] = cam.pos[i];
    v.forward[i] = cam.forward[i];
    v.up[i] = cam.up[i];
  }
  // right = forward x up (OpenGL's look-at convention, mjr_lookAt)
  v.right[0] = v.forward[1] * v.up[2] - v.forward[2] * v.up[1];
  v.right[1] = v.forward[2] * v.up[0] - v.forward[0] * v.up[2];
  v.right[2] = v.forward[0] * v.up[1] - v.forward[1] * v.up[0];
  const double n = std::sqrt(v.right[0] * v.right[0] + v.right[1] * v.right[1] + v.right[2] * v.right[2]);
  for (double& r : v.right) r /= n;
  v.frustum_center = cam.frustum_center;
  v.frustum_bottom = cam.frustum_bottom;
  v.frustum_top = cam.frustum_top;
  v.frustum_near = cam.frustum_near;
  v.width = width;
  v.height = height;
  return v;
}

PixelPoint ProjectToPixel(const CameraView& v, const double world[3]) {
  double d[3] = {world[0] - v.pos[0], world[1] - v.pos[1], world[2] - v.pos[2]};
  const double x = d[0] * v.right[0] + d[1] * v.right[1] + d[2] * v.right[2];
  const double y = d[0] * v.up[0] + d[1] * v.up[1] + d[2] * v.up[2];
  const double z = d[0] * v.forward[0] + d[1] * v.forward[1] + d[2] * v.forward[2];
  PixelPoint p;
  p.depth = z;
  if (z <= 0) return p;
  // Near-plane coordinates, then normalized device coordinates of glFrustum.
  const double xn = v.frustum_near * x / z, yn = v.frustum_near * y / z;
  const double half_h = 0.5 * (v.frustum_top - v.frustum_bottom);
  const double half_w = half_h * v.width / v.height;
  const double ndc_x = (xn - v.frustum_center) / half_w;
  const double ndc_y = (yn - 0.5 * (v.frustum_top + v.frustum_bottom)) / half_h;
  p.u = 0.5 * (ndc_x + 1.0) * v.width;
  p.v = 0.5 * (1.0 - ndc_y) * v.height;
  p.inside = p.u >= 0 && p.u < v.width && p.v >= 0 && p.v < v.height;
  return p;
}

}  // namespace exotwin
