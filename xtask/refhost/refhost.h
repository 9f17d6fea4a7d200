// A small OpenFX host built on the OpenFX reference host library
// (HostSupport), used by `cargo xtask test` to load the MorphFX bundle the
// way hosts built on that library do. It is deliberately strict: anything
// the spec calls an error, and anything a compositor would see as one (an
// error message, a render window left unwritten, a param written during a
// render), is recorded as a failure.
#pragma once

#include <cstdarg>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ofxCore.h"
#include "ofxImageEffect.h"

// The library's headers are not self-contained: this order is the one its
// own sources use.
#include "ofxhBinary.h"
#include "ofxhPropertySuite.h"
#include "ofxhClip.h"
#include "ofxhParam.h"
#include "ofxhMemory.h"
#include "ofxhImageEffect.h"
#include "ofxhPluginAPICache.h"
#include "ofxhPluginCache.h"
#include "ofxhHost.h"
#include "ofxhImageEffectAPI.h"

namespace refhost {

/// The project every instance lives in: small, so the debug build of the
/// plugin renders each check quickly; not square, so x/y mix-ups show.
constexpr int kProjectWidth = 96;
constexpr int kProjectHeight = 64;

/// Failures as they happen, from any callback; the driver reports them.
void fail(const std::string &what);
const std::vector<std::string> &failures();

/// The application: its properties and the factory of instances.
class Host : public OFX::Host::ImageEffect::Host {
 public:
  Host();
  OFX::Host::ImageEffect::Instance *newInstance(
      void *clientData, OFX::Host::ImageEffect::ImageEffectPlugin *plugin,
      OFX::Host::ImageEffect::Descriptor &desc,
      const std::string &context) override;
  OFX::Host::ImageEffect::Descriptor *makeDescriptor(
      OFX::Host::ImageEffect::ImageEffectPlugin *plugin) override;
  OFX::Host::ImageEffect::Descriptor *makeDescriptor(
      const OFX::Host::ImageEffect::Descriptor &rootContext,
      OFX::Host::ImageEffect::ImageEffectPlugin *plugin) override;
  OFX::Host::ImageEffect::Descriptor *makeDescriptor(
      const std::string &bundlePath,
      OFX::Host::ImageEffect::ImageEffectPlugin *plugin) override;
  OfxStatus vmessage(const char *type, const char *id, const char *format,
                     va_list args) override;
  OfxStatus setPersistentMessage(const char *type, const char *id,
                                 const char *format, va_list args) override;
  OfxStatus clearPersistentMessage() override;
};

/// One node. The driver sets what a host's render loop knows (the scale and
/// window of the render under way, the regions of interest it computed);
/// the clips read them.
class Effect : public OFX::Host::ImageEffect::Instance {
 public:
  Effect(OFX::Host::ImageEffect::ImageEffectPlugin *plugin,
         OFX::Host::ImageEffect::Descriptor &desc, const std::string &context);

  /// The depth the host's inputs come in (before clip preferences map it).
  std::string sourceDepth = kOfxBitDepthFloat;
  OfxPointD renderScale = {1.0, 1.0};
  OfxRectI renderWindow = {0, 0, kProjectWidth, kProjectHeight};
  std::map<OFX::Host::ImageEffect::ClipInstance *, OfxRectD> regionsOfInterest;
  bool rendering = false;
  /// Whether the input clips are connected (a node just made has none).
  bool connected = true;
  /// Whether the optional Mask and Timing clips are connected too.
  bool maskConnected = false;
  bool timingConnected = false;
  /// Whether the input clips' colour is straight (not premultiplied).
  bool straight = false;
  /// Whether paramEditBegin is refused, as HostSupport's example host does
  /// (kOfxStatErrMissingHostFeature).
  bool refuseEditBlocks = false;
  /// The components the input clips come in (before clip preferences).
  std::string sourceComponents = kOfxImageComponentRGBA;
  /// The persistent message the plugin last set (empty once cleared), and
  /// its type (kOfxMessageError, kOfxMessageWarning, ...).
  std::string persistentError;
  std::string persistentType;

  const std::string &getDefaultOutputFielding() const override;
  OFX::Host::ImageEffect::ClipInstance *newClipInstance(
      OFX::Host::ImageEffect::Instance *plugin,
      OFX::Host::ImageEffect::ClipDescriptor *descriptor, int index) override;
  OfxStatus vmessage(const char *type, const char *id, const char *format,
                     va_list args) override;
  OfxStatus setPersistentMessage(const char *type, const char *id,
                                 const char *format, va_list args) override;
  OfxStatus clearPersistentMessage() override;
  void getProjectSize(double &x, double &y) const override;
  void getProjectOffset(double &x, double &y) const override;
  void getProjectExtent(double &x, double &y) const override;
  double getProjectPixelAspectRatio() const override;
  double getEffectDuration() const override;
  double getFrameRate() const override;
  double getFrameRecursive() const override;
  void getRenderScaleRecursive(double &x, double &y) const override;
  OFX::Host::Param::Instance *newParam(
      const std::string &name, OFX::Host::Param::Descriptor &desc) override;
  OfxStatus editBegin(const std::string &name) override;
  OfxStatus editEnd() override;
  void paramChangedByPlugin(OFX::Host::Param::Instance *param) override;
  void progressStart(const std::string &message,
                     const std::string &messageid) override;
  void progressEnd() override;
  bool progressUpdate(double t) override;
  double timeLineGetTime() override;
  void timeLineGotoTime(double t) override;
  void timeLineGetBounds(double &t1, double &t2) override;
};

/// Pixels the plugin sees or writes; `pixels` outlives the image the plugin
/// releases, so the driver can read the output after the render.
struct Pixels {
  OfxRectI bounds;
  std::string depth;
  std::vector<unsigned char> bytes;
  /// Channel c of pixel (x, y), as a float whatever the depth.
  float at(int x, int y, int c) const;
};

class Clip : public OFX::Host::ImageEffect::ClipInstance {
 public:
  Clip(Effect *effect, OFX::Host::ImageEffect::ClipDescriptor &desc);
  /// The output image of the last render (null before one).
  std::shared_ptr<Pixels> output;

  const std::string &getUnmappedBitDepth() const override;
  const std::string &getUnmappedComponents() const override;
  const std::string &getPremult() const override;
  double getAspectRatio() const override;
  double getFrameRate() const override;
  void getFrameRange(double &start, double &end) const override;
  const std::string &getFieldOrder() const override;
  bool getConnected() const override;
  double getUnmappedFrameRate() const override;
  void getUnmappedFrameRange(double &start, double &end) const override;
  bool getContinuousSamples() const override;
  OFX::Host::ImageEffect::Image *getImage(OfxTime time,
                                          const OfxRectD *bounds) override;
  OfxRectD getRegionOfDefinition(OfxTime time) const override;

 private:
  Effect *effect_;
};

/// Canonical `r` in pixels at render `scale`, rounded out.
OfxRectI toPixels(const OfxRectD &r, OfxPointD scale);

/// The value every source clip shows at canonical (x, y): A a smooth ramp,
/// B a checkerboard, so warps and dissolves change what the output holds.
float sourceValue(const std::string &clip, double x, double y, int channel);

}  // namespace refhost
