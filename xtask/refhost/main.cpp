// morphfx-refhost BUNDLE_DIR: loads MorphFX.ofx.bundle from BUNDLE_DIR with
// the OpenFX reference host library, then, for each node and each context
// it must support, creates an instance, checks what the spec mandates in
// that context, asks for identity where the answer is known, and renders
// every warp method at render scale 1 and 0.5 in float and 8-bit (in
// float also in four tiles, each held to the whole frame's bits), and
// drives each node's overlay (draw, a drag that moves a line, shapes, a
// grid made with Reset Grid and a node of it dragged; drawn in
// an offscreen OpenGL context too, where Mesa's EGL is there). Exit
// status 0 when every check passed, 1 with the failures listed otherwise.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include "glcontext.h"
#include "refhost.h"

using namespace refhost;
namespace IE = OFX::Host::ImageEffect;

namespace {

struct Node {
  const char *id;
  std::vector<std::string> contexts;
};

const Node kNodes[] = {
    {"net.morphfx.Warp",
     {kOfxImageEffectContextFilter, kOfxImageEffectContextGeneral}},
    {"net.morphfx.Morph",
     {kOfxImageEffectContextGeneral, kOfxImageEffectContextTransition}},
};

std::string statusName(OfxStatus s) {
  switch (s) {
    case kOfxStatOK: return "OK";
    case kOfxStatFailed: return "Failed";
    case kOfxStatErrFatal: return "ErrFatal";
    case kOfxStatErrUnknown: return "ErrUnknown";
    case kOfxStatErrMissingHostFeature: return "ErrMissingHostFeature";
    case kOfxStatErrUnsupported: return "ErrUnsupported";
    case kOfxStatErrExists: return "ErrExists";
    case kOfxStatErrFormat: return "ErrFormat";
    case kOfxStatErrMemory: return "ErrMemory";
    case kOfxStatErrBadHandle: return "ErrBadHandle";
    case kOfxStatErrBadIndex: return "ErrBadIndex";
    case kOfxStatErrValue: return "ErrValue";
    case kOfxStatReplyDefault: return "ReplyDefault";
    default: return "status " + std::to_string(s);
  }
}

/// What every check names in its message: node, context, depth, method.
struct Where {
  std::string text;
  Where with(const std::string &more) const { return {text + ", " + more}; }
};

void expectOk(OfxStatus s, const Where &w, const char *action) {
  if (s != kOfxStatOK && s != kOfxStatReplyDefault)
    fail(w.text + ": " + action + " returned " + statusName(s));
}

/// The clips the spec mandates in `context`, inputs first.
std::vector<std::string> mandatedClips(const std::string &context) {
  if (context == kOfxImageEffectContextFilter) return {"Source", "Output"};
  if (context == kOfxImageEffectContextTransition)
    return {"SourceFrom", "SourceTo", "Output"};
  return {"Output"};
}

/// The source clips, inputs first; the optional mattes are not sources.
std::vector<std::string> inputClips(IE::Instance &fx) {
  std::vector<std::string> names;
  for (auto *d : fx.getDescriptor().getClipsByOrder()) {
    const std::string &n = d->getName();
    if (n != "Output" && n != "Mask" && n != "Timing") names.push_back(n);
  }
  return names;
}

/// The param that drives the morph's t: the host's in a transition.
std::string progressParam(const std::string &context) {
  return context == kOfxImageEffectContextTransition ? "Transition" : "progress";
}

bool setDouble(IE::Instance &fx, const std::string &name, double v) {
  auto *p = dynamic_cast<OFX::Host::Param::DoubleInstance *>(fx.getParam(name));
  return p && p->set(v) == kOfxStatOK;
}

/// A scene: one more line, and what only a scene can give (the mesh); the
/// node's own settings win over the scene's.
void loadScene(IE::Instance &fx, const Where &w) {
  static const char *scene =
      "{\"format\": \"morphfx-scene\", \"version\": 1, "
      " \"features\": [{\"type\": \"line\", \"a\": [[60,50],[80,50]], \"b\": [[62,48],[82,53]]}],"
      " \"mesh\": {\"rows\": 3, \"cols\": 3,"
      " \"a\": [[0,0],[48,0],[96,0], [0,32],[48,32],[96,32], [0,64],[48,64],[96,64]],"
      " \"b\": [[0,0],[48,0],[96,0], [0,32],[56,38],[96,32], [0,64],[48,64],[96,64]]}}";
  auto *text = dynamic_cast<OFX::Host::Param::StringInstance *>(fx.getParam("scene_text"));
  auto *own = dynamic_cast<OFX::Host::Param::BooleanInstance *>(
      fx.getParam("settings_from_scene"));
  if (!text || !own) return fail(w.text + ": no scene_text or settings_from_scene param");
  text->set(scene);
  own->set(false);
}

/// Two line pairs in the line slots: the morph moves something.
void keyLines(IE::Instance &fx, const Where &w) {
  const double lines[2][8] = {{20, 20, 70, 22, 26, 28, 76, 24},
                              {30, 50, 30, 10, 36, 48, 40, 12}};
  auto *count = dynamic_cast<OFX::Host::Param::IntegerInstance *>(fx.getParam("line_count"));
  if (!count) return fail(w.text + ": no integer param line_count");
  count->set(2);
  for (int k = 0; k < 2; ++k) {
    const std::string slot = "line" + std::to_string(k + 1);
    auto *on = dynamic_cast<OFX::Host::Param::BooleanInstance *>(
        fx.getParam(slot + "_enable"));
    if (!on) return fail(w.text + ": no param " + slot + "_enable");
    on->set(true);
    const char *ends[4] = {"_a_start", "_a_end", "_b_start", "_b_end"};
    for (int e = 0; e < 4; ++e) {
      auto *p = dynamic_cast<OFX::Host::Param::Double2DInstance *>(
          fx.getParam(slot + ends[e]));
      if (!p) return fail(w.text + ": no 2D param " + slot + ends[e]);
      p->set(lines[k][2 * e], lines[k][2 * e + 1]);
    }
  }
}

/// Mean RGBA of a render, or nothing when the render failed a check.
struct Render {
  bool ok = false;
  double mean[4] = {0, 0, 0, 0};
};

/// One frame as a host renders it: region of definition, identity,
/// begin, regions of interest, render, end. Then the output is read back.
/// `interactive`: a viewer's render while the instance is manipulated
/// (not sequential); otherwise one frame of a sequential render. `tile`:
/// render only that window of the frame, as a host that renders in tiles
/// does (a tile may rightly be an identity; that is not asked).
Render render(Effect &fx, OfxPointD scale, const Where &w, bool interactive = false,
              const OfxRectI *tile = nullptr) {
  Render out;
  const OfxTime t = 0;
  fx.renderScale = scale;
  OfxRectD rod;
  OfxStatus s = fx.getRegionOfDefinitionAction(t, scale, rod);
  expectOk(s, w, "getRegionOfDefinition");
  if (s != kOfxStatOK && s != kOfxStatReplyDefault) return out;
  fx.renderWindow = tile ? *tile : toPixels(rod, scale);
  OfxRectI &win = fx.renderWindow;
  if (win.x2 <= win.x1 || win.y2 <= win.y1) {
    fail(w.text + ": empty region of definition");
    return out;
  }
  if (!tile) {
    OfxTime idTime = t;
    std::string idClip;
    s = fx.isIdentityAction(idTime, kOfxImageFieldNone, win, scale, idClip);
    if (s == kOfxStatOK) {
      fail(w.text + ": identity (" + idClip + ") where the morph moves pixels");
      return out;
    }
    expectOk(s, w, "isIdentity");
  }
  expectOk(fx.beginRenderAction(t, t, 1, interactive, scale, !interactive, interactive), w,
           "beginSequenceRender");
  fx.regionsOfInterest.clear();
  expectOk(fx.getRegionOfInterestAction(t, scale, rod, fx.regionsOfInterest), w,
           "getRegionsOfInterest");
  fx.persistentError.clear();
  fx.rendering = true;
  s = fx.renderAction(t, kOfxImageFieldNone, win, scale, !interactive, interactive, false);
  fx.rendering = false;
  expectOk(fx.endRenderAction(t, t, 1, interactive, scale, !interactive, interactive), w,
           "endSequenceRender");
  if (s != kOfxStatOK) {
    fail(w.text + ": render returned " + statusName(s) + " (" +
         fx.persistentError + ")");
    return out;
  }
  if (!fx.persistentError.empty())
    fail(w.text + ": render succeeded but left an error: " + fx.persistentError);
  auto *clip = dynamic_cast<Clip *>(fx.getClip("Output"));
  if (!clip || !clip->output) {
    fail(w.text + ": render never fetched the output image");
    return out;
  }
  const Pixels &px = *clip->output;
  long n = 0;
  for (int y = win.y1; y < win.y2; ++y)
    for (int x = win.x1; x < win.x2; ++x, ++n)
      for (int c = 0; c < 4; ++c) {
        const float v = px.at(x, y, c);
        if (!std::isfinite(v) || v < -0.25f || v > 1.25f) {
          std::ostringstream m;
          m << w.text << ": output pixel (" << x << ", " << y << ") channel "
            << c << " is " << v << " (unwritten or out of range)";
          fail(m.str());
          return out;
        }
        out.mean[c] += v;
      }
  for (double &m : out.mean) m /= double(n);
  out.ok = true;
  return out;
}

/// The output pixels of the last render, as floats (RGBA, row by row).
std::vector<float> outputPixels(Effect &fx) {
  std::vector<float> v;
  auto *clip = dynamic_cast<Clip *>(fx.getClip("Output"));
  if (!clip || !clip->output) return v;
  const OfxRectI &b = fx.renderWindow;
  for (int y = b.y1; y < b.y2; ++y)
    for (int x = b.x1; x < b.x2; ++x)
      for (int c = 0; c < 4; ++c) v.push_back(clip->output->at(x, y, c));
  return v;
}

/// The Mask (and on Morph the Timing) clip connected through the library:
/// at render scale 1 the masked picture is `src + (effect - src) * mix * m`
/// pixel for pixel, src Source A and m the mask's alpha; the timing matte
/// changes the picture; at scale 0.5 both render, their means close to
/// scale 1's (render's own checks).
void checkMattes(Effect &fx, const Where &w) {
  const std::vector<std::string> inputs = inputClips(fx);
  const OfxPointD one = {1, 1};
  const Render plain = render(fx, one, w.with("no mattes"));
  const std::vector<float> effect = outputPixels(fx);
  if (!plain.ok) return;
  auto *mix = dynamic_cast<OFX::Host::Param::DoubleInstance *>(fx.getParam("mix"));
  if (!mix) return fail(w.text + ": no double param mix");
  mix->set(0.5);
  fx.maskConnected = true;
  const Where wm = w.with("Mask, mix 0.5");
  const Render masked = render(fx, one, wm.with("scale 1"));
  const std::vector<float> got = outputPixels(fx);
  if (masked.ok && got.size() == effect.size()) {
    const OfxRectI &b = fx.renderWindow;
    size_t k = 0;
    int bad = 0;
    for (int y = b.y1; y < b.y2; ++y)
      for (int x = b.x1; x < b.x2; ++x)
        for (int c = 0; c < 4; ++c, ++k) {
          const double px = x + 0.5, py = y + 0.5;
          const float src = sourceValue(inputs[0], px, py, c);
          const float m = sourceValue("Mask", px, py, 3);
          const float want = src + (effect[k] - src) * 0.5f * m;
          if (std::fabs(got[k] - want) > 1e-4f && bad++ == 0) {
            std::ostringstream msg;
            msg << wm.text << ": pixel (" << x << ", " << y << ") channel " << c << " is "
                << got[k] << ", not " << want << " (effect " << effect[k] << ", source "
                << src << ", mask " << m << ")";
            fail(msg.str());
          }
        }
  }
  render(fx, {0.5, 0.5}, wm.with("scale 0.5"));
  mix->set(1.0);
  fx.maskConnected = false;
  if (fx.getClip("Timing")) {
    fx.timingConnected = true;
    const Where wt = w.with("Timing");
    const Render timed = render(fx, one, wt.with("scale 1"));
    const Render half = render(fx, {0.5, 0.5}, wt.with("scale 0.5"));
    bool differs = false;
    for (int c = 0; c < 3; ++c) differs |= std::fabs(timed.mean[c] - plain.mean[c]) > 1e-3;
    if (timed.ok && !differs) fail(wt.text + ": the timing matte changed nothing");
    for (int c = 0; c < 4; ++c)
      if (timed.ok && half.ok && std::fabs(timed.mean[c] - half.mean[c]) > 0.03)
        fail(wt.text + ": channel means differ between scale 1 and 0.5");
    fx.timingConnected = false;
  }
}

/// At the ends of the morph the node passes a source through, and says so.
void checkIdentity(Effect &fx, const std::string &context, const Where &w) {
  const std::vector<std::string> inputs = inputClips(fx);
  const bool isMorph = inputs.size() >= 2;
  const std::string progress = progressParam(context);
  const OfxPointD scale = {1, 1};
  fx.renderScale = scale;
  const OfxRectI win = {0, 0, kProjectWidth, kProjectHeight};
  struct Case {
    double t;
    std::string clip;
  };
  std::vector<Case> cases = {{0.0, inputs[0]}};
  if (isMorph) cases.push_back({1.0, inputs[1]});
  for (const Case &c : cases) {
    setDouble(fx, progress, c.t);
    OfxTime time = 0;
    std::string clip;
    const OfxStatus s =
        fx.isIdentityAction(time, kOfxImageFieldNone, win, scale, clip);
    std::ostringstream at;
    at << progress << " = " << c.t;
    if (s != kOfxStatOK || clip != c.clip || time != 0)
      fail(w.with(at.str()).text + ": isIdentity answered " + statusName(s) +
           " '" + clip + "' at time " + std::to_string(time) + ", expected '" +
           c.clip + "' at time 0");
  }
  setDouble(fx, progress, 0.5);
}

int choiceCount(IE::Instance &fx, const std::string &name) {
  auto *p = fx.getParam(name);
  return p ? p->getProperties().getDimension(kOfxParamPropChoiceOption) : 0;
}

/// A viewer dragging one of ten lines (`field` method), as the library
/// sends it (`kOfxImageEffectPropInteractiveRenderStatus` 1, not
/// sequential): interactive renders after each move, where the plugin may
/// redo its maps from the last ones, end at the picture a sequential
/// render of the same lines makes afresh, within 0.01 (a hundredth of the
/// unit range). The redo swaps the moved line's terms in every block here,
/// near ones included, and remakes only those whose weights refuse the
/// swap; its distance from the exact map at 320 × 180 is held by the
/// harness's `tests/drag.rs`.
void checkDrag(Effect &fx, const Where &w) {
  auto *text = dynamic_cast<OFX::Host::Param::StringInstance *>(fx.getParam("scene_text"));
  auto *method = dynamic_cast<OFX::Host::Param::ChoiceInstance *>(fx.getParam("method"));
  if (!text || !method) return fail(w.text + ": no scene_text or method param");
  for (int m = 0; m < choiceCount(fx, "method"); ++m)
    if (method->getProperties().getStringProperty(kOfxParamPropChoiceOption, m) == "field")
      method->set(m);
  const auto scene = [](double dx) {
    std::ostringstream s;
    s << "{\"format\": \"morphfx-scene\", \"version\": 1, \"features\": [";
    for (int k = 0; k < 8; ++k) {
      const double x = 8 + 11 * k, y = 10 + 6 * k;
      s << (k ? ", " : "") << "{\"type\": \"line\", \"a\": [[" << x + (k ? 0 : dx) << ", "
        << y << "], [" << x + 6 << ", " << y + 14 << "]], \"b\": [[" << x + 2 << ", " << y - 1
        << "], [" << x + 7 << ", " << y + 15 << "]]}";
    }
    s << "]}";
    return s.str();
  };
  const OfxPointD one = {1, 1};
  std::vector<float> viewer;
  for (int step = 0; step < 4; ++step) {
    text->set(scene(1.5 * step).c_str());
    if (!render(fx, one, w.with("interactive, move " + std::to_string(step)), true).ok) return;
    viewer = outputPixels(fx);
  }
  if (!render(fx, one, w.with("sequential")).ok) return;
  const std::vector<float> fresh = outputPixels(fx);
  if (fresh.size() != viewer.size()) return fail(w.text + ": renders of different sizes");
  float worst = 0;
  for (size_t k = 0; k < fresh.size(); ++k)
    worst = std::max(worst, std::fabs(fresh[k] - viewer[k]));
  if (worst > 0.01f) {
    std::ostringstream m;
    m << w.text << ": the interactive render after the drag differs by " << worst
      << " from a sequential render of the same lines";
    fail(m.str());
  }
  std::cout << "refhost: " << w.text << ": largest difference " << worst << std::endl;
}

/// The overlay as the library's own interact classes drive it.
class Overlay : public IE::OverlayInteract {
 public:
  explicit Overlay(IE::Instance &fx) : IE::OverlayInteract(fx) {}
  int redraws = 0;
  void getViewportSize(double &w, double &h) const override {
    w = kProjectWidth, h = kProjectHeight;
  }
  void getPixelScale(double &x, double &y) const override { x = 1, y = 1; }
  void getBackgroundColour(double &r, double &g, double &b) const override {
    r = g = b = 0;
  }
  bool getSuggestedColour(double &, double &, double &) const override { return false; }
  OfxStatus swapBuffers() override {
    fail("an overlay swapped buffers (the host does)");
    return kOfxStatFailed;
  }
  OfxStatus redraw() override { return ++redraws, kOfxStatOK; }
};

/// The overlay in a host with no OpenGL context and no Draw suite: draw
/// succeeds (drawing nothing), and a drag moves the grabbed end of line 1
/// on A (at (70, 22), keyed by keyLines) to where the pen lets go.
void checkOverlay(Effect &fx, const Where &w) {
  if (!fx.getOverlayInteractMainEntry())
    return fail(w.text + ": no overlay interact entry");
  Overlay ov(fx);
  expectOk(ov.createInstanceAction(), w, "overlay createInstance");
  const OfxPointD scale = {1, 1};
  expectOk(ov.drawAction(0, scale), w, "overlay draw");
  const OfxPointD from = {70, 22}, to = {60, 30};
  const OfxPointI vp = {0, 0};
  expectOk(ov.penDownAction(0, scale, from, vp, 1), w, "overlay pen down");
  expectOk(ov.penMotionAction(0, scale, to, vp, 1), w, "overlay pen motion");
  expectOk(ov.penUpAction(0, scale, to, vp, 0), w, "overlay pen up");
  auto *end = dynamic_cast<OFX::Host::Param::Double2DInstance *>(fx.getParam("line1_a_end"));
  double x = 0, y = 0;
  if (!end || end->get(x, y) != kOfxStatOK || x != to.x || y != to.y) {
    std::ostringstream m;
    m << w.text << ": overlay drag left line1_a_end at (" << x << ", " << y
      << "), not (60, 30)";
    fail(m.str());
  }
  // Clear Line on slot 2: turned off, and Line Count back to 1.
  expectOk(fx.beginInstanceChangedAction(kOfxChangeUserEdited), w, "beginInstanceChanged");
  expectOk(fx.paramInstanceChangedAction("line2_clear", kOfxChangeUserEdited, 0, scale), w,
           "instanceChanged line2_clear");
  expectOk(fx.endInstanceChangedAction(kOfxChangeUserEdited), w, "endInstanceChanged");
  auto *on = dynamic_cast<OFX::Host::Param::BooleanInstance *>(fx.getParam("line2_enable"));
  auto *count = dynamic_cast<OFX::Host::Param::IntegerInstance *>(fx.getParam("line_count"));
  bool enabled = true;
  int lines = 0;
  if (!on || !count || on->get(enabled) != kOfxStatOK || count->get(lines) != kOfxStatOK ||
      enabled || lines != 1)
    fail(w.text + ": Clear Line left line 2 enabled or Line Count not 1");
  // Back as keyLines left them, for the renders that follow.
  if (end) end->set(from.x, from.y);
  keyLines(fx, w);
}

/// Whether some pixel within 2 of (x, y) has the hue of `colour` (the
/// overlay's lines are anti-aliased over the background, so not its value).
bool hueNear(const GlContext &gl, int x, int y, bool orange) {
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      const Rgba p = gl.pixel(x + dx, y + dy);
      const bool is = orange ? p.r > p.g && p.g > p.b && p.r - p.b > 0.4f
                             : p.b > p.g && p.g > p.r && p.b - p.r > 0.4f;
      if (is) return true;
    }
  return false;
}

