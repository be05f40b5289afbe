// An OSMesa (software, off-screen) OpenGL context: no display, no X server, no GPU needed.
// Debian's libmujoco.so.2.2.2 links no GL library (no GLEW, no GLX in its DT_NEEDED). Its built-in
// glad loader (src/render/glad/glad.c) looks, at the first mjr_makeContext, for a GetProcAddress
// already visible in the process in this order: eglGetProcAddress, OSMesaGetProcAddress,
// glXGetProcAddressARB (then walks loaded DSOs with dl_iterate_phdr). The rendering plugin links
// libOSMesa but is opened RTLD_LOCAL (render/render_plugin.h), so the first context promotes
// libOSMesa to the global scope (dlopen RTLD_NOLOAD | RTLD_GLOBAL): OSMesa then wins over the
// libGLX.so.0 that OpenCV pulls in; it would lose to a globally loaded libEGL.
// No DISPLAY or MUJOCO_GL is needed. Rendering is llvmpipe (Mesa 22.3, GL 4.5 compatibility).
#pragma once

namespace exotwin {

class OsMesaContext {
 public:
  // Creates an RGBA context (24-bit depth, 8-bit stencil) with a width x height (px, > 0) buffer and
  // makes it current on the calling thread. Throws std::runtime_error if OSMesa fails.
  OsMesaContext(int width, int height);
  ~OsMesaContext();
  OsMesaContext(const OsMesaContext&) = delete;
  OsMesaContext& operator=(const OsMesaContext&) = delete;

  // Makes this context current on the calling thread (call before any mjr_* if several exist).
  void MakeCurrent();

 private:
  void* ctx_ = nullptr;  // OSMesaContext
  unsigned char* buffer_ = nullptr;
  int width_, height_;
};

}  // namespace exotwin
