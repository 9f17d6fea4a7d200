//! Hosts that send what the spec does not allow, or fail where it lets them,
//! get a failure status and a message through their message suite from the
//! plugin, never a crash, and the instance renders whole afterwards. One
//! test per kind of misuse, each through the plugin's C entry points.
//!
//! Every test loads its own host ([`host`]): the plugin fetches a host's
//! suites in the load action, and some tests withhold suites.

use std::ffi::CStr;
use std::sync::Arc;

mod common;

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::host::misuse::{arm, Armed, Misuse};
use morphfx_harness::host::planes;
use morphfx_harness::host::props::PropertySet;
use morphfx_harness::host::{
    take_unowned_messages, Bundle, ErrorKind, Frame, FrameSource, HostOptions, Instance, Message,
    OutputSpec,
};
use openfx::sys::generic::core::*;
use openfx::sys::generic::property::*;
use openfx::sys::image_effect_v1::draw_suite::kOfxDrawSuite;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::interact::kOfxInteractSuite;
use openfx::sys::image_effect_v1::memory::kOfxMemorySuite;
use openfx::sys::image_effect_v1::message::kOfxMessageSuite;
use openfx::sys::image_effect_v1::multi_thread::kOfxMultiThreadSuite;
use openfx::sys::image_effect_v1::param::kOfxParameterSuite;
use openfx::sys::image_effect_v1::progress::kOfxProgressSuite;
use openfx::sys::image_effect_v1::time_line::kOfxTimeLineSuite;

use common::{bundle_path, Still};

/// A host of our own with `misuses` armed (and other tests of this file
/// kept out until the first value is dropped).
fn host(misuses: &[Misuse]) -> (Armed, Bundle) {
    let armed = arm(misuses);
    take_unowned_messages();
    let bundle = Bundle::load(&bundle_path()).expect("the bundle loads");
    (armed, bundle)
}

/// A Warp node over a 32 × 24 gradient, no line set.
fn gradient_warp(bundle: &Bundle) -> Instance<'_> {
    let inst = bundle
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    let img = Image::from_fn(RectI::from_size(32, 24), 4, |i, j, c| {
        if c == 3 {
            1.0
        } else {
            (i + 2 * j + c as i32) as f32 * 0.01
        }
    });
    let frame = Arc::new(Frame::from_image(&img, "OfxBitDepthFloat", false));
    inst.connect("Source", Arc::new(Still(frame))).unwrap();
    inst.set_project(32.0, 24.0);
    inst
}

/// A Warp node over a 32 × 24 gradient with one line pair that moves.
fn warp(bundle: &Bundle) -> Instance<'_> {
    let inst = gradient_warp(bundle);
    inst.set_int("line_count", 1).unwrap();
    for (id, v) in [
        ("a_start", [4.0, 4.0]),
        ("a_end", [20.0, 6.0]),
        ("b_start", [5.0, 4.0]),
        ("b_end", [21.0, 7.0]),
    ] {
        inst.set_double(&format!("line1_{id}"), &v, None).unwrap();
    }
    inst
}

/// A render, as a well-behaved host sends it.
fn picture(inst: &Instance) -> Image {
    let spec = OutputSpec {
        identity: false,
        ..OutputSpec::default()
    };
    inst.render(0.0, spec).unwrap().to_image()
}

/// The error the plugin posted, or a failure naming what it did not post.
fn error_text(messages: &[Message], what: &str) -> String {
    messages
        .iter()
        .find(|m| m.kind == "OfxMessageError")
        .map(|m| m.text.clone())
        .unwrap_or_else(|| panic!("{what}: no error message, only {messages:?}"))
}

fn failed(status: OfxStatus) -> bool {
    status != kOfxStatOK && status != kOfxStatReplyDefault
}

