//! Render glue: host images in, core calls, host image out. Conversions to
//! pixel rows, render scale and pixel aspect happen here, once (DESIGN rule 3).

use std::sync::{Arc, Mutex};

use morphfx::features::{Feature, Side};
use morphfx::geom::{PixelScale, RectD, RectI, Vec2};
use morphfx::image::WarpMap;
use morphfx::image::{EdgeMode, ImageView, Layout, Plane, RowsMut, Sample, Sampler};
use morphfx::make_warp::{self, Method, WarpSettings};
use morphfx::morph::{dissolve, dissolve_weighted, show, Warped};
use morphfx::scene::Scene;
use morphfx::transition::{self, Rates, Weights};
use morphfx::views::{self, View};
use morphfx::warp::auto::{self, Correspondence, WorkImage};
use morphfx::warp::mesh::{self, MeshPair, Pass};
use morphfx::warp::thin_plate::multigrid::Report;
use morphfx::warp::thin_plate::ThinPlateWarp;
use morphfx::warp::Warp;
use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::message::*;

use super::instance::{self, Instance, GRIDS_KEPT, PLANES_KEPT, PLATES_KEPT};
use super::params::{Reader, Settings, OFFSET_A, OFFSET_B, TRANSITION_PARAM};
use super::NodeKind;
use crate::cache::key_of;
use crate::wrapper::clips::{Depth, Effect, HostImage, HostSample, ImageInfo};
use crate::wrapper::props::PropSet;
use crate::wrapper::{Failure, Outcome, Reply};

/// `$body` with `$T` the Rust type of a host bit depth.
macro_rules! with_depth {
    ($depth:expr, $T:ident => $body:expr) => {
        match $depth {
            Depth::U8 => {
                type $T = u8;
                $body
            }
            Depth::U16 => {
                type $T = u16;
                $body
            }
            Depth::F32 => {
                type $T = f32;
                $body
            }
        }
    };
}

pub(super) const TRANSITION: &str = "OfxImageEffectContextTransition";

pub(super) fn context(effect: &Effect) -> String {
    effect
        .props()
        .and_then(|p| p.get_string(kOfxImageEffectPropContext, 0))
        .unwrap_or_default()
}

/// The frame offsets of the sources (params read without a settings pass).
fn offsets(kind: NodeKind, effect: &Effect, time: f64) -> (f64, f64) {
    let Ok(instance) = instance::get(effect) else {
        return (0.0, 0.0);
    };
    let Ok(params) = instance.params() else {
        return (0.0, 0.0);
    };
    let r = Reader::new(params, kind, time);
    let a = r.int(OFFSET_A) as f64;
    let b = if kind == NodeKind::Morph {
        r.int(OFFSET_B) as f64
    } else {
        0.0
    };
    (a, b)
}

/// The output's region of definition at `time`: the union of the connected
/// sources' regions, each at the time (offset included) it is read - what
/// hosts' own dissolves do with inputs of different data windows. The
/// region of definition action and the render use this one answer.
fn output_region(kind: NodeKind, effect: &Effect, context: &str, time: f64) -> Outcome<OfxRectD> {
    let (a, b) = kind.source_clips(context);
    let (oa, ob) = offsets(kind, effect, time);
    let mut union: Option<OfxRectD> = None;
    for (name, offset) in std::iter::once((a, oa)).chain(b.map(|b| (b, ob))) {
        let clip = effect.clip(name)?;
        if !clip.is_connected() {
            continue;
        }
        // A connected clip with no region at this time adds none (its
        // image is transparent black, like a failed fetch).
        let Ok(r) = clip.rod(time + offset) else {
            continue;
        };
        union = Some(match union {
            None => r,
            Some(u) => OfxRectD {
                x1: u.x1.min(r.x1),
                y1: u.y1.min(r.y1),
                x2: u.x2.max(r.x2),
                y2: u.y2.max(r.y2),
            },
        });
    }
    union.ok_or_else(|| {
        Failure::BadInput(format!(
            "no source clip of {} is connected",
            kind.info().label
        ))
    })
}

pub fn region_of_definition(
    kind: NodeKind,
    effect: &Effect,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let rod = output_region(kind, effect, &context(effect), time)?;
    out_args.set_doubles(
        kOfxImageEffectPropRegionOfDefinition,
        &[rod.x1, rod.y1, rod.x2, rod.y2],
    )
}

