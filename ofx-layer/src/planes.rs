//! The multi-plane extension of Nuke and Natron (The Foundry's
//! `fnOfxExtensions.h`, Natron's `ofxNatron.h`): a clip carries planes
//! besides its colour (a CG render's AOVs, mattes, IDs, motion vectors); a
//! multi-planar effect says which planes it reads and makes
//! (`GetClipComponents`), the render action names the planes to fill, and
//! each plane is fetched through the plane suite.
//!
//! A plane is named by a string: The Foundry's (colour, motion vectors,
//! disparity), or Natron's encoding of any layer,
//! `NatronOfxImageComponentsPlaneName_<name>[_PlaneLabel_<label>]
//! [_ChannelsLabel_<label>]_Channel_<c1>…` with 1 to 4 channels, which is
//! also the components string of that plane's images.

use std::ffi::{c_char, CStr};

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;

/// Host and effect descriptors: the effect fetches planes (int, 0 or 1).
pub const MULTI_PLANAR: &CStr = c"uk.co.thefoundry.OfxImageEffectPropMultiPlanar";
/// Effect descriptor: what the host does with the planes the effect does
/// not make (0 block, 1 pass through from the pass-through clip).
pub const PASS_THROUGH_COMPONENTS: &CStr =
    c"uk.co.thefoundry.OfxImageEffectPropPassThroughComponents";
/// Effect descriptor: every plane in one render action (1).
pub const RENDER_ALL_PLANES: &CStr = c"OfxImageEffectPropRenderAllPlanes";
/// Clip instance: the planes present on the clip (string × N).
pub const PLANES_PRESENT: &CStr = c"uk.co.thefoundry.OfxImageEffectClipPropPlanesPresent";
/// Render in-arg: the planes to fill (string × N; none: colour).
pub const RENDER_PLANES: &CStr = c"OfxImageEffectPropRenderPlanes";
/// The action asking which planes each clip needs and the output makes.
pub const GET_CLIP_COMPONENTS: &CStr = c"uk.co.thefoundry.OfxImageEffectActionGetClipComponents";
/// Out-arg prefix of `GET_CLIP_COMPONENTS`, followed by a clip's name.
pub const NEEDED_PREFIX: &str = "uk.co.thefoundry.OfxNeededComp_";
/// Out-args of `GET_CLIP_COMPONENTS`: where planes not made come from.
pub const PASS_THROUGH_CLIP: &CStr = c"uk.co.thefoundry.ImageEffectPropPassThroughClip";
pub const PASS_THROUGH_TIME: &CStr = c"uk.co.thefoundry.ImageEffectPropPassThroughTime";
/// The plane suite's name (version 1 fetches a plane).
pub const PLANE_SUITE: &CStr = c"uk.co.thefoundry.FnOfxImageEffectPlaneSuite";

/// The colour plane: what `clipGetImage` gives.
pub const COLOUR: &str = "uk.co.thefoundry.OfxImagePlaneColour";
const FORWARD: &str = "uk.co.thefoundry.OfxImagePlaneForwardMotionVector";
const BACKWARD: &str = "uk.co.thefoundry.OfxImagePlaneBackMotionVector";
const DISPARITY_LEFT: &str = "uk.co.thefoundry.OfxImagePlaneStereoDisparityLeft";
const DISPARITY_RIGHT: &str = "uk.co.thefoundry.OfxImagePlaneStereoDisparityRight";
/// Natron's encoding of a layer.
pub const NATRON_PLANE: &str = "NatronOfxImageComponentsPlaneName_";
const NATRON_LABEL: &str = "_PlaneLabel_";
const NATRON_CHANNELS_LABEL: &str = "_ChannelsLabel_";
pub const NATRON_CHANNEL: &str = "_Channel_";

/// The Foundry's plane suite, version 1 (`FnOfxImageEffectPlaneSuiteV1`).
#[repr(C)]
#[allow(non_snake_case)] // the C struct's field name
pub struct PlaneSuiteV1 {
    /// As `clipGetImage`, for the named plane.
    pub clipGetImagePlane: Option<
        unsafe extern "C" fn(
            clip: OfxImageClipHandle,
            time: OfxTime,
            plane: *const c_char,
            region: *const OfxRectD,
            image: *mut OfxPropertySetHandle,
        ) -> OfxStatus,
    >,
}