/// The overlay in a viewer with an OpenGL context current, no Draw suite,
/// zoomed to 2 screen pixels per canonical unit while the host reports a
/// pixel scale of (1, 1), as some hosts do at every zoom. Line 1's A (orange)
/// and B (blue) are drawn where they are, nothing is drawn away from the
/// lines, the GL state is left as found, and the pen's hit radius follows
/// the zoom the projection shows: 6.5 units from an end is 13 screen pixels,
/// outside the 8-pixel radius, so a click there grabs nothing.
void checkOverlayGl(Effect &fx, const Where &w) {
  const int zoom = 2;
  GlContext gl(kProjectWidth * zoom, kProjectHeight * zoom);
  if (!gl.ready()) {
    static bool said = false;
    if (!said) std::cout << "refhost: GL overlay check SKIPPED: " << gl.why() << std::endl;
    said = true;
    return;
  }
  gl.viewerFrame(kProjectWidth, kProjectHeight, {0.2f, 0.2f, 0.2f, 1});
  Overlay ov(fx);
  expectOk(ov.createInstanceAction(), w, "overlay createInstance");
  const OfxPointD scale = {1, 1};
  expectOk(ov.drawAction(0, scale), w, "overlay draw");
  // Line 1 (keyLines): A (20, 20) - (70, 22), B (26, 28) - (76, 24).
  if (!hueNear(gl, 45 * zoom, 21 * zoom, true))
    fail(w.text + ": line 1's A is not drawn orange at its middle (45, 21)");
  if (!hueNear(gl, 51 * zoom, 26 * zoom, false))
    fail(w.text + ": line 1's B is not drawn blue at its middle (51, 26)");
  const Rgba empty = gl.pixel(90 * zoom, 5 * zoom);
  if (std::fabs(empty.r - 0.2f) > 0.004f || std::fabs(empty.g - 0.2f) > 0.004f ||
      std::fabs(empty.b - 0.2f) > 0.004f) {
    std::ostringstream m;
    m << w.text << ": the overlay drew at (90, 5), far from every line: (" << empty.r << ", "
      << empty.g << ", " << empty.b << ")";
    fail(m.str());
  }
  const Rgba c = gl.currentColour();
  if (gl.blendEnabled() || gl.stippleEnabled() || gl.lineWidth() != 1.0f ||
      c.r != 0.1f || c.g != 0.2f || c.b != 0.3f || c.a != 0.4f)
    fail(w.text + ": the overlay's draw left GL state changed (blend, stipple, width, colour)");

  const OfxPointD near = {20, 13.5}, nudge = {20.5, 13.8};
  const OfxPointI vp = {0, 0};
  expectOk(ov.penDownAction(0, scale, near, vp, 1), w, "overlay pen down");
  expectOk(ov.penMotionAction(0, scale, nudge, vp, 1), w, "overlay pen motion");
  expectOk(ov.penUpAction(0, scale, nudge, vp, 0), w, "overlay pen up");
  auto *start =
      dynamic_cast<OFX::Host::Param::Double2DInstance *>(fx.getParam("line1_a_start"));
  auto *count = dynamic_cast<OFX::Host::Param::IntegerInstance *>(fx.getParam("line_count"));
  double x = 0, y = 0;
  int lines = 0;
  if (!start || start->get(x, y) != kOfxStatOK || x != 20 || y != 20 || !count ||
      count->get(lines) != kOfxStatOK || lines != 2) {
    std::ostringstream m;
    m << w.text << ": a click 13 screen pixels from line 1's A start moved it to (" << x
      << ", " << y << ") or left Line Count " << lines
      << ": the hit radius did not follow the projection's zoom";
    fail(m.str());
  }
}