/// Clip preferences: the output changes from frame to frame (line slots,
/// scene keyframes and progress all animate), so a host must not cache one
/// frame for every time; it is premultiplied, as the dissolve is, unless
/// every connected source is straight (then the samplers keep it straight).
pub fn clip_preferences(kind: NodeKind, effect: &Effect, out_args: &PropSet) -> Outcome {
    out_args.set_int(kOfxImageEffectFrameVarying, 0, 1)?;
    let (a, b) = kind.source_clips(&context(effect));
    let mut straight = Vec::new();
    for name in std::iter::once(a).chain(b) {
        let clip = effect.clip(name)?;
        if clip.is_connected() {
            let state = clip
                .props()?
                .get_string(kOfxImageEffectPropPreMultiplication, 0)
                .unwrap_or_default();
            straight.push(state == "OfxImageUnPreMultiplied");
        }
    }
    let output = if !straight.is_empty() && straight.iter().all(|s| *s) {
        "OfxImageUnPreMultiplied"
    } else {
        "OfxImagePreMultiplied"
    };
    out_args.set_string(kOfxImageEffectPropPreMultiplication, 0, output)
}

/// A warp can pull from anywhere: ask for each source's whole region, at the
/// frame (offset included) that source is read for this render.
pub fn regions_of_interest(
    kind: NodeKind,
    effect: &Effect,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let context = context(effect);
    let (a, b) = kind.source_clips(&context);
    let (oa, ob) = offsets(kind, effect, time);
    for (name, offset) in std::iter::once((a, oa)).chain(b.map(|b| (b, ob))) {
        let clip = effect.clip(name)?;
        if !clip.is_connected() {
            continue;
        }
        if let Ok(rod) = clip.rod(time + offset) {
            let prop =
                std::ffi::CString::new(format!("OfxImageClipPropRoI_{name}")).unwrap_or_default();
            out_args.set_doubles(&prop, &[rod.x1, rod.y1, rod.x2, rod.y2])?;
        }
    }
    Ok(())
}

pub fn frames_needed(
    kind: NodeKind,
    effect: &Effect,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let (oa, ob) = offsets(kind, effect, time);
    let context = context(effect);
    let (a, b) = kind.source_clips(&context);
    for (name, off) in std::iter::once((a, oa)).chain(b.map(|b| (b, ob))) {
        let prop = std::ffi::CString::new(format!("OfxImageClipPropFrameRange_{name}"))
            .unwrap_or_default();
        out_args.set_doubles(&prop, &[time + off, time + off])?;
    }
    Ok(())
}