#[test]
fn an_action_sent_without_an_effect_handle_is_refused_as_a_bad_handle_and_said() {
    let (_armed, b) = host(&[]);
    let inst = warp(&b);
    let good = picture(&inst);
    let actions: [&CStr; 17] = [
        kOfxActionDescribe,
        kOfxImageEffectActionDescribeInContext,
        kOfxActionCreateInstance,
        kOfxActionDestroyInstance,
        kOfxActionPurgeCaches,
        kOfxActionSyncPrivateData,
        kOfxActionBeginInstanceChanged,
        kOfxActionInstanceChanged,
        kOfxActionEndInstanceChanged,
        kOfxImageEffectActionGetRegionOfDefinition,
        kOfxImageEffectActionGetRegionsOfInterest,
        kOfxImageEffectActionGetFramesNeeded,
        kOfxImageEffectActionGetClipPreferences,
        kOfxImageEffectActionIsIdentity,
        kOfxImageEffectActionRender,
        kOfxImageEffectActionBeginSequenceRender,
        kOfxImageEffectActionEndSequenceRender,
    ];
    for action in actions {
        let (status, _) = inst.send_raw(action, true, None, None);
        assert_eq!(status, kOfxStatErrBadHandle, "{action:?}");
        // No effect to attach it to: the message suite v1 takes a null handle.
        let said = take_unowned_messages();
        let text = error_text(&said, &format!("{action:?}"));
        assert!(
            text.contains(&*action.to_string_lossy()) && text.contains("effect handle"),
            "{action:?}: {text}"
        );
    }
    assert_eq!(picture(&inst).data, good.data, "the instance is unharmed");
}

#[test]
fn an_action_sent_without_its_arguments_is_refused_and_said() {
    let (_armed, b) = host(&[]);
    let inst = warp(&b);
    let good = picture(&inst);
    let args = PropertySet::new();
    // (action, in arguments given, out arguments given)
    let cases: [(&CStr, bool, bool); 8] = [
        (kOfxImageEffectActionRender, false, true),
        (kOfxImageEffectActionGetRegionOfDefinition, false, true),
        (kOfxImageEffectActionGetRegionOfDefinition, true, false),
        (kOfxImageEffectActionGetRegionsOfInterest, false, true),
        (kOfxImageEffectActionIsIdentity, true, false),
        (kOfxImageEffectActionGetFramesNeeded, false, true),
        (kOfxImageEffectActionGetClipPreferences, true, false),
        (kOfxActionInstanceChanged, false, true),
    ];
    for (action, with_in, with_out) in cases {
        let (status, said) = inst.send_raw(
            action,
            false,
            with_in.then_some(&args),
            with_out.then_some(&args),
        );
        assert_eq!(status, kOfxStatErrBadHandle, "{action:?}");
        let which = if with_in {
            "out arguments"
        } else {
            "in arguments"
        };
        let text = error_text(&said, &format!("{action:?}"));
        assert!(text.contains(which), "{action:?}: {text}");
    }
    assert_eq!(picture(&inst).data, good.data, "the instance is unharmed");
}

/// Well-formed render arguments for the whole 32 × 24 frame at time 0.
fn render_args() -> PropertySet {
    let a = PropertySet::new();
    a.set_double(kOfxPropTime, &[0.0]);
    a.set_str(kOfxImageEffectPropFieldToRender, "OfxImageFieldNone");
    a.set_int(kOfxImageEffectPropRenderWindow, &[0, 0, 32, 24]);
    a.set_double(kOfxImageEffectPropRenderScale, &[1.0, 1.0]);
    a
}

#[test]
fn arguments_of_the_wrong_type_or_size_are_refused_naming_the_property() {
    let (_armed, b) = host(&[]);
    let inst = warp(&b);
    let good = picture(&inst);
    type Spoil = fn(&PropertySet);
    let cases: [(&CStr, &CStr, Spoil); 5] = [
        (kOfxImageEffectActionRender, kOfxPropTime, |a| {
            a.set_str(kOfxPropTime, "zero")
        }),
        (
            kOfxImageEffectActionRender,
            kOfxImageEffectPropRenderWindow,
            |a| a.set_int(kOfxImageEffectPropRenderWindow, &[0, 0]),
        ),
        (
            kOfxImageEffectActionRender,
            kOfxImageEffectPropRenderWindow,
            |a| a.set_double(kOfxImageEffectPropRenderWindow, &[0.0, 0.0, 32.0, 24.0]),
        ),
        (kOfxImageEffectActionIsIdentity, kOfxPropTime, |a| {
            a.set_ptr(kOfxPropTime, std::ptr::null_mut())
        }),
        (kOfxActionInstanceChanged, kOfxPropName, |a| {
            a.set_int(kOfxPropName, &[3])
        }),
    ];
    for (action, property, spoil) in cases {
        let args = render_args();
        args.set_str(kOfxPropName, "line_count");
        args.set_str(kOfxPropChangeReason, "OfxChangeUserEdited");
        spoil(&args);
        let out = PropertySet::new();
        let (status, said) = inst.send_raw(action, false, Some(&args), Some(&out));
        assert!(failed(status), "{action:?} {property:?}: status {status}");
        let text = error_text(&said, &format!("{action:?} {property:?}"));
        assert!(
            text.contains(&*property.to_string_lossy()) && text.contains("kOfxStatErr"),
            "{action:?}: {text}"
        );
    }
    assert_eq!(picture(&inst).data, good.data, "the instance is unharmed");
}