/// Scene Text's shapes edited through the library's own overlay interact:
/// a drag moves one control point of a curve, and the point tool adds a
/// point feature, each written back into the String param this host gives
/// storage; the numbers read back are where the pen let go.
void checkOverlayShapes(Effect &fx, const Where &w) {
  auto *text = dynamic_cast<OFX::Host::Param::StringInstance *>(fx.getParam("scene_text"));
  auto *tool = dynamic_cast<OFX::Host::Param::ChoiceInstance *>(fx.getParam("draw_tool"));
  if (!text || !tool) return fail(w.text + ": no scene_text or draw_tool param");
  text->set(
      "{\"format\": \"morphfx-scene\", \"version\": 1, \"features\": [{\"name\": \"brow\", "
      "\"type\": \"curve\", \"a\": [[40, 40], [50, 45], [60, 40]], "
      "\"b\": [[40, 42], [50, 48], [60, 42]]}]}");
  Overlay ov(fx);
  expectOk(ov.createInstanceAction(), w, "overlay createInstance");
  const OfxPointD scale = {1, 1};
  const OfxPointI vp = {0, 0};
  expectOk(ov.drawAction(0, scale), w, "overlay draw");
  const OfxPointD from = {50, 45}, mid = {51, 46}, to = {52.5, 47};
  expectOk(ov.penDownAction(0, scale, from, vp, 1), w, "overlay pen down on the curve");
  expectOk(ov.penMotionAction(0, scale, mid, vp, 1), w, "overlay pen motion");
  expectOk(ov.penUpAction(0, scale, to, vp, 0), w, "overlay pen up");
  std::string after;
  text->get(after);
  auto has = [&](const char *s) { return after.find(s) != std::string::npos; };
  if (!has("[52.5, 47]") || has("[50, 45]") || !has("[40, 40]") || !has("[60, 40]") ||
      !has("[50, 48]"))
    fail(w.text + ": dragging the curve's middle A point to (52.5, 47) left Scene Text " +
         after);
  // A host that refuses edit blocks (HostSupport's example host answers
  // paramEditBegin with kOfxStatErrMissingHostFeature): the drag still
  // edits, without an undo block.
  fx.refuseEditBlocks = true;
  const OfxPointD back = {50, 45};
  expectOk(ov.penDownAction(0, scale, to, vp, 1), w, "overlay pen down (no edit blocks)");
  expectOk(ov.penUpAction(0, scale, back, vp, 0), w, "overlay pen up (no edit blocks)");
  fx.refuseEditBlocks = false;
  text->get(after);
  if (!has("[50, 45]") || has("[52.5, 47]"))
    fail(w.text + ": with paramEditBegin refused, dragging the point back to (50, 45) left "
         "Scene Text " + after);
  tool->set(1);  // point
  const OfxPointD empty = {85, 55};
  expectOk(ov.penDownAction(0, scale, empty, vp, 1), w, "overlay pen down (point tool)");
  expectOk(ov.penUpAction(0, scale, empty, vp, 0), w, "overlay pen up (point tool)");
  text->get(after);
  if (!has("\"type\": \"point\"") || !has("\"a\": [[85, 55]]") || !has("\"b\": [[85, 55]]"))
    fail(w.text + ": the point tool's click at (85, 55) left Scene Text " + after);
  // With a Scene File in use its shapes are read-only: the click is
  // refused with a warning on the node, not an error (an error would mark
  // a node that renders fine as failed, Natron's ERROR badge).
  auto *file = dynamic_cast<OFX::Host::Param::StringInstance *>(fx.getParam("scene_file"));
  if (!file) return fail(w.text + ": no scene_file param");
  const std::string path = "/tmp/morphfx-refhost-" + std::to_string(getpid()) + ".morph.json";
  std::ofstream(path) << after;
  file->set(path.c_str());
  fx.persistentError.clear();
  fx.persistentType.clear();
  const OfxPointD other = {88, 8};  // clear of every line and shape
  expectOk(ov.penDownAction(0, scale, other, vp, 1), w, "overlay pen down (file in use)");
  expectOk(ov.penUpAction(0, scale, other, vp, 0), w, "overlay pen up (file in use)");
  if (fx.persistentError.find("Copy Scene Into Node") == std::string::npos ||
      fx.persistentType != kOfxMessageWarning)
    fail(w.text + ": a click while Scene File is in use left '" + fx.persistentError +
         "' as " + (fx.persistentType.empty() ? "nothing" : fx.persistentType));
  file->set("");
  std::remove(path.c_str());
  tool->set(0);
}