/// The source a node's output equals bit for bit at this time, if any:
/// progress 0 shows A and 1 shows B unchanged (through the views that pass a
/// picture through), unless a transition paces pixels differently. Answered
/// `kOfxStatOK` with the clip and its time, else `kOfxStatReplyDefault`.
pub fn is_identity(
    kind: NodeKind,
    effect: &Effect,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome<Reply> {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let instance = instance::get(effect)?;
    let context = context(effect);
    let settings = Settings::read(instance.params()?, time, kind);
    let inputs = warp_inputs(kind, &instance, &settings, time, &context)?;
    let Some(side) = identity_side(kind, settings.view, &inputs) else {
        return Ok(Reply::Default);
    };
    let (a, b) = kind.source_clips(&context);
    let (name, offset) = match (side, b) {
        (Side::B, Some(b)) => (b, settings.offset_b),
        _ => (a, settings.offset_a),
    };
    if !effect.clip(name)?.is_connected() {
        return Ok(Reply::Default); // rendered as transparent black
    }
    out_args.set_string(kOfxPropName, 0, name)?;
    out_args.set_double(kOfxPropTime, 0, time + offset as f64)?;
    Ok(Reply::Done)
}

/// Which source the output is at `inputs`' progress, when it is one unchanged.
fn identity_side(kind: NodeKind, view: View, inputs: &WarpInputs) -> Option<Side> {
    let transition = &inputs.warp.settings.transition;
    if !(transition.geometry.is_uniform_at(inputs.t) && transition.colour().is_uniform_at(inputs.t))
    {
        return None;
    }
    let side = if inputs.t <= 0.0 {
        Side::A
    } else if inputs.t >= 1.0 && kind == NodeKind::Morph {
        Side::B
    } else {
        return None;
    };
    match (view, side) {
        (View::Morph, _) | (View::WarpedA, Side::A) | (View::WarpedB, Side::B) => Some(side),
        _ => None,
    }
}

/// The scene named by the params, parsed once per content.
fn load_scene(instance: &Instance, settings: &Settings) -> Outcome<Option<Arc<Scene>>> {
    let path = settings.scene_file.trim();
    let (key, source) = if !path.is_empty() {
        let meta = std::fs::metadata(path)
            .map_err(|e| Failure::BadInput(format!("scene file {path}: {e}")))?;
        (
            format!("file:{path}:{:?}:{}", meta.modified().ok(), meta.len()),
            Some(path),
        )
    } else if !settings.scene_text.trim().is_empty() {
        (format!("text:{}", settings.scene_text), None)
    } else {
        return Ok(None);
    };
    let mut cached = instance.scene.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((k, scene)) = cached.as_ref() {
        if *k == key {
            return Ok(Some(scene.clone()));
        }
    }
    let text = match source {
        Some(path) => std::fs::read_to_string(path)
            .map_err(|e| Failure::BadInput(format!("scene file {path}: {e}")))?,
        None => settings.scene_text.clone(),
    };
    let scene = Scene::parse(&text).map_err(|e| match source {
        Some(path) => Failure::BadInput(format!("scene file {path}: {e}")),
        None => Failure::BadInput(format!("scene text: {e}")),
    })?;
    let scene = Arc::new(scene);
    *cached = Some((key, scene.clone()));
    Ok(Some(scene))
}

/// Everything the warps at one time depend on.
#[derive(Debug)]
struct WarpInputs {
    features: Vec<Feature>,
    warp: WarpSettings,
    t: f64,
}

fn warp_inputs(
    kind: NodeKind,
    instance: &Instance,
    settings: &Settings,
    time: f64,
    context: &str,
) -> Outcome<WarpInputs> {
    let scene = load_scene(instance, settings)?;
    // The scene's features first, so transition curves attached by index
    // name the scene's own features.
    let mut features = Vec::new();
    let mut warp = WarpSettings::new(settings.warp.clone());
    let mut t = settings.progress;
    if let Some(scene) = &scene {
        features.extend(scene.features_at(time));
        if settings.settings_from_scene {
            let node_transition = warp.settings.transition.clone();
            warp = scene.warp_settings_at(time);
            // A scene without a transition leaves the node's in place.
            if warp.settings.transition == Default::default() {
                warp.settings.transition = node_transition;
            }
        } else {
            warp.meshes = scene.mesh_at(time);
        }
        if settings.use_scene_progress {
            t = scene.progress_at(time).unwrap_or(t);
        }
    }
    features.extend(settings.lines.iter().cloned());
    if kind == NodeKind::Morph && context == TRANSITION {
        t = instance
            .params()?
            .double(TRANSITION_PARAM, time)?
            .clamp(0.0, 1.0);
    }
    Ok(WarpInputs { features, warp, t })
}

/// A source clip's image, or `None` where the host has none: an unconnected
/// clip, or a fetch that failed, which the spec says to treat as transparent
/// black and carry on.
fn source(effect: &Effect, name: &str, time: f64) -> Outcome<Option<HostImage>> {
    let clip = effect.clip(name)?;
    if !clip.is_connected() {
        return Ok(None);
    }
    clip.image(time)
}

/// The largest frame (canonical px along a side) a warp covers; a larger or
/// infinite region of definition (allowed by the spec) is cut to the project.
const LARGEST_FRAME: f64 = 65536.0;

/// The canonical frame a warp covers: the output's region of definition,
/// or, where that is infinite or absurdly large, the project.
fn warp_region(effect: &Effect, rod: &OfxRectD) -> RectD {
    let r = RectD::new(rod.x1, rod.y1, rod.x2, rod.y2);
    if r.width() <= LARGEST_FRAME && r.height() <= LARGEST_FRAME && r.is_valid() {
        return r;
    }
    let (origin, size) = project(effect, rod);
    let p = RectD::new(origin.x, origin.y, origin.x + size.x, origin.y + size.y);
    let cut = RectD::new(
        r.x1.max(p.x1),
        r.y1.max(p.y1),
        r.x2.min(p.x2),
        r.y2.min(p.y2),
    );
    if cut.is_valid() && cut.width() > 0.0 && cut.height() > 0.0 {
        cut
    } else {
        p
    }
}

/// What one render call reads from the host, before any computing.
struct Gathered {
    time: f64,
    window: RectI,
    /// The host renders frames in order on this instance (warm starts allowed).
    sequential: bool,
    settings: Settings,
    inputs: WarpInputs,
    a: Option<HostImage>,
    b: Option<HostImage>,
    out_info: ImageInfo,
    /// The output's region of definition ([`output_region`]).
    rod: OfxRectD,
    project: (Vec2, Vec2),
}

/// What one render call reads from the host, and the output image to write.
fn gather(
    kind: NodeKind,
    effect: &Effect,
    instance: &Instance,
    in_args: &PropSet,
) -> Outcome<(Gathered, HostImage)> {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let [x1, y1, x2, y2] = in_args.get_ints::<4>(kOfxImageEffectPropRenderWindow)?;
    let sequential = in_args
        .get_int(kOfxImageEffectPropSequentialRenderStatus, 0)
        .unwrap_or(0)
        == 1;
    let context = context(effect);
    let settings = Settings::read(instance.params()?, time, kind);
    if !settings.missing.is_empty() && instance.first_time("missing params") {
        effect.message(
            kOfxMessageWarning,
            c"net.morphfx.MissingParams",
            &format!(
                "the host could not read these params; their defaults are used: {}",
                settings.missing.join(", ")
            ),
        );
    }
    let inputs = warp_inputs(kind, instance, &settings, time, &context)?;
    let (a_name, b_name) = kind.source_clips(&context);
    let a = source(effect, a_name, time + settings.offset_a as f64)?;
    let b = match b_name {
        Some(b) => source(effect, b, time + settings.offset_b as f64)?,
        None => None,
    };
    let out = effect
        .clip("Output")?
        .image(time)?
        .ok_or_else(|| Failure::Failed("the host gave no output image".into()))?;
    let out_info = *out.info();
    let rod = output_region(kind, effect, &context, time)?;
    let project = project(effect, &rod);
    let gathered = Gathered {
        time,
        window: RectI::new(x1, y1, x2, y2),
        sequential,
        settings,
        inputs,
        a,
        b,
        out_info,
        rod,
        project,
    };
    Ok((gathered, out))
}

/// A view over `source`'s pixels, or over one transparent black pixel.
fn view_of<'a, S: HostSample>(
    source: &'a Option<HostImage>,
    black: &'a [S; 4],
) -> Outcome<ImageView<'a, S>> {
    match source {
        Some(image) => image.view::<S>(),
        None => {
            ImageView::new(black, Layout::packed(RectI::new(0, 0, 1, 1), 4)).map_err(Failure::from)
        }
    }
}

