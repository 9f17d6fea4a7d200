// The host side: application properties, instances, clips, images and
// params, on the reference host library's base classes.
#include "refhost.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <limits>

#include "ofxMessage.h"

namespace refhost {

static std::vector<std::string> gFailures;

void fail(const std::string &what) {
  std::cerr << "refhost: FAIL: " << what << std::endl;
  gFailures.push_back(what);
}

const std::vector<std::string> &failures() { return gFailures; }

static std::string format(const char *fmt, va_list args) {
  char buf[4096];
  vsnprintf(buf, sizeof buf, fmt, args);
  return buf;
}

static bool isError(const char *type) {
  return std::strcmp(type, kOfxMessageError) == 0 ||
         std::strcmp(type, kOfxMessageFatal) == 0;
}

// ---------------------------------------------------------------- host

Host::Host() {
  // What a general-purpose compositor announces: tiles, multi-resolution,
  // temporal access, RGBA and alpha, every context.
  _properties.setStringProperty(kOfxPropName, "net.morphfx.refhost");
  _properties.setStringProperty(kOfxPropLabel, "MorphFX reference-library host");
  _properties.setIntProperty(kOfxPropAPIVersion, 1, 0);
  _properties.setIntProperty(kOfxPropAPIVersion, 4, 1);
  _properties.setIntProperty(kOfxPropVersion, 1, 0);
  _properties.setStringProperty(kOfxPropVersionLabel, "1.0");
  _properties.setIntProperty(kOfxImageEffectHostPropIsBackground, 0);
  _properties.setIntProperty(kOfxImageEffectPropSupportsOverlays, 1);
  _properties.setIntProperty(kOfxImageEffectPropSupportsMultiResolution, 1);
  _properties.setIntProperty(kOfxImageEffectPropSupportsTiles, 1);
  _properties.setIntProperty(kOfxImageEffectPropTemporalClipAccess, 1);
  _properties.setStringProperty(kOfxImageEffectPropSupportedComponents,
                                kOfxImageComponentRGBA, 0);
  _properties.setStringProperty(kOfxImageEffectPropSupportedComponents,
                                kOfxImageComponentAlpha, 1);
  const char *contexts[] = {
      kOfxImageEffectContextGenerator, kOfxImageEffectContextFilter,
      kOfxImageEffectContextGeneral, kOfxImageEffectContextTransition};
  for (int i = 0; i < 4; ++i)
    _properties.setStringProperty(kOfxImageEffectPropSupportedContexts,
                                  contexts[i], i);
  _properties.setIntProperty(kOfxImageEffectPropSupportsMultipleClipDepths, 0);
  _properties.setIntProperty(kOfxImageEffectPropSupportsMultipleClipPARs, 0);
  _properties.setIntProperty(kOfxImageEffectPropSetableFrameRate, 0);
  _properties.setIntProperty(kOfxImageEffectPropSetableFielding, 0);
  _properties.setIntProperty(kOfxParamHostPropSupportsCustomInteract, 0);
  _properties.setIntProperty(kOfxParamHostPropSupportsStringAnimation, 0);
  _properties.setIntProperty(kOfxParamHostPropSupportsChoiceAnimation, 0);
  _properties.setIntProperty(kOfxParamHostPropSupportsBooleanAnimation, 0);
  _properties.setIntProperty(kOfxParamHostPropSupportsCustomAnimation, 0);
  _properties.setIntProperty(kOfxParamHostPropMaxParameters, -1);
  _properties.setIntProperty(kOfxParamHostPropMaxPages, 0);
  _properties.setIntProperty(kOfxParamHostPropPageRowColumnCount, 0, 0);
  _properties.setIntProperty(kOfxParamHostPropPageRowColumnCount, 0, 1);
}

OFX::Host::ImageEffect::Instance *Host::newInstance(
    void *, OFX::Host::ImageEffect::ImageEffectPlugin *plugin,
    OFX::Host::ImageEffect::Descriptor &desc, const std::string &context) {
  return new Effect(plugin, desc, context);
}

OFX::Host::ImageEffect::Descriptor *Host::makeDescriptor(
    OFX::Host::ImageEffect::ImageEffectPlugin *plugin) {
  return new OFX::Host::ImageEffect::Descriptor(plugin);
}

OFX::Host::ImageEffect::Descriptor *Host::makeDescriptor(
    const OFX::Host::ImageEffect::Descriptor &rootContext,
    OFX::Host::ImageEffect::ImageEffectPlugin *plugin) {
  return new OFX::Host::ImageEffect::Descriptor(rootContext, plugin);
}

OFX::Host::ImageEffect::Descriptor *Host::makeDescriptor(
    const std::string &bundlePath,
    OFX::Host::ImageEffect::ImageEffectPlugin *plugin) {
  return new OFX::Host::ImageEffect::Descriptor(bundlePath, plugin);
}

OfxStatus Host::vmessage(const char *type, const char *id, const char *fmt,
                         va_list args) {
  std::string text = format(fmt, args);
  std::cerr << "refhost: message (" << type << "): " << text << std::endl;
  // An error outside any instance (while loading or describing) is a
  // failure; a question gets the answer a batch host gives.
  if (isError(type)) fail(std::string("host-level error message: ") + text);
  return std::strcmp(type, kOfxMessageQuestion) == 0 ? kOfxStatReplyNo
                                                      : kOfxStatOK;
}

OfxStatus Host::setPersistentMessage(const char *type, const char *id,
                                     const char *fmt, va_list args) {
  return vmessage(type, id, fmt, args);
}

OfxStatus Host::clearPersistentMessage() { return kOfxStatOK; }

// ---------------------------------------------------------------- params

namespace P = OFX::Host::Param;

// Params hold one value each (this host does not animate): what the plugin
// gets back is what was last set, starting from the descriptor's default.
class DoubleParam : public P::DoubleInstance {
  double v_;