/// Track Forward through the library, before any render: images fetched in
/// instanceChanged, the progress suite, keys set at other times. The
/// sources do not move from frame to frame, so B's line, which lies on
/// Source B's checkerboard, must stay where it was keyed (a tracker that
/// drifted, or keyed at the wrong scale, would move it). A's line lies on a
/// Grid warps: Grid Rows and Grid Columns at 4, Reset Grid pressed (an
/// even mesh over Source A, 96 x 64 here; the node's Method becomes mesh,
/// as Settings From Scene is off), then B's node (row 1, col 1) at
/// (32, 64/3) dragged through the overlay to (36, 25): Scene Text read
/// back holds the 4 x 4 mesh, method mesh, and the moved node on B only.
void checkOverlayGrid(Effect &fx, const Where &w) {
  auto *text = dynamic_cast<OFX::Host::Param::StringInstance *>(fx.getParam("scene_text"));
  auto *rows = dynamic_cast<OFX::Host::Param::IntegerInstance *>(fx.getParam("grid_rows"));
  auto *cols = dynamic_cast<OFX::Host::Param::IntegerInstance *>(fx.getParam("grid_cols"));
  auto *edit = dynamic_cast<OFX::Host::Param::ChoiceInstance *>(fx.getParam("overlay_edit"));
  auto *method = dynamic_cast<OFX::Host::Param::ChoiceInstance *>(fx.getParam("method"));
  if (!text || !rows || !cols || !edit || !method)
    return fail(w.text + ": no scene_text, grid_rows, grid_cols, overlay_edit or method param");
  // Reset Grid sets the node's Method to mesh (its own settings rule
  // here): put it back for the checks that follow.
  int was = 0;
  method->get(was);
  text->set("{\"format\": \"morphfx-scene\", \"version\": 1, \"features\": []}");
  rows->set(4);
  cols->set(4);
  const OfxPointD scale = {1, 1};
  expectOk(fx.beginInstanceChangedAction(kOfxChangeUserEdited), w, "beginInstanceChanged");
  expectOk(fx.paramInstanceChangedAction("reset_grid", kOfxChangeUserEdited, 0, scale), w,
           "instanceChanged reset_grid");
  expectOk(fx.endInstanceChangedAction(kOfxChangeUserEdited), w, "endInstanceChanged");
  std::string after;
  text->get(after);
  auto has = [&](const char *s) { return after.find(s) != std::string::npos; };
  if (!has("\"method\": \"mesh\"") || !has("\"rows\": 4") || !has("\"cols\": 4") ||
      !has("[96, 64]") || !has("[32, 21.33"))
    return fail(w.text + ": Reset Grid (4 x 4) left Scene Text " + after);
  edit->set(2);  // B
  Overlay ov(fx);
  expectOk(ov.createInstanceAction(), w, "overlay createInstance");
  const OfxPointI vp = {0, 0};
  expectOk(ov.drawAction(0, scale), w, "overlay draw");
  const OfxPointD from = {32, 64.0 / 3.0}, mid = {34, 23}, to = {36, 25};
  expectOk(ov.penDownAction(0, scale, from, vp, 1), w, "overlay pen down on a node");
  expectOk(ov.penMotionAction(0, scale, mid, vp, 1), w, "overlay pen motion");
  expectOk(ov.penUpAction(0, scale, to, vp, 0), w, "overlay pen up");
  edit->set(0);
  method->set(was);
  text->get(after);
  const std::size_t b = after.find("\"b\"");
  const bool moved = b != std::string::npos && after.find("[36, 25", b) != std::string::npos;
  const bool a_kept = after.find("[36, 25") > b;
  if (!moved || !a_kept)
    fail(w.text + ": dragging B's node (1, 1) to (36, 25) left Scene Text " + after);
}