/// A plane whose images a host says have components no plane has (five
/// channels, where Natron's planes have one to four) is refused as bad
/// input naming the clip and the components, not rendered.
#[test]
fn a_plane_with_components_no_plane_has_is_refused() {
    const FIVE: &str =
        "NatronOfxImageComponentsPlaneName_N_Channel_a_Channel_b_Channel_c_Channel_d_Channel_e";
    let armed = arm(&[Misuse::TamperImage("Source", |p| {
        let planar = p
            .str(kOfxImageEffectPropComponents)
            .is_some_and(|c| c.starts_with("NatronOfx"));
        if planar {
            p.set_str(kOfxImageEffectPropComponents, FIVE);
        }
    })]);
    let options = HostOptions {
        multi_plane: true,
        ..HostOptions::default()
    };
    let b = Bundle::load_with(&bundle_path(), options).expect("the bundle loads");
    let inst = warp(&b);
    let n = planes::plane("N", &["X", "Y", "Z"]);
    let frame = Frame::from_float_image(Image::new(RectI::from_size(32, 24), 3));
    let source: Arc<dyn FrameSource> = Arc::new(Still(Arc::new(frame)));
    inst.connect_planes("Source", vec![(n.clone(), source)])
        .unwrap();
    let err = inst
        .render_planes(0.0, OutputSpec::default(), &[planes::COLOUR.to_owned(), n])
        .expect_err("the render was refused");
    assert_eq!(err.kind, ErrorKind::BadInput, "{}", err.message);
    assert!(
        err.message.contains("clip Source") && err.message.contains(FIVE),
        "{}",
        err.message
    );
    drop(armed);
}

/// Renders with `misuse` armed on a fresh host: the error's text.
fn refused_with(misuse: Misuse) -> String {
    let (_armed, b) = host(&[misuse]);
    let inst = warp(&b);
    let err = inst
        .render(0.0, OutputSpec::default())
        .expect_err("the render was refused");
    err.message
}

#[test]
fn an_image_with_null_data_is_refused() {
    for clip in ["Source", "Output"] {
        let text = refused_with(Misuse::TamperImage(clip, |p| {
            p.set_ptr(kOfxImagePropData, std::ptr::null_mut())
        }));
        assert!(
            text.contains(clip) && text.contains("no pixel data"),
            "{clip}: {text}"
        );
    }
}

#[test]
fn row_bytes_shorter_than_a_row_are_refused() {
    type Spoil = fn(&PropertySet);
    let spoils: [Spoil; 3] = [
        |p| {
            let b = p.ints(kOfxImagePropBounds);
            p.set_int(kOfxImagePropRowBytes, &[(b[2] - b[0]) * 16 - 4])
        },
        |p| {
            let b = p.ints(kOfxImagePropBounds);
            p.set_int(kOfxImagePropRowBytes, &[4 - (b[2] - b[0]) * 16])
        },
        |p| p.set_int(kOfxImagePropRowBytes, &[0]),
    ];
    for spoil in spoils {
        for clip in ["Source", "Output"] {
            let text = refused_with(Misuse::TamperImage(clip, spoil));
            assert!(
                text.contains(clip) && text.contains("row bytes are smaller than a row"),
                "{clip}: {text}"
            );
        }
    }
}

#[test]
fn image_properties_of_the_wrong_type_or_size_are_refused_naming_the_property() {
    type Spoil = fn(&PropertySet);
    let cases: [(&str, Spoil); 4] = [
        ("OfxImagePropBounds", |p| {
            p.set_double(kOfxImagePropBounds, &[0.0, 0.0, 32.0, 24.0])
        }),
        ("OfxImagePropBounds", |p| {
            p.set_int(kOfxImagePropBounds, &[0, 0])
        }),
        ("OfxImagePropRowBytes", |p| {
            p.set_str(kOfxImagePropRowBytes, "512")
        }),
        ("OfxBitDepthHalf", |p| {
            p.set_str(kOfxImageEffectPropPixelDepth, "OfxBitDepthHalf")
        }),
    ];
    for (named, spoil) in cases {
        let text = refused_with(Misuse::TamperImage("Source", spoil));
        assert!(text.contains(named), "{named}: {text}");
    }
}