 public:
  DoubleParam(P::Descriptor &d, P::SetInstance *s)
      : P::DoubleInstance(d, s),
        v_(d.getProperties().getDoubleProperty(kOfxParamPropDefault)) {}
  OfxStatus get(double &v) override { return v = v_, kOfxStatOK; }
  OfxStatus get(OfxTime, double &v) override { return get(v); }
  OfxStatus set(double v) override { return v_ = v, kOfxStatOK; }
  OfxStatus set(OfxTime, double v) override { return set(v); }
  OfxStatus derive(OfxTime, double &v) override { return v = 0, kOfxStatOK; }
  OfxStatus integrate(OfxTime t1, OfxTime t2, double &v) override {
    return v = v_ * (t2 - t1), kOfxStatOK;
  }
};

class Double2DParam : public P::Double2DInstance {
  double x_, y_;

 public:
  Double2DParam(P::Descriptor &d, P::SetInstance *s)
      : P::Double2DInstance(d, s),
        x_(d.getProperties().getDoubleProperty(kOfxParamPropDefault, 0)),
        y_(d.getProperties().getDoubleProperty(kOfxParamPropDefault, 1)) {}
  OfxStatus get(double &x, double &y) override {
    x = x_, y = y_;
    return kOfxStatOK;
  }
  OfxStatus get(OfxTime, double &x, double &y) override { return get(x, y); }
  OfxStatus set(double x, double y) override {
    x_ = x, y_ = y;
    return kOfxStatOK;
  }
  OfxStatus set(OfxTime, double x, double y) override { return set(x, y); }
};

template <class Base>
class IntLikeParam : public Base {
  int v_;

 public:
  IntLikeParam(P::Descriptor &d, P::SetInstance *s)
      : Base(d, s),
        v_(d.getProperties().getIntProperty(kOfxParamPropDefault)) {}
  OfxStatus get(int &v) override { return v = v_, kOfxStatOK; }
  OfxStatus get(OfxTime, int &v) override { return get(v); }
  OfxStatus set(int v) override { return v_ = v, kOfxStatOK; }
  OfxStatus set(OfxTime, int v) override { return set(v); }
};

class BoolParam : public P::BooleanInstance {
  bool v_;