pub fn render(kind: NodeKind, effect: &Effect, in_args: &PropSet) -> Outcome {
    let instance = instance::get(effect)?;
    let (mut g, mut out) = gather(kind, effect, &instance, in_args)?;
    let out_scale = PixelScale::new(
        g.out_info.render_scale.0,
        g.out_info.render_scale.1,
        g.out_info.par,
    );
    let scale_of = |s: &Option<HostImage>| match s {
        Some(image) => {
            let i = image.info();
            PixelScale::new(i.render_scale.0, i.render_scale.1, i.par)
        }
        None => out_scale,
    };
    let (a_scale, b_scale) = (scale_of(&g.a), scale_of(&g.b));
    // Both sources are read at one depth (the descriptor says so); a missing
    // one takes the other's, or the output's.
    let depth = match (
        g.a.as_ref().map(HostImage::info),
        g.b.as_ref().map(HostImage::info),
    ) {
        (Some(a), Some(b)) if a.depth != b.depth => {
            return Err(Failure::BadInput(
                "Source A and Source B have different bit depths".into(),
            ))
        }
        (Some(i), _) | (None, Some(i)) => i.depth,
        (None, None) => g.out_info.depth,
    };
    let premultiplied = |s: &Option<HostImage>| s.as_ref().is_none_or(|i| i.info().premultiplied);
    if g.inputs.warp.method() == Method::Auto {
        let (Some(a_img), Some(b_img)) = (&g.a, &g.b) else {
            return Err(Failure::BadInput(
                "method \"auto\" finds its warp from two images: connect both sources (Morph node)"
                    .into(),
            ));
        };
        let (a_work, b_work) = with_depth!(depth, S => (
            WorkImage::from_view(&a_img.view::<S>()?),
            WorkImage::from_view(&b_img.view::<S>()?),
        ));
        let a_frame = canonical(a_img.info().bounds, a_scale);
        let b_frame = canonical(b_img.info().bounds, b_scale);
        g.inputs.warp.correspondence = Some(correspondence(
            &instance,
            &g.inputs,
            (g.time, g.sequential),
            (&a_work, a_frame),
            (&b_work, b_frame),
        )?);
    }
    // Triangles pin the border of the frame, so the whole frame warps.
    g.inputs.warp.region = Some(warp_region(effect, &g.rod));
    if effect.aborted() {
        return Ok(());
    }
    let job = prepare(kind, &instance, &g, out_scale)?;
    let (a, b) = (&g.a, &g.b);
    let settings = &g.settings;
    with_depth!(g.out_info.depth, D => {
        let rows = out.rows_mut::<D>(g.window)?;
        with_depth!(depth, S => {
            // Transparent black: the stand-in for a source with no image.
            let black = [S::default(); 4];
            let edge = |s: &Option<HostImage>| if s.is_some() { settings.edge } else { EdgeMode::Black };
            let a_sampler = Sampler::new(view_of::<S>(a, &black)?, a_scale, settings.filter, edge(a), premultiplied(a));
            if kind == NodeKind::Morph {
                let b_sampler = Sampler::new(view_of::<S>(b, &black)?, b_scale, settings.filter, edge(b), premultiplied(b));
                job.draw(&a_sampler, Some(&b_sampler), rows);
            } else {
                job.draw(&a_sampler, None, rows);
            }
        })
    });
    Ok(())
}