/// plain ramp, where the tracker may rightly report it lost (a warning).
void checkTrack(Effect &fx, const Where &w) {
  auto *b = dynamic_cast<OFX::Host::Param::Double2DInstance *>(fx.getParam("line1_b_start"));
  if (!b) return fail(w.text + ": no param line1_b_start");
  double x0 = 0, y0 = 0;
  b->get(0, x0, y0);
  const OfxPointD scale = {1, 1};
  expectOk(fx.beginInstanceChangedAction(kOfxChangeUserEdited), w, "beginInstanceChanged");
  expectOk(fx.paramInstanceChangedAction("track_forward", kOfxChangeUserEdited, 0, scale), w,
           "instanceChanged track_forward");
  expectOk(fx.endInstanceChangedAction(kOfxChangeUserEdited), w, "endInstanceChanged");
  for (double t : {3.0, 10.0}) {
    double x = 0, y = 0;
    if (b->get(t, x, y) != kOfxStatOK || std::fabs(x - x0) > 0.05 || std::fabs(y - y0) > 0.05) {
      std::ostringstream m;
      m << w.text << ": Track Forward moved line 1's B start from (" << x0 << ", " << y0
        << ") to (" << x << ", " << y << ") at frame " << t << " of a still source";
      fail(m.str());
    }
  }
  // Back as keyLines left them, for the renders that follow.
  keyLines(fx, w);
}

