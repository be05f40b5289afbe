// Where a world point lands in the rendered image: the pinhole model MuJoCo's mjr_render uses
// (glFrustum from the scene camera, horizontal extent set by the viewport aspect ratio).
#pragma once

struct mjvGLCamera_;

namespace exotwin {

// A camera as rendered: frame in world coordinates (m), frustum at the near plane (m), image size.
struct CameraView {
  double pos[3], forward[3], up[3], right[3];
  double frustum_center, frustum_bottom, frustum_top, frustum_near;
  int width, height;  // px
};

// Pixel coordinates in a top-down image (u right, v down, px; pixel centres at integer + 0.5).
struct PixelPoint {
  double u = 0, v = 0;
  double depth = 0;      // distance along the view direction (m); <= 0 behind the camera
  bool inside = false;   // in front of the camera and within the image
};

// Camera of a MuJoCo scene (scn.camera[0] and [1] averaged, as mjr_render does) for an image of
// width x height px.
CameraView MakeCameraView(const mjvGLCamera_& cam, int width, int height);

// Projects a world point (m) to pixel coordinates.
PixelPoint ProjectToPixel(const CameraView& view, const double world[3]);

}  // namespace exotwin