/// Everything the pixels depend on, computed (or found in the caches) from
/// what [`gather`] read: the maps for the render window, the dissolve
/// weights, the transition rates. Pure given the instance's caches.
fn prepare<'g>(
    kind: NodeKind,
    instance: &'g Instance,
    g: &'g Gathered,
    scale: PixelScale,
) -> Outcome<Job<'g>> {
    let inputs = &g.inputs;
    let view = g.settings.view;
    // The two-pass mesh warp makes pixels (per render window), not a map:
    // pictures take that path, ST maps and the grid the one-pass map.
    let mesh = inputs.warp.method() == Method::Mesh;
    if mesh {
        inputs.warp.mesh_pair()?; // a missing mesh is bad input before any pixel
    }
    let two_pass = mesh && inputs.warp.settings.mesh.pass == Pass::TwoPass;
    // Maps cover the render window, never more: a tile costs its own pixels,
    // and an infinite region of definition costs nothing extra.
    let map_window = g.window;
    let map = |side: Side| -> Outcome<Arc<WarpMap>> {
        let key = key_of(&(inputs, side, map_window, scale.x, scale.y));
        instance.warps.get_or_compute(key, || {
            let w: Arc<dyn Warp> = if inputs.warp.method() == Method::ThinPlate {
                Arc::new(thin_plate(instance, inputs, side, (g.time, g.sequential))?)
            } else {
                make_warp::toward(&inputs.features, side, inputs.t, &inputs.warp)?
            };
            Ok::<_, Failure>(w.map_window(map_window, scale))
        })
    };
    let picture = matches!(view, View::Morph | View::WarpedA | View::WarpedB);
    let bad = |e: morphfx::Error| Failure::BadInput(e.to_string());
    let two_sources = kind == NodeKind::Morph;
    // A non-uniform colour transition weighs every pixel of the dissolve.
    let weighted = view == View::Morph
        && two_sources
        && !inputs
            .warp
            .settings
            .transition
            .colour()
            .is_uniform_at(inputs.t);
    // The two-pass mesh warp makes pixels, not maps; weights need maps.
    let by_map = !(two_pass && picture) || weighted;
    let weights = if weighted {
        let (ma, mb) = (map(Side::A)?, map(Side::B)?);
        let key = key_of(&(inputs, "weights", map_window, scale.x, scale.y));
        Some(instance.weights.get_or_compute(key, || {
            let colour = inputs
                .warp
                .colour_rates(&inputs.features, inputs.t)
                .map_err(bad)?;
            // W1 carries B onto A: the warp of A toward B's positions.
            let w1 =
                make_warp::toward(&inputs.features, Side::A, 1.0, &inputs.warp).map_err(bad)?;
            Ok::<_, Failure>(transition::colour_weights(&colour, &ma, &mb, w1.as_ref()))
        })?)
    } else {
        None
    };
    let rates = if view == View::Transition {
        Some(
            inputs
                .warp
                .geometry_rates(&inputs.features, inputs.t)
                .map_err(bad)?,
        )
    } else {
        None
    };
    let (origin, size) = g.project;
    Ok(Job {
        view,
        weights,
        rates,
        t: inputs.t,
        features: &inputs.features,
        map_a: if needs_a(view) && by_map {
            Some(map(Side::A)?)
        } else {
            None
        },
        map_b: if needs_b(kind, view) && by_map {
            Some(map(Side::B)?)
        } else {
            None
        },
        meshes: if by_map {
            None
        } else {
            inputs.warp.meshes.as_ref()
        },
        planes: &instance.planes,
        premultiply: premultiply(g),
        scale,
        origin,
        size,
    })
}

