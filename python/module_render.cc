// exotwin.render_frame: a still of the twin rendered off-screen into a NumPy array (the rendering
// plugin's RenderStill, render/render_plugin.h; the plugin is found as the package says,
// python/exotwin/__init__.py).
#include <mujoco/mujoco.h>

#include <cmath>

#include "core/error.h"
#include "formats/model_file.h"
#include "python/module.h"
#include "render/render_plugin.h"
#include "sim/plant.h"

namespace exotwin::python {
namespace {

// The leg of model file `params` (the exoskeleton alone without `human:`) at hip and knee angles (rad),
// as the videos show it: a (height, width, 3) uint8 RGB array.
py::array RenderFrame(double q_hip, double q_knee, const std::string& params, int width, int height) {
  if (!std::isfinite(q_hip) || !std::isfinite(q_knee))
    throw InputError("render_frame: expected finite angles (rad), got hip " + std::to_string(q_hip) + ", knee " +
                     std::to_string(q_knee));
  if (width < 16 || height < 16 || width > 8192 || height > 8192 || width % 2 || height % 2)
    throw InputError("render_frame: expected an even width and height of 16 .. 8192 px, got " + std::to_string(width) +
                     "x" + std::to_string(height));
  auto* rgb = new std::vector<unsigned char>();
  py::capsule owner(rgb, [](void* p) { delete static_cast<std::vector<unsigned char>*>(p); });
  {
    py::gil_scoped_release release;
    const LegParams p = ReadModelFile(params);
    Plant plant(ExowheelMjcfPath(p.human.has_value()));
    plant.SetParams(p);
    plant.Reset({q_hip, q_knee}, {0.0, 0.0}, 0.0);
    RenderOptions opt;
    opt.width = width;
    opt.height = height;
    opt.overlays = false;
    *rgb = RenderStill(plant.model(), plant.data()->qpos, opt);
  }
  const size_t w = static_cast<size_t>(width), h = static_cast<size_t>(height);
  if (rgb->size() != w * h * 3) throw std::runtime_error("render_frame: the renderer returned a frame of another size");
  return py::array_t<unsigned char>({h, w, size_t{3}}, {w * 3, size_t{3}, size_t{1}}, rgb->data(), owner);
}

}  // namespace

void BindRender(py::module_& m) {
  m.def("_render_frame", &RenderFrame, py::arg("q_hip"), py::arg("q_knee"), py::arg("params"), py::arg("width"),
        py::arg("height"));
}

}  // namespace exotwin::python