/// The channel count of an image's components string: OpenFX's own,
/// Natron's two-channel `XY`, The Foundry's motion vectors and disparity
/// (two channels each), and Natron's encoded planes (1 to 4).
pub fn channels_of(components: &str) -> Option<usize> {
    match components {
        "OfxImageComponentRGBA" => Some(4),
        "OfxImageComponentRGB" => Some(3),
        "OfxImageComponentAlpha" => Some(1),
        "NatronOfxImageComponentXY"
        | "uk.co.thefoundry.OfxImageComponentMotionVectors"
        | "uk.co.thefoundry.OfxImageComponentStereoDisparity" => Some(2),
        other => {
            let n = other
                .strip_prefix(NATRON_PLANE)?
                .matches(NATRON_CHANNEL)
                .count();
            (1..=4).contains(&n).then_some(n)
        }
    }
}

/// A plane string's layer name, as a compositor reads it: Natron's plane
/// name (`crypto00`, `N`), or a word for The Foundry's planes; the string
/// itself when it is neither.
pub fn name_of(plane: &str) -> &str {
    match plane {
        COLOUR => "rgba",
        FORWARD => "forward",
        BACKWARD => "backward",
        DISPARITY_LEFT => "disparityL",
        DISPARITY_RIGHT => "disparityR",
        other => match other.strip_prefix(NATRON_PLANE) {
            Some(rest) => {
                let end = [NATRON_LABEL, NATRON_CHANNELS_LABEL, NATRON_CHANNEL]
                    .iter()
                    .filter_map(|m| rest.find(m))
                    .min()
                    .unwrap_or(rest.len());
                &rest[..end]
            }
            None => other,
        },
    }
}

/// A Natron plane string for layer `name` with `channels` (what a host
/// hands out, and the components of that plane's images).
pub fn natron_plane(name: &str, channels: &[&str]) -> String {
    let mut s = format!("{NATRON_PLANE}{name}");
    for c in channels {
        s.push_str(NATRON_CHANNEL);
        s.push_str(c);
    }
    s
}

/// Which planes each clip needs, and where the planes the output does not
/// make pass through from: the effect's answer to `GetClipComponents`.
#[derive(Debug, Default, PartialEq)]
pub struct ClipPlanes {
    pub(super) needed: Vec<(&'static str, Vec<String>)>,
    pub(super) pass_through: Option<(&'static str, f64)>,
}

impl ClipPlanes {
    /// `clip` (the output: the planes it makes) needs `planes`.
    pub fn set(&mut self, clip: &'static str, planes: Vec<String>) {
        self.needed.push((clip, planes));
    }
    /// Planes the output does not make come from `clip` at `time`.
    pub fn pass_through(&mut self, clip: &'static str, time: f64) {
        self.pass_through = Some((clip, time));
    }
}

/// Whether `plane` is the colour plane (also what a host's empty list means).
pub fn is_colour(plane: &str) -> bool {
    plane == COLOUR
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn natron_planes_say_their_name_and_channels() {
        let n = natron_plane("N", &["X", "Y", "Z"]);
        assert_eq!(
            n,
            "NatronOfxImageComponentsPlaneName_N_Channel_X_Channel_Y_Channel_Z"
        );
        assert_eq!((name_of(&n), channels_of(&n)), ("N", Some(3)));
        let labelled = "NatronOfxImageComponentsPlaneName_fr.unique.id.position_PlaneLabel_Position_Channel_X_Channel_Y_Channel_Z";
        assert_eq!(name_of(labelled), "fr.unique.id.position");
        let disparity = "NatronOfxImageComponentsPlaneName_DisparityLeft_ChannelsLabel_Disparity_Channel_X_Channel_Y";
        assert_eq!(
            (name_of(disparity), channels_of(disparity)),
            ("DisparityLeft", Some(2))
        );
        let five = natron_plane("big", &["a", "b", "c", "d", "e"]);
        assert_eq!(channels_of(&five), None, "a plane has 1 to 4 channels");
        assert_eq!(channels_of(&natron_plane("none", &[])), None);
    }

    #[test]
    fn foundry_planes_and_openfx_components_are_known() {
        assert_eq!(name_of(COLOUR), "rgba");
        assert_eq!(name_of(FORWARD), "forward");
        assert_eq!(channels_of("OfxImageComponentRGB"), Some(3));
        assert_eq!(channels_of("NatronOfxImageComponentXY"), Some(2));
        assert_eq!(channels_of("OfxImageComponentNone"), None);
        assert_eq!(channels_of("something else"), None);
    }
}