/// Which sources (A, B) are straight but must come out premultiplied: the
/// output is premultiplied unless every source with an image is straight
/// (see [`clip_preferences`]), and a dissolve adds like to like.
fn premultiply(g: &Gathered) -> [bool; 2] {
    let straight = |s: &Option<HostImage>| s.as_ref().map(|i| !i.info().premultiplied);
    let (a, b) = (straight(&g.a), straight(&g.b));
    let output_straight = a.unwrap_or(true) && b.unwrap_or(true) && (a.is_some() || b.is_some());
    [
        !output_straight && a == Some(true),
        !output_straight && b == Some(true),
    ]
}

/// The canonical rectangle a host image's pixels cover.
fn canonical(bounds: RectI, scale: PixelScale) -> RectD {
    RectD::new(
        bounds.x1 as f64 / scale.x,
        bounds.y1 as f64 / scale.y,
        bounds.x2 as f64 / scale.x,
        bounds.y2 as f64 / scale.y,
    )
}

/// The frame's `auto` correspondence: solved once per content of the two
/// images and settings (tiles and repeated renders share it), warm-started
/// from the previous frame's grid when this instance solved it.
fn correspondence(
    instance: &Instance,
    inputs: &WarpInputs,
    (time, sequential): (f64, bool),
    (a, a_frame): (&WorkImage, RectD),
    (b, b_frame): (&WorkImage, RectD),
) -> Outcome<Arc<Correspondence>> {
    let settings = &inputs.warp.settings.auto;
    let per_segment = inputs.warp.settings.samples_per_segment;
    let same_setup = key_of(&(
        settings,
        per_segment,
        a_frame,
        b_frame,
        a.width,
        a.height,
        b.width,
        b.height,
    ));
    let key = key_of(&(same_setup, a.digest(), b.digest(), &inputs.features));
    instance.correspondences.get_or_compute(key, || {
        // Warm starts only in a sequential render: otherwise the result
        // would depend on which frames this instance happened to render.
        let warm = sequential
            .then(|| {
                let grids = instance.grids.lock().unwrap_or_else(|e| e.into_inner());
                grids
                    .iter()
                    .find(|(t, k, _)| *t == time - 1.0 && *k == same_setup)
                    .map(|(_, _, g)| g.clone())
            })
            .flatten();
        let started = std::time::Instant::now();
        let (c, table) = auto::correspond(
            a,
            a_frame,
            b,
            b_frame,
            &inputs.features,
            per_segment,
            settings,
            warm.as_ref(),
        )
        .map_err(|e| Failure::BadInput(e.to_string()))?;
        if crate::wrapper::host::switches().verbose {
            eprintln!(
                "auto: frame {time}: {}x{} to {}x{}, {} start, {:.2} s\n{}",
                a.width,
                a.height,
                b.width,
                b.height,
                if warm.is_some() && settings.warm_start {
                    "warm"
                } else {
                    "cold"
                },
                started.elapsed().as_secs_f64(),
                auto::table_text(&table)
            );
        }
        let mut grids = instance.grids.lock().unwrap_or_else(|e| e.into_inner());
        grids.retain(|(t, k, _)| !(*t == time && *k == same_setup));
        if grids.len() >= GRIDS_KEPT {
            grids.remove(0);
        }
        grids.push((time, same_setup, c.grid.clone()));
        Ok(c)
    })
}

