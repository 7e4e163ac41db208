#pragma once
/// @file
/// A headless OpenGL context through EGL (Mesa's surfaceless platform: no display, no window, no
/// X server), for rendering offscreen with MuJoCo's renderer on a machine without a screen.

#include <stdexcept>

namespace rigger::sim {

/// EGL or desktop OpenGL is not available here (no libEGL driver, no surfaceless platform, no
/// OpenGL-capable config). what() names the EGL call that failed and its error code.
class GlUnavailableError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An EGL display on the surfaceless platform with a desktop OpenGL context, current on the
/// constructing thread. OpenGL contexts are bound to one thread: create it on the thread that
/// renders, and render only there. Not copyable or movable; the destructor releases the context
/// and never throws.
class EglContext {
 public:
  /// Creates the context and makes it current on the calling thread (no surface: render into
  /// framebuffer objects). @throws GlUnavailableError
  EglContext();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  /// Makes the context current on the calling thread again (after another context was).
  /// @throws GlUnavailableError
  void make_current();

  /// The OpenGL renderer string (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
  const char* renderer() const;

 private:
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
};

}  // namespace rigger::sim
