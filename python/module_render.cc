// exotwin.render_frame: a still of the twin rendered off-screen into a NumPy array (the rendering
// plugin's RenderStill, render/render_plugin.h; the plugin is found as the package says,
// python/exotwin/__init__.py).
#include <mujoco/mujoco.h>

#include <array>
#include <cmath>

#include "core/error.h"
#include "formats/model_file.h"
#include "python/module.h"
#include "render/render_plugin.h"
#include "sim/ghost_legs.h"
#include "sim/plant.h"

namespace exotwin::python {
namespace {

// The leg of model file `params` (the exoskeleton alone without `human:`) at hip and knee angles (rad),
// with translucent ghost legs (sim/ghost_legs.h, as render-replay draws a replay's simulated angles) at
// `ghosts` (hip, knee pairs; colours `rgba`, one per ghost, or none: GhostLegStyle's), as the videos
// show it: a (height, width, 3) uint8 RGB array.
py::array RenderFrame(double q_hip, double q_knee, const std::string& params,
                      const std::vector<std::pair<double, double>>& ghosts,
                      const std::vector<std::array<double, 4>>& rgba, int width, int height) {
  const auto finite = [](double hip, double knee, const std::string& what) {
    if (!std::isfinite(hip) || !std::isfinite(knee))
      throw InputError("render_frame: expected finite angles (rad) for " + what + ", got hip " + std::to_string(hip) +
                       ", knee " + std::to_string(knee));
  };
  finite(q_hip, q_knee, "the leg");
  for (size_t k = 0; k < ghosts.size(); ++k) finite(ghosts[k].first, ghosts[k].second, "ghost " + std::to_string(k));
  if (!rgba.empty() && rgba.size() != ghosts.size())
    throw InputError("render_frame: ghost_rgba: expected one colour per ghost (" + std::to_string(ghosts.size()) +
                     "), got " + std::to_string(rgba.size()));
  for (const auto& c : rgba)
    for (double v : c)
      if (!(v >= 0 && v <= 1)) throw InputError("render_frame: ghost_rgba: expected values in 0 .. 1, got " + std::to_string(v));
  if (width < 16 || height < 16 || width > 8192 || height > 8192 || width % 2 || height % 2)
    throw InputError("render_frame: expected an even width and height of 16 .. 8192 px, got " + std::to_string(width) +
                     "x" + std::to_string(height));
  auto* rgb = new std::vector<unsigned char>();
  py::capsule owner(rgb, [](void* p) { delete static_cast<std::vector<unsigned char>*>(p); });
  {
    py::gil_scoped_release release;
    const LegParams p = ReadModelFile(params);
    std::vector<GhostLegStyle> styles(ghosts.size());
    for (size_t k = 0; k < ghosts.size(); ++k) {
      styles[k].suffix = "_ghost" + std::to_string(k + 1);
      if (!rgba.empty()) styles[k].rgba = rgba[k];
    }
    GhostLegModel legs(ExowheelMjcfPath(p.human.has_value()), styles, p.L1);
    legs.SetLeg(-1, q_hip, q_knee);
    for (size_t k = 0; k < ghosts.size(); ++k) legs.SetLeg(static_cast<int>(k), ghosts[k].first, ghosts[k].second);
    RenderOptions opt;
    opt.width = width;
    opt.height = height;
    opt.overlays = false;
    *rgb = RenderStill(legs.model(), legs.data()->qpos, opt);
  }
  const size_t w = static_cast<size_t>(width), h = static_cast<size_t>(height);
  if (rgb->size() != w * h * 3) throw std::runtime_error("render_frame: the renderer returned a frame of another size");
  return py::array_t<unsigned char>({h, w, size_t{3}}, {w * 3, size_t{3}, size_t{1}}, rgb->data(), owner);
}

}  // namespace

void BindRender(py::module_& m) {
  m.def("_render_frame", &RenderFrame, py::arg("q_hip"), py::arg("q_knee"), py::arg("params"), py::arg("ghosts"),
        py::arg("rgba"), py::arg("width"), py::arg("height"));
}

}  // namespace exotwin::python