/// The frame's thin plates on `side`, solved from the plates this instance
/// solved nearest in time (this frame at another scale, or a neighbouring
/// frame of the sequence) with the same settings: Lee et al.'s warm start,
/// since features move little from frame to frame.
fn thin_plate(
    instance: &Instance,
    inputs: &WarpInputs,
    side: Side,
    (time, sequential): (f64, bool),
) -> Outcome<ThinPlateWarp> {
    let setup = key_of(&(side, &inputs.warp.settings.thin_plate, inputs.warp.region));
    // Warm starts only in a sequential render (see `correspondence`).
    let warm = sequential
        .then(|| {
            let plates = instance.plates.lock().unwrap_or_else(|e| e.into_inner());
            plates
                .iter()
                .filter(|(t, k, _)| *k == setup && (t - time).abs() <= 1.0)
                .min_by(|a, b| (a.0 - time).abs().total_cmp(&(b.0 - time).abs()))
                .map(|(_, _, p)| p.clone())
        })
        .flatten();
    let w = make_warp::thin_plate_toward(
        &inputs.features,
        side,
        inputs.t,
        &inputs.warp,
        warm.as_deref(),
    )
    .map_err(|e| Failure::BadInput(e.to_string()))?;
    if crate::wrapper::host::switches().verbose {
        let cycles = |r: &Report| r.residuals.len() - 1;
        eprintln!(
            "thin-plate: frame {time} side {side:?}: {} start, {} + {} cycles",
            if warm.is_some() { "warm" } else { "cold" },
            cycles(&w.plate.report_x),
            cycles(&w.plate.report_y),
        );
    }
    let mut plates = instance.plates.lock().unwrap_or_else(|e| e.into_inner());
    plates.retain(|(t, k, _)| !(*t == time && *k == setup));
    if plates.len() >= PLATES_KEPT {
        plates.remove(0);
    }
    plates.push((time, setup, Arc::new(w.plate.clone())));
    Ok(w)
}

fn needs_a(view: View) -> bool {
    matches!(
        view,
        View::Morph | View::WarpedA | View::StmapA | View::Grid | View::Transition
    )
}

fn needs_b(kind: NodeKind, view: View) -> bool {
    kind == NodeKind::Morph && matches!(view, View::Morph | View::WarpedB | View::StmapB)
}

/// The rectangle ST maps are normalised by, as (origin, size): the project
/// when the host says (the spec's project size, placed at the project offset;
/// the extent is rooted at 0,0 and is not the size), else the source's
/// region of definition.
fn project(effect: &Effect, rod: &OfxRectD) -> (Vec2, Vec2) {
    let from_host = effect.props().ok().and_then(|p| {
        let size = p.get_doubles::<2>(kOfxImageEffectPropProjectSize).ok()?;
        let origin = p
            .get_doubles::<2>(kOfxImageEffectPropProjectOffset)
            .unwrap_or([0.0, 0.0]);
        (size[0] > 0.0 && size[1] > 0.0)
            .then(|| (Vec2::new(origin[0], origin[1]), Vec2::new(size[0], size[1])))
    });
    from_host.unwrap_or((
        Vec2::new(rod.x1, rod.y1),
        Vec2::new(rod.x2 - rod.x1, rod.y2 - rod.y1),
    ))
}

struct Job<'a> {
    view: View,
    /// Per-pixel dissolve weights (non-uniform colour transition).
    weights: Option<Arc<Weights>>,
    /// Geometry rates (the transition view).
    rates: Option<Rates>,
    t: f64,
    features: &'a [Feature],
    map_a: Option<Arc<WarpMap>>,
    map_b: Option<Arc<WarpMap>>,
    /// The mesh pair when pictures come from the two-pass mesh warp.
    meshes: Option<&'a MeshPair>,
    /// Output planes reused between two-pass renders.
    planes: &'a Mutex<Vec<Plane>>,
    /// Straight sources (A, B) to bring to premultiplied colour.
    premultiply: [bool; 2],
    scale: PixelScale,
    origin: Vec2,
    size: Vec2,
}