 public:
  BoolParam(P::Descriptor &d, P::SetInstance *s)
      : P::BooleanInstance(d, s),
        v_(d.getProperties().getIntProperty(kOfxParamPropDefault) != 0) {}
  OfxStatus get(bool &v) override { return v = v_, kOfxStatOK; }
  OfxStatus get(OfxTime, bool &v) override { return get(v); }
  OfxStatus set(bool v) override { return v_ = v, kOfxStatOK; }
  OfxStatus set(OfxTime, bool v) override { return set(v); }
};

class StringParam : public P::StringInstance {
  std::string v_;

 public:
  StringParam(P::Descriptor &d, P::SetInstance *s)
      : P::StringInstance(d, s),
        v_(d.getProperties().getStringProperty(kOfxParamPropDefault)) {}
  OfxStatus get(std::string &v) override { return v = v_, kOfxStatOK; }
  OfxStatus get(OfxTime, std::string &v) override { return get(v); }
  OfxStatus set(const char *v) override { return v_ = v, kOfxStatOK; }
  OfxStatus set(OfxTime, const char *v) override { return set(v); }
};

// ---------------------------------------------------------------- effect

Effect::Effect(OFX::Host::ImageEffect::ImageEffectPlugin *plugin,
               OFX::Host::ImageEffect::Descriptor &desc,
               const std::string &context)
    : OFX::Host::ImageEffect::Instance(plugin, desc, context, false) {}

const std::string &Effect::getDefaultOutputFielding() const {
  static const std::string none = kOfxImageFieldNone;
  return none;
}

OFX::Host::ImageEffect::ClipInstance *Effect::newClipInstance(
    OFX::Host::ImageEffect::Instance *, OFX::Host::ImageEffect::ClipDescriptor *d,
    int) {
  return new Clip(this, *d);
}

OfxStatus Effect::vmessage(const char *type, const char *, const char *fmt,
                           va_list args) {
  std::string text = format(fmt, args);
  std::cerr << "refhost: message (" << type << "): " << text << std::endl;
  if (isError(type)) fail("error message: " + text);
  // Natron shows every message from a render thread as a modal dialog.
  if (rendering) fail("message during render: " + text);
  return std::strcmp(type, kOfxMessageQuestion) == 0 ? kOfxStatReplyNo
                                                      : kOfxStatOK;
}

OfxStatus Effect::setPersistentMessage(const char *type, const char *,
                                       const char *fmt, va_list args) {
  persistentError = format(fmt, args);
  persistentType = type ? type : "";
  std::cerr << "refhost: persistent message (" << type
            << "): " << persistentError << std::endl;
  return kOfxStatOK;
}

OfxStatus Effect::clearPersistentMessage() {
  persistentError.clear();
  return kOfxStatOK;
}

// The spec roots the extent at 0,0; size goes with offset. The project is
// not letterboxed here, so size equals extent.
void Effect::getProjectSize(double &x, double &y) const {
  x = kProjectWidth, y = kProjectHeight;
}
void Effect::getProjectOffset(double &x, double &y) const { x = y = 0; }
void Effect::getProjectExtent(double &x, double &y) const {
  x = kProjectWidth, y = kProjectHeight;
}
double Effect::getProjectPixelAspectRatio() const { return 1.0; }
double Effect::getEffectDuration() const { return 10.0; }
double Effect::getFrameRate() const { return 24.0; }
double Effect::getFrameRecursive() const { return 0.0; }
void Effect::getRenderScaleRecursive(double &x, double &y) const {
  x = renderScale.x, y = renderScale.y;
}

P::Instance *Effect::newParam(const std::string &name, P::Descriptor &d) {
  const std::string &type = d.getType();
  if (type == kOfxParamTypeDouble) return new DoubleParam(d, this);
  if (type == kOfxParamTypeDouble2D) return new Double2DParam(d, this);
  if (type == kOfxParamTypeInteger)
    return new IntLikeParam<P::IntegerInstance>(d, this);
  if (type == kOfxParamTypeChoice)
    return new IntLikeParam<P::ChoiceInstance>(d, this);
  if (type == kOfxParamTypeBoolean) return new BoolParam(d, this);
  if (type == kOfxParamTypeString) return new StringParam(d, this);
  if (type == kOfxParamTypeGroup) return new P::GroupInstance(d, this);
  if (type == kOfxParamTypePage) return new P::PageInstance(d, this);
  if (type == kOfxParamTypePushButton) return new P::PushbuttonInstance(d, this);
  fail("param " + name + " has a type this host does not offer: " + type);
  return nullptr;
}

OfxStatus Effect::editBegin(const std::string &) {
  return refuseEditBlocks ? kOfxStatErrMissingHostFeature : kOfxStatOK;
}
OfxStatus Effect::editEnd() { return kOfxStatOK; }

void Effect::paramChangedByPlugin(P::Instance *param) {
  // The spec forbids param writes from render-time actions.
  if (rendering) fail("param " + param->getName() + " written during a render");
  OFX::Host::ImageEffect::Instance::paramChangedByPlugin(param);
}

void Effect::progressStart(const std::string &, const std::string &) {}
void Effect::progressEnd() {}
bool Effect::progressUpdate(double) { return true; }
double Effect::timeLineGetTime() { return 0.0; }
void Effect::timeLineGotoTime(double) {}
void Effect::timeLineGetBounds(double &t1, double &t2) { t1 = 0, t2 = 10; }

// ---------------------------------------------------------------- images

static int bytesPerComponent(const std::string &depth) {
  if (depth == kOfxBitDepthByte) return 1;
  if (depth == kOfxBitDepthShort) return 2;
  return 4;
}

float Pixels::at(int x, int y, int c) const {
  const int w = bounds.x2 - bounds.x1;
  const size_t i = (size_t(y - bounds.y1) * w + (x - bounds.x1)) * 4 + c;
  const int n = bytesPerComponent(depth);
  if (n == 1) return bytes[i] / 255.0f;
  if (n == 2) {
    unsigned short s;
    std::memcpy(&s, &bytes[i * 2], 2);
    return s / 65535.0f;
  }
  float f;
  std::memcpy(&f, &bytes[i * 4], 4);
  return f;
}

static void store(Pixels &p, size_t i, float v) {
  const int n = bytesPerComponent(p.depth);
  const float c = std::fmin(std::fmax(v, 0.0f), 1.0f);
  if (n == 1) {
    p.bytes[i] = (unsigned char)std::lround(c * 255.0f);
  } else if (n == 2) {
    unsigned short s = (unsigned short)std::lround(c * 65535.0f);
    std::memcpy(&p.bytes[i * 2], &s, 2);
  } else {
    std::memcpy(&p.bytes[i * 4], &v, 4);
  }
}

float sourceValue(const std::string &clip, double x, double y, int channel) {
  // The mattes: the mask's alpha a ramp across, the timing matte's up.
  if (clip == "Mask") return channel == 3 ? float(x / kProjectWidth) : 1.0f;
  if (clip == "Timing") return channel == 3 ? float(y / kProjectHeight) : 0.0f;
  if (channel == 3) return 1.0f;
  const bool isA = clip == "Source" || clip == "SourceA" || clip == "SourceFrom";
  if (isA) {
    const double v[3] = {x / kProjectWidth, y / kProjectHeight, 0.25};
    return float(v[channel]);
  }
  const bool light = (int(std::floor(x / 8)) + int(std::floor(y / 8))) % 2 == 0;
  const double v[3] = {light ? 0.9 : 0.1, 0.5, light ? 0.2 : 0.8};
  return float(v[channel]);
}

class Image : public OFX::Host::ImageEffect::Image {
 public:
  Image(Clip &clip, const Effect &effect, const std::shared_ptr<Pixels> &px,
        const OfxRectI &rod, OfxTime time)
      : OFX::Host::ImageEffect::Image(
            clip, effect.renderScale.x, effect.renderScale.y, px->bytes.data(),
            px->bounds, rod,
            (px->bounds.x2 - px->bounds.x1) * 4 * bytesPerComponent(px->depth),
            kOfxImageFieldNone,
            clip.getName() + "@" + std::to_string(time)),
        pixels_(px) {}

