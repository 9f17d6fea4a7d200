//! What a host sees of a node just made, before anything is connected, and
//! how its errors reach the host: the spec lets interface actions come while
//! non-optional clips are unconnected, and Natron asks for the region of
//! definition at once, showing any failure as an ERROR badge on the node.
//! Every action goes through the plugin's C entry point.

use std::sync::Arc;

mod common;

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::host::misuse::{arm, Misuse};
use morphfx_harness::host::props::{PropertySet, Value};
use morphfx_harness::host::{Bundle, Frame, Instance, Message, OutputSpec};
use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::param::*;

use common::{bundle_path, Still};

const NODES: [(&str, &[&str]); 2] = [
    (
        "net.morphfx.Morph",
        &[
            "OfxImageEffectContextGeneral",
            "OfxImageEffectContextTransition",
        ],
    ),
    (
        "net.morphfx.Warp",
        &[
            "OfxImageEffectContextFilter",
            "OfxImageEffectContextGeneral",
        ],
    ),
];

fn bundle() -> &'static Bundle {
    static B: std::sync::OnceLock<Bundle> = std::sync::OnceLock::new();
    B.get_or_init(|| Bundle::load(&bundle_path()).expect("the bundle loads"))
}

/// The project the instances live in, not square so x/y mix-ups show.
const PROJECT: (f64, f64) = (40.0, 24.0);

fn time_and_scale() -> PropertySet {
    let a = PropertySet::new();
    a.set_double(kOfxPropTime, &[0.0]);
    a.set_double(kOfxImageEffectPropRenderScale, &[1.0, 1.0]);
    a
}

/// The interface actions a host sends a node, each with the arguments the
/// spec gives it (out-args set to their defaults first, as a host does).
fn interface_actions(inst: &Instance) -> Vec<(&'static std::ffi::CStr, PropertySet, PropertySet)> {
    let project = [0.0, 0.0, PROJECT.0, PROJECT.1];
    let rod_out = PropertySet::new();
    rod_out.set_double(kOfxImageEffectPropRegionOfDefinition, &project);
    let roi_in = time_and_scale();
    roi_in.set_double(kOfxImageEffectPropRegionOfInterest, &project);
    let roi_out = PropertySet::new();
    let frames_out = PropertySet::new();
    for clip in inst.effect.clip_names().iter().filter(|c| *c != "Output") {
        let roi = std::ffi::CString::new(format!("OfxImageClipPropRoI_{clip}")).unwrap();
        roi_out.set_double(&roi, &project);
        let range = std::ffi::CString::new(format!("OfxImageClipPropFrameRange_{clip}")).unwrap();
        frames_out.set_double(&range, &[0.0, 0.0]);
    }
    let identity_in = time_and_scale();
    identity_in.set_str(kOfxImageEffectPropFieldToRender, "OfxImageFieldNone");
    identity_in.set_int(
        kOfxImageEffectPropRenderWindow,
        &[0, 0, PROJECT.0 as i32, PROJECT.1 as i32],
    );
    let identity_out = PropertySet::new();
    identity_out.set_str(kOfxPropName, "");
    identity_out.set_double(kOfxPropTime, &[0.0]);
    let prefs_out = PropertySet::new();
    prefs_out.set_int(kOfxImageEffectFrameVarying, &[0]);
    prefs_out.set_str(
        kOfxImageEffectPropPreMultiplication,
        "OfxImageAlphaPremultiplied",
    );
    let frames_in = PropertySet::new();
    frames_in.set_double(kOfxPropTime, &[0.0]);
    vec![
        (
            kOfxImageEffectActionGetRegionOfDefinition,
            time_and_scale(),
            rod_out,
        ),
        (kOfxImageEffectActionGetRegionsOfInterest, roi_in, roi_out),
        (kOfxImageEffectActionGetFramesNeeded, frames_in, frames_out),
        (
            kOfxImageEffectActionGetClipPreferences,
            PropertySet::new(),
            prefs_out,
        ),
        (kOfxImageEffectActionIsIdentity, identity_in, identity_out),
    ]
}

#[test]
fn a_node_with_nothing_connected_answers_every_interface_action_without_an_error() {
    for (id, contexts) in NODES {
        for context in contexts {
            let inst = bundle().instance(id, context).unwrap();
            inst.set_project(PROJECT.0, PROJECT.1);
            for (action, in_args, out_args) in interface_actions(&inst) {
                let name = action.to_string_lossy();
                let in_args =
                    (action != kOfxImageEffectActionGetClipPreferences).then_some(&in_args);
                let (status, messages) = inst.send_raw(action, false, in_args, Some(&out_args));
                assert!(
                    status == kOfxStatOK || status == kOfxStatReplyDefault,
                    "{id} in {context}: {name} answered {status} with nothing connected: \
                     {messages:?}"
                );
                assert!(
                    messages.is_empty(),
                    "{id} in {context}: {name} posted {messages:?} with nothing connected"
                );
            }
            // Nothing to define a region by: the host's default (the
            // project, for clips that have none), and no source to be.
            let rod = inst.region_of_definition(0.0, (1.0, 1.0)).unwrap();
            assert_eq!(rod, RectI::new(0, 0, 40, 24), "{id} in {context}");
            let window = RectI::new(0, 0, 40, 24);
            assert_eq!(inst.identity(0.0, window, (1.0, 1.0)).unwrap(), None);
        }
    }
}