/// Actions sent with no effect handle, as a broken host might, straight to
/// the plugin's main entry: each must come back kOfxStatErrBadHandle (and
/// the plugin says why through this library's message suite, which takes a
/// null handle), never a crash.
void checkNullHandle(IE::ImageEffectPlugin &plugin, const Where &w) {
  OfxPlugin *raw = plugin.getPluginHandle()->getOfxPlugin();
  if (!raw || !raw->mainEntry) return fail(w.text + ": no main entry");
  for (const char *action : {kOfxImageEffectActionRender, kOfxImageEffectActionIsIdentity,
                             kOfxImageEffectActionGetRegionOfDefinition,
                             kOfxActionInstanceChanged}) {
    const OfxStatus s = raw->mainEntry(action, nullptr, nullptr, nullptr);
    if (s != kOfxStatErrBadHandle)
      fail(w.text + ": " + action + " with a null handle returned " + statusName(s));
  }
  // The library prints messages with no effect as they come, unterminated.
  std::cout << std::endl;
}

/// A render that fails for a real reason (a scene file that is not there)
/// leaves the plugin's words on the node, as the library formats them:
/// the `%` in the path arrives as written, not read as a conversion.
void checkFailureMessage(Effect &fx, const Where &w) {
  auto *file = dynamic_cast<OFX::Host::Param::StringInstance *>(fx.getParam("scene_file"));
  if (!file) return fail(w.text + ": no string param scene_file");
  const std::string path = "/no/such/folder/take 100%d %s.morph.json";
  file->set(path.c_str());
  const OfxPointD scale = {1, 1};
  fx.renderScale = scale;
  fx.renderWindow = {0, 0, kProjectWidth, kProjectHeight};
  fx.persistentError.clear();
  expectOk(fx.beginRenderAction(0, 0, 1, false, scale, true, false), w, "beginSequenceRender");
  fx.rendering = true;
  const OfxStatus s =
      fx.renderAction(0, kOfxImageFieldNone, fx.renderWindow, scale, true, false, false);
  fx.rendering = false;
  expectOk(fx.endRenderAction(0, 0, 1, false, scale, true, false), w, "endSequenceRender");
  if (s != kOfxStatFailed)
    fail(w.text + ": a render with a missing scene file returned " + statusName(s));
  if (fx.persistentError.find("scene file " + path + ": ") == std::string::npos)
    fail(w.text + ": the failed render's message arrived as '" + fx.persistentError + "'");
  file->set("");
}

/// Straight (unpremultiplied) sources, as the library names them
/// (`kOfxImageUnPreMultiplied`): the node keeps its output straight, and
/// says so in the clip preferences in the spec's words.
void checkStraight(IE::ImageEffectPlugin &plugin, const std::string &context,
                   const Where &where) {
  const Where w = where.with(context).with("straight sources");
  std::unique_ptr<IE::Instance> made(plugin.createInstance(context, nullptr));
  auto *fx = dynamic_cast<Effect *>(made.get());
  if (!fx) return fail(w.text + ": no instance (describe in context failed)");
  fx->straight = true;
  expectOk(fx->createInstanceAction(), w, "createInstance");
  if (!fx->getClipPreferences()) return fail(w.text + ": getClipPreferences failed");
  if (fx->getOutputPreMultiplication() != kOfxImageUnPreMultiplied)
    fail(w.text + ": output declared '" + fx->getOutputPreMultiplication() + "', not '" +
         kOfxImageUnPreMultiplied + "'");
}

/// RGB sources, as a host offers an RGB plate: the library gives the output
/// the sources' components (RGB) unless the plugin asks for others. The
/// ghost and folds views carry their measure in alpha, so with them the
/// node must ask for RGBA; with the morph (or warped) view, RGB stands.
void checkRgbaViews(IE::ImageEffectPlugin &plugin, const std::string &context,
                    const Where &where) {
  const Where w = where.with(context).with("RGB sources");
  std::unique_ptr<IE::Instance> made(plugin.createInstance(context, nullptr));
  auto *fx = dynamic_cast<Effect *>(made.get());
  if (!fx) return fail(w.text + ": no instance (describe in context failed)");
  fx->sourceComponents = kOfxImageComponentRGB;
  expectOk(fx->createInstanceAction(), w, "createInstance");
  auto *view = dynamic_cast<OFX::Host::Param::ChoiceInstance *>(fx->getParam("view"));
  if (!view) return fail(w.text + ": no view choice");
  const int views = choiceCount(*fx, "view");
  int asked = 0;
  for (int v = 0; v < views; ++v) {
    const std::string name =
        view->getProperties().getStringProperty(kOfxParamPropChoiceOption, v);
    const bool alpha = name == "ghost" || name == "folds";
    if (!alpha && v != 0) continue;  // the default view stands for the rest
    view->set(v);
    if (!fx->getClipPreferences()) {
      fail(w.text + ", view " + name + ": getClipPreferences failed");
      continue;
    }
    const std::string want = alpha ? kOfxImageComponentRGBA : kOfxImageComponentRGB;
    const std::string got = fx->getClip(kOfxImageEffectOutputClipName)->getComponents();
    if (got != want) fail(w.text + ", view " + name + ": output " + got + ", not " + want);
    asked += alpha;
  }
  if (asked == 0) fail(w.text + ": no ghost or folds view offered");
}

/// A node just made, nothing connected, as Natron asks of it at once:
/// region of definition, clip preferences, regions of interest, frames
/// needed and identity each answer without a failure status, and nothing
/// is left on the node (a persistent error is an ERROR badge there). The
/// library fills in its default region where the plugin replies default.
void checkUnconnected(IE::ImageEffectPlugin &plugin, const std::string &context,
                      const Where &where) {
  const Where w = where.with(context).with("nothing connected");
  std::unique_ptr<IE::Instance> made(plugin.createInstance(context, nullptr));
  auto *fx = dynamic_cast<Effect *>(made.get());
  if (!fx) return fail(w.text + ": no instance (describe in context failed)");
  fx->connected = false;
  expectOk(fx->createInstanceAction(), w, "createInstance");
  const OfxPointD scale = {1, 1};
  OfxRectD rod = {0, 0, 0, 0};
  expectOk(fx->getRegionOfDefinitionAction(0, scale, rod), w, "getRegionOfDefinition");
  if (!fx->getClipPreferences()) fail(w.text + ": getClipPreferences failed");
  const OfxRectD project = {0, 0, double(kProjectWidth), double(kProjectHeight)};
  std::map<IE::ClipInstance *, OfxRectD> rois;
  expectOk(fx->getRegionOfInterestAction(0, scale, project, rois), w, "getRegionsOfInterest");
  IE::RangeMap ranges;
  expectOk(fx->getFrameNeededAction(0, ranges), w, "getFramesNeeded");
  OfxTime time = 0;
  std::string clip;
  const OfxRectI win = {0, 0, kProjectWidth, kProjectHeight};
  const OfxStatus s = fx->isIdentityAction(time, kOfxImageFieldNone, win, scale, clip);
  if (s == kOfxStatOK) fail(w.text + ": identity to clip '" + clip + "', which is not connected");
  expectOk(s, w, "isIdentity");
  if (!fx->persistentError.empty())
    fail(w.text + ": left an error on the node: " + fx->persistentError);
}