#[test]
fn a_source_with_no_image_is_transparent_and_no_output_image_is_refused() {
    // The spec (clipGetImage): a plugin that gets kOfxStatFailed carries on
    // as if the image were transparent black.
    let (armed, b) = host(&[Misuse::NoImage("Source")]);
    let inst = warp(&b);
    let out = picture(&inst);
    assert!(out.data.iter().all(|v| *v == 0.0), "not transparent");
    assert_eq!(out.bounds, RectI::from_size(32, 24));
    drop(inst);
    drop(b);
    drop(armed);
    // Without an image to write into there is nothing to do but fail.
    let text = refused_with(Misuse::NoImage("Output"));
    assert!(text.contains("no output image"), "{text}");
}

#[test]
fn params_the_host_cannot_read_fail_the_render_naming_the_param() {
    let (_armed, b) = host(&[Misuse::UnreadableParams]);
    let inst = warp(&b);
    let err = inst
        .render(0.0, OutputSpec::default())
        .expect_err("a render with no readable params");
    assert!(
        err.message.contains("reading") && err.message.contains("kOfxStatErrUnknown"),
        "{}",
        err.message
    );
}

#[test]
fn a_host_without_a_required_suite_fails_the_load_and_says_which() {
    for suite in [kOfxPropertySuite, kOfxImageEffectSuite, kOfxParameterSuite] {
        let (_armed, b) = host(&[Misuse::WithholdSuite(suite)]);
        let err = b
            .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
            .err()
            .expect("no instance without a required suite");
        assert!(
            err.message
                .contains(&kOfxStatErrMissingHostFeature.to_string()),
            "{suite:?}: {}",
            err.message
        );
        let said = take_unowned_messages();
        let text = error_text(&said, &format!("{suite:?}"));
        assert!(text.contains(&*suite.to_string_lossy()), "{text}");
    }
    // Nor, without the message suite as well, does anything crash.
    let (_armed, b) = host(&[
        Misuse::WithholdSuite(kOfxPropertySuite),
        Misuse::WithholdSuite(kOfxMessageSuite),
    ]);
    assert!(b
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .is_err());
}

#[test]
fn a_host_without_an_optional_suite_renders_the_same_picture() {
    let good = {
        let (_armed, b) = host(&[]);
        let inst = warp(&b);
        picture(&inst)
    };
    for suite in [
        kOfxMessageSuite,
        kOfxProgressSuite,
        kOfxInteractSuite,
        kOfxDrawSuite,
        kOfxTimeLineSuite,
        kOfxMemorySuite,
        kOfxMultiThreadSuite,
    ] {
        let (_armed, b) = host(&[Misuse::WithholdSuite(suite)]);
        let inst = warp(&b);
        assert_eq!(picture(&inst).data, good.data, "{suite:?}");
        // A failure still fails, with nobody to tell but the status.
        let spec = OutputSpec {
            window: Some(RectI::new(0, 0, 200_000, 200_000)),
            ..OutputSpec::default()
        };
        assert!(inst.render(0.0, spec).is_err(), "{suite:?}");
    }
}

#[test]
fn a_render_before_begin_sequence_gives_the_picture_a_sequence_does() {
    let (_armed, b) = host(&[]);
    let inst = warp(&b);
    let alone = picture(&inst);
    inst.begin_sequence(0.0, 2.0).unwrap();
    let within = picture(&inst);
    inst.end_sequence(0.0, 2.0).unwrap();
    let after = picture(&inst);
    assert_eq!(alone.data, within.data);
    assert_eq!(alone.data, after.data);
    // An end without a begin is no harm either.
    inst.end_sequence(0.0, 2.0).unwrap();
    assert_eq!(picture(&inst).data, alone.data);
}

#[test]
fn a_render_window_beyond_any_machine_is_refused_before_any_allocation() {
    let (_armed, b) = host(&[]);
    let inst = warp(&b);
    for window in [
        RectI::new(0, 0, 200_000, 200_000),
        RectI::new(i32::MIN, i32::MIN, i32::MAX, i32::MAX),
    ] {
        let spec = OutputSpec {
            identity: false,
            window: Some(window),
            ..OutputSpec::default()
        };
        let err = inst.render(0.0, spec).expect_err("refused");
        assert!(
            err.message.contains("render window") && err.message.contains("limit"),
            "{window:?}: {}",
            err.message
        );
    }
    // The instance is unharmed: a proper render still works.
    inst.render(0.0, OutputSpec::default()).unwrap();
}

