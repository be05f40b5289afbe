#include "render/osmesa_context.h"

#include <GL/osmesa.h>
#include <dlfcn.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace exotwin {
namespace {

// Puts the already loaded libOSMesa into the process's global symbol scope (see osmesa_context.h),
// once: the rendering plugin is opened RTLD_LOCAL, which hides its libraries from MuJoCo's loader.
void MakeOsMesaGlobal() {
  static const bool done = [] {
    Dl_info info{};
    if (!dladdr(reinterpret_cast<void*>(&OSMesaGetProcAddress), &info) || !info.dli_fname)
      throw std::runtime_error("render: cannot locate libOSMesa in this process");
    if (!dlopen(info.dli_fname, RTLD_LAZY | RTLD_NOLOAD | RTLD_GLOBAL))
      throw std::runtime_error(std::string("render: cannot make ") + info.dli_fname + " global: " + dlerror());
    return true;
  }();
  (void)done;
}

}  // namespace

OsMesaContext::OsMesaContext(int width, int height) : width_(width), height_(height) {
  if (width <= 0 || height <= 0)
    throw std::runtime_error("render: OSMesa buffer size must be positive, got " +
                             std::to_string(width) + "x" + std::to_string(height));
  MakeOsMesaGlobal();
  ctx_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (!ctx_) throw std::runtime_error("render: OSMesaCreateContextExt failed (is libosmesa6 installed?)");
  buffer_ = static_cast<unsigned char*>(std::calloc(static_cast<size_t>(width) * height, 4));
  if (!buffer_) {
    OSMesaDestroyContext(static_cast<OSMesaContext>(ctx_));
    throw std::runtime_error("render: cannot allocate the OSMesa buffer");
  }
  try {
    MakeCurrent();
  } catch (...) {
    OSMesaDestroyContext(static_cast<OSMesaContext>(ctx_));
    std::free(buffer_);
    throw;
  }
}

OsMesaContext::~OsMesaContext() {
  if (OSMesaGetCurrentContext() == static_cast<OSMesaContext>(ctx_))
    OSMesaMakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
  OSMesaDestroyContext(static_cast<OSMesaContext>(ctx_));
  std::free(buffer_);
}

void OsMesaContext::MakeCurrent() {
  if (OSMesaGetCurrentContext() == static_cast<OSMesaContext>(ctx_)) return;
  if (!OSMesaMakeCurrent(static_cast<OSMesaContext>(ctx_), buffer_, GL_UNSIGNED_BYTE, width_, height_))
    throw std::runtime_error("render: OSMesaMakeCurrent failed");
}

}  // namespace exotwin