#[test]
fn the_region_of_definition_is_the_plugins_once_a_source_is_connected() {
    let inst = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    inst.set_project(PROJECT.0, PROJECT.1);
    let out = PropertySet::new();
    out.set_double(
        kOfxImageEffectPropRegionOfDefinition,
        &[0.0, 0.0, 40.0, 24.0],
    );
    connect_plate(&inst, "Source", RectI::new(-3, 2, 13, 11));
    let (status, messages) = inst.send_raw(
        kOfxImageEffectActionGetRegionOfDefinition,
        false,
        Some(&time_and_scale()),
        Some(&out),
    );
    assert_eq!(status, kOfxStatOK, "{messages:?}");
    assert_eq!(
        out.doubles(kOfxImageEffectPropRegionOfDefinition),
        vec![-3.0, 2.0, 13.0, 11.0]
    );
}

fn connect_plate(inst: &Instance, clip: &str, bounds: RectI) {
    let img = Image::from_fn(
        bounds,
        4,
        |i, j, c| {
            if c == 3 {
                1.0
            } else {
                (i + j) as f32 * 0.02
            }
        },
    );
    let frame = Arc::new(Frame::from_image(&img, "OfxBitDepthFloat", false));
    inst.connect(clip, Arc::new(Still(frame))).unwrap();
}

/// The persistent message the last action left, if any.
fn persistent(messages: &[Message]) -> Option<&Message> {
    messages.iter().find(|m| m.kind == "OfxMessageError")
}

/// In a host that loses a message's arguments, as Natron 2.5 does, the
/// text still arrives whole: it is sent as the format itself.
#[test]
fn a_real_failure_sets_the_persistent_message_with_its_percent_signs_intact() {
    let _natron = arm(&[Misuse::MessageArgumentsLost]);
    let inst = bundle()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    inst.set_project(PROJECT.0, PROJECT.1);
    connect_plate(&inst, "Source", RectI::new(0, 0, 40, 24));
    // A conversion the host would read an argument for, were it not doubled.
    let path = "/no/such/folder/take 100%d %s.morph.json";
    inst.set_string("scene_file", path).unwrap();
    let spec = OutputSpec {
        identity: false,
        ..OutputSpec::default()
    };
    // Through the persistent message (message suite v2), word for word.
    let err = inst
        .render(0.0, spec)
        .expect_err("a missing scene file fails the render");
    assert!(
        err.to_string().contains(&format!("scene file {path}: ")),
        "the message arrived as {err}"
    );
    let (_, messages) = inst.send_raw(kOfxActionPurgeCaches, false, None, None);
    let m = persistent(&messages).unwrap_or_else(|| panic!("no error on the node: {messages:?}"));
    assert!(m.text.contains(path), "{m:?}");
    // It stays on the node until a render succeeds.
    inst.render(0.0, spec).expect_err("still missing");
    inst.set_string("scene_file", "").unwrap();
    inst.render(0.0, spec).unwrap();
    let (_, messages) = inst.send_raw(kOfxActionPurgeCaches, false, None, None);
    assert!(persistent(&messages).is_none(), "{messages:?}");
}

#[test]
fn no_position_param_asks_for_host_handles_while_the_overlay_is_declared() {
    for (id, contexts) in NODES {
        for context in contexts {
            let inst = bundle().instance(id, context).unwrap();
            let overlay = match inst
                .descriptor_props()
                .get(&kOfxImageEffectPluginPropOverlayInteractV1.to_string_lossy())
            {
                Some(Value::P(p)) => p.first().copied().unwrap_or(0),
                _ => 0,
            };
            assert_ne!(overlay, 0, "{id} in {context} declares no overlay");
            let points: Vec<String> = inst
                .param_names()
                .into_iter()
                .filter(|(_, kind)| kind == "OfxParamTypeDouble2D")
                .map(|(name, _)| name)
                .collect();
            assert!(
                points.len() >= 4 * 64,
                "{id}: {} position params",
                points.len()
            );
            for name in points {
                let asks = inst
                    .param_props(&name)
                    .unwrap()
                    .ints(kOfxParamPropUseHostOverlayHandle);
                assert!(
                    asks.iter().all(|v| *v == 0),
                    "{id} in {context}: {name} asks for the host's overlay handle ({asks:?})"
                );
            }
        }
    }
}