 private:
  std::shared_ptr<Pixels> pixels_;
};

// ---------------------------------------------------------------- clips

Clip::Clip(Effect *effect, OFX::Host::ImageEffect::ClipDescriptor &desc)
    : OFX::Host::ImageEffect::ClipInstance(effect, desc), effect_(effect) {}

const std::string &Clip::getUnmappedBitDepth() const {
  return effect_->sourceDepth;
}
const std::string &Clip::getUnmappedComponents() const {
  return effect_->sourceComponents;
}
const std::string &Clip::getPremult() const {
  static const std::string premult = kOfxImagePreMultiplied;
  static const std::string straight = kOfxImageUnPreMultiplied;
  return effect_->straight ? straight : premult;
}
double Clip::getAspectRatio() const { return 1.0; }
double Clip::getFrameRate() const { return 24.0; }
void Clip::getFrameRange(double &s, double &e) const { s = 0, e = 10; }
const std::string &Clip::getFieldOrder() const {
  static const std::string none = kOfxImageFieldNone;
  return none;
}
bool Clip::getConnected() const {
  if (getName() == "Mask") return effect_->connected && effect_->maskConnected;
  if (getName() == "Timing") return effect_->connected && effect_->timingConnected;
  return isOutput() || effect_->connected;
}
double Clip::getUnmappedFrameRate() const { return 24.0; }
void Clip::getUnmappedFrameRange(double &s, double &e) const { s = 0, e = 10; }
bool Clip::getContinuousSamples() const { return false; }

OfxRectD Clip::getRegionOfDefinition(OfxTime) const {
  // An unconnected clip has no picture, so no region.
  if (!getConnected()) return OfxRectD{0, 0, 0, 0};
  OfxRectD r = {0, 0, double(kProjectWidth), double(kProjectHeight)};
  return r;
}

OfxRectI toPixels(const OfxRectD &r, OfxPointD scale) {
  OfxRectI p = {int(std::floor(r.x1 * scale.x)), int(std::floor(r.y1 * scale.y)),
                int(std::ceil(r.x2 * scale.x)), int(std::ceil(r.y2 * scale.y))};
  return p;
}

static OfxRectI intersect(const OfxRectI &a, const OfxRectI &b) {
  OfxRectI r = {std::max(a.x1, b.x1), std::max(a.y1, b.y1),
                std::min(a.x2, b.x2), std::min(a.y2, b.y2)};
  if (r.x2 < r.x1) r.x2 = r.x1;
  if (r.y2 < r.y1) r.y2 = r.y1;
  return r;
}

OFX::Host::ImageEffect::Image *Clip::getImage(OfxTime time,
                                              const OfxRectD *bounds) {
  const OfxPointD scale = effect_->renderScale;
  const OfxRectI rod = toPixels(getRegionOfDefinition(time), scale);
  if (!getConnected()) return nullptr;
  auto px = std::make_shared<Pixels>();
  px->depth = getPixelDepth();
  if (isOutput()) {
    // A real host's output buffer holds whatever was there before: NaN
    // makes any pixel of the render window left unwritten visible.
    px->bounds = effect_->renderWindow;
    const size_t n = size_t(px->bounds.x2 - px->bounds.x1) *
                     (px->bounds.y2 - px->bounds.y1) * 4;
    px->bytes.assign(n * bytesPerComponent(px->depth), 0xff);
    output = px;
    return new Image(*this, *effect_, px, rod, time);
  }
  // Like real hosts, hand over only what the plugin asked for: the region
  // it passed, else the region of interest it gave for this render.
  OfxRectI want = rod;
  if (bounds) {
    want = intersect(rod, toPixels(*bounds, scale));
  } else {
    auto roi = effect_->regionsOfInterest.find(this);
    if (roi != effect_->regionsOfInterest.end())
      want = intersect(rod, toPixels(roi->second, scale));
  }
  px->bounds = want;
  const int w = want.x2 - want.x1, h = want.y2 - want.y1;
  px->bytes.assign(size_t(w) * h * 4 * bytesPerComponent(px->depth), 0);
  for (int y = want.y1; y < want.y2; ++y)
    for (int x = want.x1; x < want.x2; ++x)
      for (int c = 0; c < 4; ++c) {
        const size_t i = (size_t(y - want.y1) * w + (x - want.x1)) * 4 + c;
        store(*px, i,
              sourceValue(getName(), (x + 0.5) / scale.x, (y + 0.5) / scale.y, c));
      }
  return new Image(*this, *effect_, px, rod, time);
}

}  // namespace refhost
