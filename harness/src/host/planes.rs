//! The multi-plane extension as Natron offers it (The Foundry's
//! `fnOfxExtensions.h` with Natron's encoded planes): the host descriptor
//! says it is multi-planar, clips list their planes, a multi-planar plugin
//! says which it needs and makes (`GetClipComponents`), the render action
//! names the planes to fill, and the plane suite hands out each plane's
//! image, whose components string is the plane's own.

use std::ffi::{c_char, CStr};
use std::sync::Arc;

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;

use super::effect::{clip_get_image, clip_of, Clip};
use super::frame::Frame;
use crate::sync::Locked;

pub const MULTI_PLANAR: &CStr = c"uk.co.thefoundry.OfxImageEffectPropMultiPlanar";
pub const PLANE_SUITE: &CStr = c"uk.co.thefoundry.FnOfxImageEffectPlaneSuite";
pub const PLANES_PRESENT: &CStr = c"uk.co.thefoundry.OfxImageEffectClipPropPlanesPresent";
pub const RENDER_PLANES: &CStr = c"OfxImageEffectPropRenderPlanes";
pub const GET_CLIP_COMPONENTS: &CStr = c"uk.co.thefoundry.OfxImageEffectActionGetClipComponents";
pub const NEEDED_PREFIX: &str = "uk.co.thefoundry.OfxNeededComp_";
pub const PASS_THROUGH_CLIP: &CStr = c"uk.co.thefoundry.ImageEffectPropPassThroughClip";
pub const COLOUR: &str = "uk.co.thefoundry.OfxImagePlaneColour";
const NATRON_PLANE: &str = "NatronOfxImageComponentsPlaneName_";
const NATRON_CHANNEL: &str = "_Channel_";

/// Natron's string for layer `name` with `channels` (1 to 4): the plane's
/// name in every call and its images' components.
pub fn plane(name: &str, channels: &[&str]) -> String {
    let mut s = format!("{NATRON_PLANE}{name}");
    for c in channels {
        s.push_str(NATRON_CHANNEL);
        s.push_str(c);
    }
    s
}

/// How many channels a plane string's images have (`None`: not a plane
/// this host makes).
pub fn channels(plane: &str) -> Option<usize> {
    let n = plane
        .strip_prefix(NATRON_PLANE)?
        .matches(NATRON_CHANNEL)
        .count();
    (1..=4).contains(&n).then_some(n)
}

/// The plane suite, version 1. While [`crate::host::Instance::render_planes`]
/// renders, the output's colour is one of its planes, handed out only
/// here, as Natron does for a multi-planar effect (its `clipGetImage` of
/// the output then gives no image).
#[repr(C)]
#[allow(non_snake_case)] // the C struct's field name
pub struct PlaneSuiteV1 {
    pub clipGetImagePlane: Option<
        unsafe extern "C" fn(
            OfxImageClipHandle,
            OfxTime,
            *const c_char,
            *const OfxRectD,
            *mut OfxPropertySetHandle,
        ) -> OfxStatus,
    >,
}

pub static SUITE: PlaneSuiteV1 = PlaneSuiteV1 {
    clipGetImagePlane: Some(clip_get_image_plane),
};

impl Clip {
    /// This clip's frame of `plane` at `time`, at the render scale in force:
    /// the output's buffer of it during a render, else its source's.
    fn plane_at(&self, plane: &str, time: f64) -> Result<Option<Arc<Frame>>, String> {
        if let Some((_, out)) = self.output_planes.locked().iter().find(|(p, _)| p == plane) {
            return Ok(Some(out.clone()));
        }
        let source = self
            .planes
            .locked()
            .iter()
            .find(|(p, _)| p == plane)
            .map(|(_, s)| s.clone());
        let Some(source) = source else {
            return Ok(None);
        };
        let frame = source.frame(time)?;
        let scale = *self.effect().render_scale.locked();
        Ok(Some(match scale == (1.0, 1.0) {
            true => frame,
            false => Arc::new(frame.scaled(scale)),
        }))
    }
}

unsafe extern "C" fn clip_get_image_plane(
    clip: OfxImageClipHandle,
    time: OfxTime,
    plane: *const c_char,
    region: *const OfxRectD,
    image: *mut OfxPropertySetHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "clip_get_image_plane", || {
        if plane.is_null() || image.is_null() {
            return kOfxStatErrBadHandle;
        }
        // SAFETY: the plugin passes a NUL-terminated plane name.
        let name = unsafe { CStr::from_ptr(plane) }
            .to_string_lossy()
            .into_owned();
        // SAFETY: the plugin passes a clip handle we gave it (see `clip_of`).
        let Some(c) = (unsafe { clip_of(clip) }) else {
            return kOfxStatErrBadHandle;
        };
        let rendering = c.output_planes.locked().iter().any(|(p, _)| p == COLOUR);
        if name == COLOUR && !rendering {
            // SAFETY: the plugin's own arguments, passed on unchanged.
            return unsafe { clip_get_image(clip, time, region, image) };
        }
        let frame = match c.plane_at(&name, time) {
            Ok(Some(f)) => f,
            // The extension: a plane the clip cannot give fails the call,
            // and the plugin takes it as transparent black.
            Ok(None) | Err(_) => return kOfxStatFailed,
        };
        let scale = *c.effect().render_scale.locked();
        let props = frame.image_props(scale, time);
        if name != COLOUR {
            props.set_str(kOfxImageEffectPropComponents, &name);
        }
        super::misuse::tamper_image(&c.name, &props);
        // SAFETY: out-pointer from the plugin. The boxed set (owning the
        // frame) is released by clipReleaseImage.
        unsafe { *image = Box::into_raw(Box::new(props)) as OfxPropertySetHandle };
        kOfxStatOK
    })
}
