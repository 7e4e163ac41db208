#include "rigger/sim/egl_context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>

#include <cstdio>
#include <string>

namespace rigger::sim {
namespace {

[[noreturn]] void fail(const std::string& what) {
  char code[16];
  std::snprintf(code, sizeof code, "0x%04X", static_cast<unsigned>(eglGetError()));
  throw GlUnavailableError("headless OpenGL (EGL, Mesa surfaceless platform): " + what + " failed with EGL error " +
                           code + "; is libegl1 with a Mesa driver (libegl-mesa0, libgl1-mesa-dri) installed?");
}

}  // namespace

EglContext::EglContext() {
  // The surfaceless platform needs no display server; eglGetDisplay(EGL_DEFAULT_DISPLAY) would
  // try X11 or Wayland first.
  const auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr) {
    fail("eglGetProcAddress(\"eglGetPlatformDisplayEXT\")");
  }
  EGLDisplay display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) {
    fail("eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA)");
  }
  EGLint major = 0;
  EGLint minor = 0;
  if (eglInitialize(display, &major, &minor) != EGL_TRUE) {
    fail("eglInitialize");
  }
  display_ = display;
  const EGLint attributes[] = {EGL_SURFACE_TYPE, 0, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint configs = 0;
  if (eglChooseConfig(display, attributes, &config, 1, &configs) != EGL_TRUE || configs < 1) {
    eglTerminate(display);
    fail("eglChooseConfig (a desktop OpenGL config without surface)");
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    eglTerminate(display);
    fail("eglBindAPI(EGL_OPENGL_API)");
  }
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, nullptr);
  if (context == EGL_NO_CONTEXT) {
    eglTerminate(display);
    fail("eglCreateContext");
  }
  context_ = context;
  if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) != EGL_TRUE) {
    eglDestroyContext(display, context);
    eglTerminate(display);
    fail("eglMakeCurrent (no surface)");
  }
}

EglContext::~EglContext() {
  // The display is not terminated: EGL hands every caller the same display for the same platform,
  // and eglTerminate would invalidate the contexts of the other rendering threads.
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display_, context_);
}

void EglContext::make_current() {
  if (eglGetCurrentContext() == context_) {
    return;
  }
  if (eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE) {
    fail("eglMakeCurrent (no surface)");
  }
}

const char* EglContext::renderer() const {
  const GLubyte* name = glGetString(GL_RENDERER);
  return name != nullptr ? reinterpret_cast<const char*>(name) : "(unknown)";
}

}  // namespace rigger::sim
