#include "glcontext.h"

#include <dlfcn.h>

namespace refhost {

namespace {

// EGL 1.5 and GL 1.1 constants (egl.h, eglext.h, gl.h), written out so the
// reference host needs neither header.
const int kEglNone = 0x3038, kEglSurfaceType = 0x3033, kEglPbufferBit = 0x0001,
          kEglRenderableType = 0x3040, kEglOpenGlBit = 0x0008, kEglRedSize = 0x3024,
          kEglGreenSize = 0x3023, kEglBlueSize = 0x3022, kEglAlphaSize = 0x3021,
          kEglWidth = 0x3057, kEglHeight = 0x3056;
const unsigned kEglOpenGlApi = 0x30A2, kEglPlatformSurfacelessMesa = 0x31DD;
const unsigned kGlBlend = 0x0BE2, kGlLineStipple = 0x0B24, kGlLineWidth = 0x0B21,
               kGlCurrentColor = 0x0B00, kGlProjection = 0x1701, kGlModelview = 0x1700,
               kGlColorBufferBit = 0x4000, kGlRgba = 0x1908, kGlFloat = 0x1406;

using Display = void *(*)(unsigned, void *, const long *);
using Initialize = unsigned (*)(void *, int *, int *);
using BindApi = unsigned (*)(unsigned);
using ChooseConfig = unsigned (*)(void *, const int *, void **, int, int *);
using CreatePbuffer = void *(*)(void *, void *, const int *);
using CreateContext = void *(*)(void *, void *, void *, const int *);
using MakeCurrent = unsigned (*)(void *, void *, void *, void *);
using Destroy = unsigned (*)(void *, void *);
using Terminate = unsigned (*)(void *);

template <class F>
F sym(void *lib, const char *name) {
  return lib ? reinterpret_cast<F>(dlsym(lib, name)) : nullptr;
}

}  // namespace

bool GlContext::fail(const std::string &why) {
  _why = why;
  return false;
}

GlContext::GlContext(int width, int height) : _width(width), _height(height) {
  // Both libraries stay loaded in the process, as a host's do: the bundle
  // finds libGL there rather than loading its own.
  _egl = dlopen("libEGL.so.1", RTLD_NOW | RTLD_GLOBAL);
  _gl = dlopen("libGL.so.1", RTLD_NOW | RTLD_GLOBAL);
  if (!_egl || !_gl) {
    fail("no libEGL.so.1 or libGL.so.1 (apt-get install libegl1 libgl1 libegl-mesa0)");
    return;
  }
  auto display = sym<Display>(_egl, "eglGetPlatformDisplay");
  auto initialize = sym<Initialize>(_egl, "eglInitialize");
  auto bind = sym<BindApi>(_egl, "eglBindAPI");
  auto choose = sym<ChooseConfig>(_egl, "eglChooseConfig");
  auto pbuffer = sym<CreatePbuffer>(_egl, "eglCreatePbufferSurface");
  auto create = sym<CreateContext>(_egl, "eglCreateContext");
  auto current = sym<MakeCurrent>(_egl, "eglMakeCurrent");
  if (!display || !initialize || !bind || !choose || !pbuffer || !create || !current) {
    fail("libEGL.so.1 lacks EGL 1.5");
    return;
  }
  int major = 0, minor = 0;
  _display = display(kEglPlatformSurfacelessMesa, nullptr, nullptr);
  if (!_display || !initialize(_display, &major, &minor)) {
    fail("no EGL display on Mesa's surfaceless platform (apt-get install libegl-mesa0)");
    return;
  }
  const int want[] = {kEglSurfaceType, kEglPbufferBit, kEglRenderableType, kEglOpenGlBit,
                      kEglRedSize,     8,              kEglGreenSize,      8,
                      kEglBlueSize,    8,              kEglAlphaSize,      8,
                      kEglNone};
  void *config = nullptr;
  int configs = 0;
  if (!bind(kEglOpenGlApi) || !choose(_display, want, &config, 1, &configs) || configs < 1) {
    fail("no EGL config for desktop OpenGL in an RGBA8 pbuffer");
    return;
  }
  const int size[] = {kEglWidth, width, kEglHeight, height, kEglNone};
  _surface = pbuffer(_display, config, size);
  _context = create(_display, config, nullptr, nullptr);
  if (!_surface || !_context || !current(_display, _surface, _surface, _context)) {
    fail("could not make an EGL pbuffer context current");
    return;
  }
  _ready = true;
}

GlContext::~GlContext() {
  if (!_display) return;
  if (auto current = sym<MakeCurrent>(_egl, "eglMakeCurrent"))
    current(_display, nullptr, nullptr, nullptr);
  if (_context)
    if (auto destroy = sym<Destroy>(_egl, "eglDestroyContext")) destroy(_display, _context);
  if (_surface)
    if (auto destroy = sym<Destroy>(_egl, "eglDestroySurface")) destroy(_display, _surface);
  if (auto terminate = sym<Terminate>(_egl, "eglTerminate")) terminate(_display);
}

void GlContext::viewerFrame(double canonicalWidth, double canonicalHeight, Rgba clear) {
  sym<void (*)(int, int, int, int)>(_gl, "glViewport")(0, 0, _width, _height);
  auto mode = sym<void (*)(unsigned)>(_gl, "glMatrixMode");
  auto identity = sym<void (*)()>(_gl, "glLoadIdentity");
  mode(kGlModelview);
  identity();
  mode(kGlProjection);
  identity();
  sym<void (*)(double, double, double, double, double, double)>(_gl, "glOrtho")(
      0, canonicalWidth, 0, canonicalHeight, -1, 1);
  sym<void (*)(float, float, float, float)>(_gl, "glClearColor")(clear.r, clear.g, clear.b,
                                                                 clear.a);
  sym<void (*)(unsigned)>(_gl, "glClear")(kGlColorBufferBit);
  sym<void (*)(float, float, float, float)>(_gl, "glColor4f")(0.1f, 0.2f, 0.3f, 0.4f);
  sym<void (*)(float)>(_gl, "glLineWidth")(1.0f);
}

Rgba GlContext::pixel(int x, int y) const {
  sym<void (*)()>(_gl, "glFinish")();
  Rgba p = {0, 0, 0, 0};
  sym<void (*)(int, int, int, int, unsigned, unsigned, void *)>(_gl, "glReadPixels")(
      x, y, 1, 1, kGlRgba, kGlFloat, &p);
  return p;
}

bool GlContext::blendEnabled() const {
  return sym<unsigned char (*)(unsigned)>(_gl, "glIsEnabled")(kGlBlend);
}

bool GlContext::stippleEnabled() const {
  return sym<unsigned char (*)(unsigned)>(_gl, "glIsEnabled")(kGlLineStipple);
}

float GlContext::lineWidth() const {
  float w = 0;
  sym<void (*)(unsigned, float *)>(_gl, "glGetFloatv")(kGlLineWidth, &w);
  return w;
}

Rgba GlContext::currentColour() const {
  Rgba c = {0, 0, 0, 0};
  sym<void (*)(unsigned, float *)>(_gl, "glGetFloatv")(kGlCurrentColor, &c.r);
  return c;
}

}  // namespace refhost