/// Motion blur and the vectors view as HostSupport drives them. The scene
/// keys a line at frames -1 and 1 (its B end moving 0.1 px), so the warp
/// moves within a one-frame shutter around frame 0: Motion Blur 4 renders
/// (four samples averaged) and comes out within 0.05 of the unblurred
/// frame's mean in every channel; the vectors view renders, its motion a
/// fraction of a pixel (inside the render check's range). Put back after.
void checkMotion(Effect &fx, const Where &w) {
  auto *text = dynamic_cast<OFX::Host::Param::StringInstance *>(fx.getParam("scene_text"));
  auto *samples = dynamic_cast<OFX::Host::Param::IntegerInstance *>(fx.getParam("motion_blur"));
  auto *view = dynamic_cast<OFX::Host::Param::ChoiceInstance *>(fx.getParam("view"));
  if (!text || !samples || !view || !setDouble(fx, "shutter", 1.0))
    return fail(w.text + ": no scene_text, motion_blur, shutter or view param");
  text->set(
      "{\"format\": \"morphfx-scene\", \"version\": 1, \"keyframes\": ["
      "{\"frame\": -1, \"features\": [{\"type\": \"line\", \"a\": [[30, 20], [70, 40]], "
      "\"b\": [[32, 22], [72, 42]]}]},"
      "{\"frame\": 1, \"features\": [{\"type\": \"line\", \"a\": [[30, 20], [70, 40]], "
      "\"b\": [[32, 22], [72.1, 42]]}]}]}");
  // The slots' two lines cross and fold the field, where a point is shown
  // twice and its vector may follow either: off for this check.
  auto *count = dynamic_cast<OFX::Host::Param::IntegerInstance *>(fx.getParam("line_count"));
  if (!count) return fail(w.text + ": no line_count param");
  int lines = 0;
  count->get(lines);
  count->set(0);
  const OfxPointD one = {1, 1};
  samples->set(0);
  const Render still = render(fx, one, w.with("motion blur 0"));
  samples->set(4);
  const Render blurred = render(fx, one, w.with("motion blur 4"));
  if (still.ok && blurred.ok)
    for (int c = 0; c < 4; ++c)
      if (std::fabs(still.mean[c] - blurred.mean[c]) > 0.05) {
        std::ostringstream m;
        m << w.text << ": channel " << c << " mean " << blurred.mean[c]
          << " with motion blur, " << still.mean[c] << " without";
        fail(m.str());
      }
  samples->set(0);
  const int views = choiceCount(fx, "view");
  const std::string last =
      views > 0 ? view->getProperties().getStringProperty(kOfxParamPropChoiceOption, views - 1)
                : "";
  if (last != "vectors") return fail(w.text + ": the view's last option is not vectors");
  view->set(views - 1);
  render(fx, one, w.with("vectors view"));
  view->set(0);
  count->set(lines);
}

/// The index of choice param `name`'s option `option`, or -1.
int choiceIndex(IE::Instance &fx, const std::string &name, const std::string &option) {
  auto *p = fx.getParam(name);
  for (int k = 0; p && k < choiceCount(fx, name); ++k)
    if (p->getProperties().getStringProperty(kOfxParamPropChoiceOption, k) == option) return k;
  return -1;
}

/// The Filter's `nearest` option through the library: the warped source
/// holds only values the source holds (IDs stay IDs), moved by the warp.
/// Morph shows its warped B (a checkerboard of two colours), Warp its
/// source (a ramp whose values are pixel centres over the frame).
void checkNearest(Effect &fx, const Where &w) {
  auto *filter = dynamic_cast<OFX::Host::Param::ChoiceInstance *>(fx.getParam("filter"));
  auto *view = dynamic_cast<OFX::Host::Param::ChoiceInstance *>(fx.getParam("view"));
  const int nearest = choiceIndex(fx, "filter", "nearest");
  const bool morph = inputClips(fx).size() == 2;
  const int picture = morph ? choiceIndex(fx, "view", "warped-b") : 0;
  if (!filter || !view || nearest < 0 || picture < 0)
    return fail(w.text + ": no filter option nearest or no warped-b view");
  filter->set(nearest);
  view->set(picture);
  const Render out = render(fx, {1, 1}, w.with("nearest"));
  const std::vector<float> px = outputPixels(fx);
  filter->set(0);
  view->set(0);
  if (!out.ok) return;
  const auto near = [](double v, double to) { return std::fabs(v - to) < 1e-5; };
  const auto centre = [&](double v, int n) {
    return near(v * n - 0.5, std::round(v * n - 0.5));
  };
  const std::string shown = inputClips(fx).back();
  const OfxRectI &b = fx.renderWindow;
  size_t k = 0;
  int moved = 0;
  for (int y = b.y1; y < b.y2; ++y)
    for (int x = b.x1; x < b.x2; ++x, k += 4) {
      const float r = px[k], g = px[k + 1], bl = px[k + 2];
      const bool source =
          morph ? (near(r, 0.9) && near(bl, 0.2)) || (near(r, 0.1) && near(bl, 0.8))
                : centre(r, kProjectWidth) && centre(g, kProjectHeight);
      if (!source) {
        std::ostringstream m;
        m << w.text << ": nearest gave (" << r << ", " << g << ", " << bl << ") at (" << x
          << ", " << y << "), no source value";
        return fail(m.str());
      }
      moved += !near(r, sourceValue(shown, x + 0.5, y + 0.5, 0));
    }
  if (moved == 0) fail(w.text + ": nearest: the warp moved nothing");
}

