// An offscreen OpenGL context, as a host's viewer has one current while it
// calls an overlay's draw action: EGL on Mesa's surfaceless platform (no X
// server, no GPU: llvmpipe draws), desktop GL with the compatibility
// profile so GL 1.1 immediate mode works. EGL and GL are opened at run time
// (dlopen), so the reference host builds and runs where neither is
// installed and simply skips the GL check there.
#pragma once

#include <string>

namespace refhost {

struct Rgba {
  float r, g, b, a;
};

class GlContext {
 public:
  /// A `width` x `height` pbuffer context, current on this thread, or one
  /// that is not `ready()` with `why()` it is not.
  GlContext(int width, int height);
  ~GlContext();
  GlContext(const GlContext &) = delete;
  GlContext &operator=(const GlContext &) = delete;

  bool ready() const { return _ready; }
  const std::string &why() const { return _why; }

  /// As a viewer sets up before an overlay draws: the viewport is the whole
  /// buffer and the projection maps canonical [0, w] x [0, h] onto it;
  /// cleared to `clear`, current colour and line width set to odd values.
  void viewerFrame(double canonicalWidth, double canonicalHeight, Rgba clear);
  /// The pixel at (x, y), counted from the bottom-left, after a glFinish.
  Rgba pixel(int x, int y) const;
  /// GL state the overlay must leave as it found it.
  bool blendEnabled() const;
  bool stippleEnabled() const;
  float lineWidth() const;
  Rgba currentColour() const;

 private:
  bool fail(const std::string &why);
  void *_egl = nullptr, *_gl = nullptr;
  void *_display = nullptr, *_surface = nullptr, *_context = nullptr;
  int _width, _height;
  bool _ready = false;
  std::string _why;
};

}  // namespace refhost