impl Job<'_> {
    fn draw<S: Sample, D: Sample>(
        &self,
        a: &Sampler<'_, S>,
        b: Option<&Sampler<'_, S>>,
        rows: RowsMut<'_, D>,
    ) {
        if let Some(pair) = self.meshes {
            return self.draw_two_pass(pair, a, b, rows);
        }
        let (ma, mb) = (self.map_a.as_deref(), self.map_b.as_deref());
        let wa = ma.map(|m| Warped::Map(a, m));
        let wb = b.zip(mb).map(|(b, m)| Warped::Map(b, m));
        macro_rules! picture {
            ($w:expr, $side:expr) => {
                self.in_output_state($w.as_ref().expect("a map for the side drawn"), $side)
            };
        }
        match (self.view, b) {
            (View::Morph, Some(_)) => match &self.weights {
                Some(w) => dissolve_weighted(
                    picture!(wa, Side::A),
                    picture!(wb, Side::B),
                    self.t,
                    w,
                    rows,
                ),
                None => dissolve(picture!(wa, Side::A), picture!(wb, Side::B), self.t, rows),
            },
            (View::Morph | View::WarpedA, _) => show(picture!(wa, Side::A), rows),
            (View::WarpedB, Some(_)) => show(picture!(wb, Side::B), rows),
            (View::StmapA, _) => views::stmap(ma.expect("map A"), self.origin, self.size, rows),
            (View::StmapB, _) => {
                views::stmap(mb.or(ma).expect("map"), self.origin, self.size, rows)
            }
            (View::Transition, _) => match &self.rates {
                Some(r) => views::transition_grey(r, ma.expect("map A"), rows),
                None => views::transition_grey(&Rates::Uniform(self.t), ma.expect("map A"), rows),
            },
            (View::Grid, _) => views::grid(ma.expect("map A"), self.features, self.t, rows),
            (View::WarpedB, None) => show(picture!(wa, Side::A), rows),
        }
    }

    /// `w` as the output holds colour: premultiplied when `side` is straight
    /// and the output is not.
    fn in_output_state<'w, S: Sample>(&self, w: &'w Warped<'w, S>, side: Side) -> Warped<'w, S> {
        let k = if side == Side::A { 0 } else { 1 };
        if self.premultiply[k] {
            Warped::Premultiplied(w)
        } else {
            *w
        }
    }

    /// Pictures through the two-pass mesh warp, made for this render window
    /// only (its cost follows the window, so tiles stay cheap; nothing that
    /// depends on the host's pixels is cached). A side whose mesh does not
    /// move is copied, not filtered.
    fn draw_two_pass<S: Sample, D: Sample>(
        &self,
        pair: &MeshPair,
        a: &Sampler<'_, S>,
        b: Option<&Sampler<'_, S>>,
        rows: RowsMut<'_, D>,
    ) {
        let window = rows.bounds;
        let to = pair.at(self.t);
        let identity = WarpMap::identity(window, self.scale);
        let pool = || self.planes.lock().unwrap_or_else(|e| e.into_inner());
        let plane = |side: Side, s: &Sampler<'_, S>| {
            let from = pair.side(side);
            (*from != to).then(|| {
                let mut p = pool().pop().unwrap_or(Plane {
                    window,
                    channels: 0,
                    pixels: Vec::new(),
                });
                p.window = window;
                mesh::two_pass_into(s, from, &to, self.scale, &mut p);
                p
            })
        };
        let used = match (self.view, b) {
            (View::Morph, Some(b)) => {
                let (pa, pb) = (
                    (self.t < 1.0).then(|| plane(Side::A, a)).flatten(),
                    (self.t > 0.0).then(|| plane(Side::B, b)).flatten(),
                );
                let (wa, wb) = (warped(a, &pa, &identity), warped(b, &pb, &identity));
                dissolve(
                    self.in_output_state(&wa, Side::A),
                    self.in_output_state(&wb, Side::B),
                    self.t,
                    rows,
                );
                [pa, pb]
            }
            (View::WarpedB, Some(b)) => {
                let p = plane(Side::B, b);
                show(
                    self.in_output_state(&warped(b, &p, &identity), Side::B),
                    rows,
                );
                [p, None]
            }
            _ => {
                let p = plane(Side::A, a);
                show(
                    self.in_output_state(&warped(a, &p, &identity), Side::A),
                    rows,
                );
                [p, None]
            }
        };
        let mut kept = pool();
        for p in used.into_iter().flatten() {
            if kept.len() < PLANES_KEPT {
                kept.push(p);
            }
        }
    }
}

/// A two-pass side: its pixels, or the source itself when its mesh stays put.
fn warped<'a, S: Sample>(
    source: &'a Sampler<'a, S>,
    plane: &'a Option<Plane>,
    identity: &'a WarpMap,
) -> Warped<'a, S> {
    match plane {
        Some(p) => Warped::Pixels(p),
        None => Warped::Map(source, identity),
    }
}