/// The frame rendered in four tiles split off-centre, as a host that
/// renders in tiles asks for it, has the whole frame's bits (the maps'
/// grids and lattices are fixed in the image, not in the window).
void checkTiles(Effect &fx, const Where &w) {
  const Render whole = render(fx, {1, 1}, w.with("whole"));
  const std::vector<float> all = outputPixels(fx);
  const OfxRectI frame = fx.renderWindow;
  if (!whole.ok) return;
  const int fw = frame.x2 - frame.x1, sx = frame.x1 + 37, sy = frame.y1 + 23;
  const OfxRectI tiles[4] = {{frame.x1, frame.y1, sx, sy},
                             {sx, frame.y1, frame.x2, sy},
                             {frame.x1, sy, sx, frame.y2},
                             {sx, sy, frame.x2, frame.y2}};
  for (const OfxRectI &tile : tiles) {
    if (!render(fx, {1, 1}, w.with("tile"), false, &tile).ok) return;
    const std::vector<float> part = outputPixels(fx);
    size_t k = 0;
    for (int y = tile.y1; y < tile.y2; ++y)
      for (int x = tile.x1; x < tile.x2; ++x)
        for (int c = 0; c < 4; ++c, ++k) {
          const float want = all[(size_t((y - frame.y1) * fw + (x - frame.x1))) * 4 + c];
          if (std::memcmp(&part[k], &want, sizeof(float)) != 0) {
            std::ostringstream m;
            m.precision(9);
            m << w.text << ": pixel (" << x << ", " << y << ") channel " << c << " is "
              << part[k] << " rendered in the tile (" << tile.x1 << ", " << tile.y1 << ", "
              << tile.x2 << ", " << tile.y2 << ") but " << want << " in the whole frame";
            return fail(m.str());
          }
        }
  }
}

/// One instance of `node` in `context`, its sources at `depth`.
void checkContext(IE::ImageEffectPlugin &plugin, const std::string &context,
                  const std::string &depth, const Where &where) {
  const Where w = where.with(context).with(depth);
  std::unique_ptr<IE::Instance> made(plugin.createInstance(context, nullptr));
  auto *fx = dynamic_cast<Effect *>(made.get());
  if (!fx) return fail(w.text + ": no instance (describe in context failed)");
  fx->sourceDepth = depth;
  for (const std::string &clip : mandatedClips(context))
    if (!fx->getClip(clip)) fail(w.text + ": mandated clip " + clip + " missing");
  if (inputClips(*fx).empty()) return fail(w.text + ": no input clip");
  if (context == kOfxImageEffectContextTransition &&
      !dynamic_cast<OFX::Host::Param::DoubleInstance *>(fx->getParam("Transition")))
    return fail(w.text + ": mandated double param Transition missing");
  keyLines(*fx, w);
  loadScene(*fx, w);
  setDouble(*fx, progressParam(context), 0.5);
  expectOk(fx->createInstanceAction(), w, "createInstance");
  if (!fx->getClipPreferences()) fail(w.text + ": getClipPreferences failed");
  checkIdentity(*fx, context, w);
  if (depth == std::string(kOfxBitDepthFloat)) {
    checkFailureMessage(*fx, w.with("missing scene file"));
    checkOverlay(*fx, w.with("overlay"));
    checkOverlayGl(*fx, w.with("overlay in OpenGL"));
    checkOverlayShapes(*fx, w.with("overlay shapes"));
    checkOverlayGrid(*fx, w.with("overlay grid"));
    loadScene(*fx, w);
    if (inputClips(*fx).size() == 2) checkTrack(*fx, w.with("track"));
    checkMattes(*fx, w.with("mattes"));
    checkDrag(*fx, w.with("drag"));
    checkMotion(*fx, w.with("motion"));
    checkNearest(*fx, w.with("filter"));
    loadScene(*fx, w);
  }

  auto *method = dynamic_cast<OFX::Host::Param::ChoiceInstance *>(fx->getParam("method"));
  const int methods = choiceCount(*fx, "method");
  if (!method || methods < 1) return fail(w.text + ": no method choice");
  for (int m = 0; m < methods; ++m) {
    method->set(m);
    const std::string name = method->getProperties().getStringProperty(
        kOfxParamPropChoiceOption, m);
    const Where wm = w.with("method " + name);
    std::cout << "refhost: " << wm.text << std::endl;
    if (depth == std::string(kOfxBitDepthFloat)) {
      checkTiles(*fx, wm.with("tiles"));
      // The mesh both ways: two-pass pictures, one-pass maps.
      auto *pass = dynamic_cast<OFX::Host::Param::ChoiceInstance *>(fx->getParam("mesh_pass"));
      if (name == "mesh" && pass) {
        pass->set(choiceIndex(*fx, "mesh_pass", "one-pass"));
        checkTiles(*fx, wm.with("one-pass tiles"));
        pass->set(0);
      }
    }
    const Render full = render(*fx, {1, 1}, wm.with("scale 1"));
    const Render half = render(*fx, {0.5, 0.5}, wm.with("scale 0.5"));
    if (!full.ok || !half.ok) continue;
    // The same picture at half resolution: its mean colour barely moves.
    for (int c = 0; c < 4; ++c)
      if (std::fabs(full.mean[c] - half.mean[c]) > 0.03) {
        std::ostringstream m;
        m << wm.text << ": channel " << c << " mean " << full.mean[c]
          << " at scale 1 but " << half.mean[c] << " at scale 0.5";
        fail(m.str());
      }
  }
}

}  // namespace

int main(int argc, char **argv) {
  if (argc != 2) {
    std::cerr << "usage: morphfx-refhost DIR (the folder holding MorphFX.ofx.bundle)\n";
    return 2;
  }
  OFX::Host::PluginCache::getPluginCache()->setCacheVersion("morphfx-refhost");
  Host host;
  IE::PluginCache effects(host);
  effects.registerInCache(*OFX::Host::PluginCache::getPluginCache());
  OFX::Host::PluginCache::getPluginCache()->addFileToPath(argv[1]);
  OFX::Host::PluginCache::getPluginCache()->scanPluginFiles();

  int checked = 0;
  for (const Node &node : kNodes) {
    IE::ImageEffectPlugin *plugin = effects.getPluginById(node.id);
    if (!plugin) {
      fail(std::string(node.id) + ": not found in " + argv[1]);
      continue;
    }
    const std::set<std::string> &offered = plugin->getContexts();
    for (const std::string &context : node.contexts) {
      if (!offered.count(context)) {
        fail(std::string(node.id) + ": context " + context + " not offered");
        continue;
      }
      checkUnconnected(*plugin, context, {node.id});
      checkStraight(*plugin, context, {node.id});
      checkRgbaViews(*plugin, context, {node.id});
      for (const char *depth : {kOfxBitDepthFloat, kOfxBitDepthByte}) {
        checkContext(*plugin, context, depth, {node.id});
        ++checked;
      }
    }
    // Loaded by now (the instances above), so it has the message suite.
    checkNullHandle(*plugin, {std::string(node.id) + ", null handle"});
  }
  OFX::Host::PluginCache::clearPluginCache();

  if (!failures().empty()) {
    std::cerr << "refhost: " << failures().size() << " failure(s)\n";
    return 1;
  }
  std::cout << "refhost: " << checked
            << " node/context/depth combinations passed every check\n";
  return 0;
}