/// The OFX types a host may make a param with, as far as values go.
const PARAM_TYPES: [&str; 7] = [
    "OfxParamTypeDouble",
    "OfxParamTypeDouble2D",
    "OfxParamTypeInteger",
    "OfxParamTypeBoolean",
    "OfxParamTypeChoice",
    "OfxParamTypeString",
    "OfxParamTypeGroup",
];

/// Every type but those a param declared as `declared` takes the values of.
fn wrong_types(declared: &str) -> Vec<&'static str> {
    let ints = [
        "OfxParamTypeInteger",
        "OfxParamTypeBoolean",
        "OfxParamTypeChoice",
    ];
    PARAM_TYPES
        .into_iter()
        .filter(|t| *t != declared && !(ints.contains(t) && ints.contains(&declared)))
        .collect()
}

/// A host that made `param` with another type than the plugin declared
/// (`wrong`): the action reading or writing it fails naming the param, and
/// the plugin never calls the host's value functions on it, so the host
/// never writes through a pointer sized for another type.
fn refuses_param_of_wrong_type(
    param: &'static str,
    wrong: &'static str,
    act: fn(&Instance) -> String,
) {
    let (_armed, bundle) = host(&[Misuse::ParamType(param, wrong)]);
    let inst = gradient_warp(&bundle);
    if param != "line_count" {
        inst.set_int("line_count", 1).unwrap();
    }
    let why = act(&inst);
    assert!(
        why.contains(param),
        "{param} made as {wrong}: the failure does not name it: {why}"
    );
    assert_eq!(
        inst.value_calls(param),
        0,
        "{param} made as {wrong}: the plugin called the host's value functions on it"
    );
}

fn render_fails(inst: &Instance) -> String {
    let spec = OutputSpec {
        identity: false,
        ..OutputSpec::default()
    };
    match inst.render(0.0, spec) {
        Ok(_) => String::from("the render succeeded"),
        Err(e) => e.to_string(),
    }
}

fn clear_line_fails(inst: &Instance) -> String {
    match inst.instance_changed("line1_clear", 0.0) {
        Ok(()) => String::from("Clear Line succeeded"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_param_the_host_made_with_another_type_is_never_read_through_the_wrong_pointer() {
    // Reads at render time: one param of each declared type.
    for (param, declared) in [
        ("progress", "OfxParamTypeDouble"),
        ("line_count", "OfxParamTypeInteger"),
        ("use_scene_progress", "OfxParamTypeBoolean"),
        ("method", "OfxParamTypeChoice"),
        ("line1_a_start", "OfxParamTypeDouble2D"),
        ("scene_text", "OfxParamTypeString"),
    ] {
        for wrong in wrong_types(declared) {
            refuses_param_of_wrong_type(param, wrong, render_fails);
        }
    }
}

#[test]
fn a_param_the_host_made_with_another_type_is_never_written_through_the_wrong_values() {
    // Clear Line writes a position and two integers without reading them first.
    for (param, declared) in [
        ("line1_b_end", "OfxParamTypeDouble2D"),
        ("line1_enable", "OfxParamTypeBoolean"),
        ("line_count", "OfxParamTypeInteger"),
    ] {
        for wrong in wrong_types(declared) {
            refuses_param_of_wrong_type(param, wrong, clear_line_fails);
        }
    }
}

#[test]
fn an_instance_sent_to_another_plugins_entry_is_refused_not_cast() {
    let (_armed, b) = host(&[]);
    let inst = warp(&b);
    let args = render_args();
    // A Warp instance handed to the Morph node's main entry: the plugin
    // finds no Morph there and says so, rather than reading a Warp as one.
    let (status, messages) = inst
        .send_via(
            "net.morphfx.Morph",
            kOfxImageEffectActionRender,
            Some(&args),
        )
        .unwrap();
    assert_eq!(status, kOfxStatErrBadHandle);
    let text = error_text(&messages, "render through the wrong entry");
    assert!(text.contains("not a net.morphfx.Morph node"), "{text}");
    // The instance itself is unharmed.
    picture(&inst);
}
