//! Render glue, in three stages: [`gather`] reads everything from the host
//! (params, clips, images), [`prepare`] computes what the pixels depend on
//! (pure given the instance's caches), [`draw`] writes the output rows at
//! the host's depths. Conversions to pixel rows, render scale and pixel
//! aspect happen here, once: the core sees canonical coordinates only.

mod draw;
mod planes;
mod regions;
mod warm;

use std::sync::Arc;

use morphfx::features::Side;
use morphfx::geom::{PixelScale, RectD, RectI, Vec2};
use morphfx::image::{
    EdgeMode, Filter, Image, ImageView, Layout, RowsMut, Sample, Sampler, WarpMap,
};
use morphfx::make_warp::{self, Method};
use morphfx::morph::mix::{mask_plane, mix, Mix};
use morphfx::morph::Warped;
use morphfx::transition::{self, Matte};
use morphfx::views::View;
use morphfx::warp::auto::WorkImage;
use morphfx::warp::mesh::Pass;
use morphfx::warp::Warp;

use crate::cache::Key;
use crate::nodes::inputs::{warp_inputs, WarpInputs};
use crate::nodes::kind::{NodeKind, MASK_CLIP, TIMING_CLIP};
use crate::nodes::params::Settings;
use crate::nodes::state::NodeState;
use draw::Job;
use ofx_layer::clips::{Depth, EffectHandle, HostImage, HostSample};
use ofx_layer::plugin::RenderArgs;
use ofx_layer::{Failure, Outcome};
pub use planes::clip_planes;
pub use regions::{
    clip_preferences, frames_needed, is_identity, region_of_definition, regions_of_interest,
};

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

mod blur;
mod mattes;

/// The render action: gather, prepare, draw; for each plane the host asks
/// for (colour, and the others where it has the multi-plane extension).
pub fn render(instance: &NodeState, effect: &EffectHandle, args: &RenderArgs) -> Outcome {
    let (request, lent) = gather(instance, effect, args)?;
    if effect.aborted() {
        return Ok(());
    }
    let others = args
        .planes
        .iter()
        .filter(|p| !ofx_layer::planes::is_colour(p))
        .map(|p| plane_request(instance, effect, &request, p))
        .collect::<Outcome<Vec<_>>>()?;
    if planes::colour_asked(&args.planes) {
        render_plane(instance, effect, request, lent)?;
    }
    for (request, lent) in others {
        render_plane(instance, effect, request, lent)?;
    }
    Ok(())
}

/// A plane besides colour: the colour's request over the plane's images,
/// drawn as [`planes::treatment`] says, and the images it holds.
fn plane_request(
    instance: &NodeState,
    effect: &EffectHandle,
    request: &Request,
    plane: &str,
) -> Outcome<(Request, Lent)> {
    let kind = instance.kind;
    let (a_name, b_name) = kind.source_clips(instance.context);
    let (time, settings) = (request.time, &request.settings);
    let a = planes::plane_image(effect, a_name, time + settings.offset_a as f64, plane)?;
    let b = match b_name {
        Some(b) => planes::plane_image(effect, b, time + settings.offset_b as f64, plane)?,
        None => None,
    };
    let out = planes::output_image(effect, time, plane)?;
    let how = planes::treatment(plane, settings, kind.has_b(), request.inputs.t);
    let mut r = request.clone();
    r.depth = source_depth(&a, &b, out.info().depth)?;
    r.sources = [&a, &b].map(|s| s.as_ref().map(source_of));
    (r.settings.view, r.settings.filter, r.ids) = (how.view, how.filter, how.ids);
    r.fixed = Some((how.view, how.filter));
    if how.ids {
        r.settings.shutter.samples = 0;
    }
    let mask = match how.view.is_picture() {
        true => source(effect, MASK_CLIP, time)?,
        false => None,
    };
    let sources = [a, b];
    Ok((r, Lent { sources, mask, out }))
}

/// One plane of the output: the view, blurred or not.
fn render_plane(
    instance: &NodeState,
    effect: &EffectHandle,
    mut request: Request,
    mut lent: Lent,
) -> Outcome {
    let kind = instance.kind;
    if effect.aborted() {
        return Ok(());
    }
    if request.settings.view == View::Vectors {
        return render_vectors(kind, instance, effect, request, &mut lent);
    }
    if let Some(samples) = blur_samples(instance, effect, &request)? {
        return render_blurred(kind, instance, effect, samples, &mut lent);
    }
    correspond(instance, &mut request)?;
    let job = prepare(kind, instance, &request)?;
    if effect.aborted() {
        return Ok(());
    }
    draw(kind, &job, &request, &mut lent)
}

/// Motion blur: the requests of a blurred frame, one per time of the
/// shutter; `None` when the frame renders once: no blur asked, a view
/// that is not a picture, or a still scene (every sample's warps and mix
/// as the frame's). Each sample takes the params, the scene and so the
/// warps at its time; the source images stay the frame's: it is the
/// warp's motion that blurs, as an animated distortion's does.
fn blur_samples(
    instance: &NodeState,
    effect: &EffectHandle,
    request: &Request,
) -> Outcome<Option<Vec<Request>>> {
    let times = request.settings.shutter.times(request.time);
    if times.len() < 2 || !request.settings.view.is_picture() {
        return Ok(None);
    }
    let samples = times
        .iter()
        .map(|t| request.at(instance.kind, effect, instance, *t))
        .collect::<Outcome<Vec<Request>>>()?;
    let what = |r: &Request| Key::of(&(&r.inputs, r.settings.mix.to_bits()));
    let frame = what(request);
    if samples.iter().all(|r| what(r) == frame) {
        return Ok(None);
    }
    Ok(Some(samples))
}

/// A blurred frame: each sample rendered in float, their mean written to
/// the output window.
fn render_blurred(
    kind: &'static NodeKind,
    instance: &NodeState,
    effect: &EffectHandle,
    samples: Vec<Request>,
    lent: &mut Lent,
) -> Outcome {
    let window = samples[0].window;
    let mask = lent.mask.as_ref().map(mask_of).transpose()?;
    let mut mean = blur::Mean::new(window, lent.out.info().channels);
    for mut request in samples {
        if effect.aborted() {
            return Ok(());
        }
        correspond(instance, &mut request)?;
        let job = prepare(kind, instance, &request)?;
        let mut one = mean.sample();
        let mut view = one.view_mut();
        draw_rows::<f32>(kind, &job, &request, (&lent.sources, &mask), view.rows())?;
        mean.add(&one);
    }
    with_depth!(lent.out.info().depth, D => mean.write(lent.out.rows_mut::<D>(window)?));
    Ok(())
}

/// The vectors view: the motion of warped A (the Warp node's source) to
/// the next and the previous frame, from its warps at this frame and
/// those two (the params and scene there; the images the frame's).
fn render_vectors(
    kind: &'static NodeKind,
    instance: &NodeState,
    effect: &EffectHandle,
    mut request: Request,
    lent: &mut Lent,
) -> Outcome {
    let (time, window, scale) = (request.time, request.window, request.out_scale);
    let mut warp_at = |at: f64| {
        let mut other = match at == time {
            true => None,
            false => Some(request.at(kind, effect, instance, at)?),
        };
        let r = other.as_mut().unwrap_or(&mut request);
        correspond(instance, r)?;
        let inputs = &r.inputs;
        make_warp::toward(&inputs.features, Side::A, inputs.t, &inputs.warp).map_err(bad_input)
    };
    let (now, next, prev) = (warp_at(time)?, warp_at(time + 1.0)?, warp_at(time - 1.0)?);
    with_depth!(lent.out.info().depth, D => {
        let rows = lent.out.rows_mut::<D>(window)?;
        morphfx::views::vectors(now.as_ref(), next.as_ref(), prev.as_ref(), scale, rows);
    });
    Ok(())
}

/// A source as [`prepare`] sees it: what its image's properties say.
#[derive(Debug, Clone, Copy)]
struct Source {
    scale: PixelScale,
    /// The canonical rectangle its pixels cover.
    covers: RectD,
    premultiplied: bool,
}

/// What one render reads from the host, holding no host handle: everything
/// [`prepare`] needs, so it can be made by hand in tests.
#[derive(Clone)]
struct Request {
    time: f64,
    window: RectI,
    /// The host renders frames in order on this instance (warm starts allowed).
    sequential: bool,
    /// A viewer's render while the instance is manipulated (maps may be
    /// redone from the last ones).
    interactive: bool,
    settings: Settings,
    inputs: WarpInputs,
    /// Sources A and B (`None`: no image).
    sources: [Option<Source>; 2],
    /// The sample depth both sources are read at.
    depth: Depth,
    out_scale: PixelScale,
    /// The rectangle ST maps are normalised by, as (origin, size).
    project: (Vec2, Vec2),
    /// Both sources as `auto` work images (method `auto` only).
    work: Option<Arc<[WorkImage; 2]>>,
    /// The Timing input's matte (Morph node, connected).
    timing: Option<Arc<Matte>>,
    /// The plane holds IDs or mattes: Mix and the Mask switch, not blend.
    ids: bool,
    /// A plane's view and filter, held over a blurred frame's samples.
    fixed: Option<(View, Filter)>,
}

impl Request {
    /// This render's request with the params, the scene and so the warps
    /// taken at `time` instead (the images stay the frame's): one sample of
    /// a motion-blurred frame.
    fn at(
        &self,
        kind: &'static NodeKind,
        effect: &EffectHandle,
        instance: &NodeState,
        time: f64,
    ) -> Outcome<Request> {
        let mut settings = read_settings(kind, effect, instance, time)?;
        if let Some((view, filter)) = self.fixed {
            (settings.view, settings.filter) = (view, filter);
        }
        let mut inputs = warp_inputs(instance, &settings, time)?;
        if let Some(matte) = &self.timing {
            inputs.warp.settings.transition = mattes::timed(matte.clone(), &settings);
        }
        inputs.warp.region = self.inputs.warp.region;
        Ok(Request {
            time,
            settings,
            inputs,
            work: self.work.clone(),
            timing: self.timing.clone(),
            ..*self
        })
    }
}

/// The host's images one render holds: sources A and B, the mask (picture
/// views only), and the output.
struct Lent {
    sources: [Option<HostImage>; 2],
    mask: Option<HostImage>,
    out: HostImage,
}

/// A source clip's image, or `None` where the host has none: an unconnected
/// clip, or a fetch that failed, which the spec says to treat as transparent
/// black and carry on.
fn source(effect: &EffectHandle, name: &str, time: f64) -> Outcome<Option<HostImage>> {
    let clip = effect.clip(name)?;
    if !clip.is_connected() {
        return Ok(None);
    }
    clip.image_plane(time, ofx_layer::planes::COLOUR)
}

/// The most pixels one render window may have.
const MAX_RENDER_PIXELS: usize = 1 << 28;

/// Everything one render reads from the host, and the images it holds.
fn gather(
    instance: &NodeState,
    effect: &EffectHandle,
    args: &RenderArgs,
) -> Outcome<(Request, Lent)> {
    let (time, window, sequential) = (args.time, args.window, args.sequential);
    let interactive = args.interactive;
    if window.area() > MAX_RENDER_PIXELS {
        // Maps and intermediate rows are sized by the window: refuse before
        // asking for memory no machine has (an allocation failure would
        // abort the host with the artist's session).
        return Err(Failure::BadInput(format!(
            "the render window is {}x{} pixels, over MorphFX's limit of {MAX_RENDER_PIXELS} \
             (16384x16384): render it in tiles or at a lower render scale",
            window.width(),
            window.height()
        )));
    }
    let kind = instance.kind;
    let settings = read_settings(kind, effect, instance, time)?;
    let mut inputs = warp_inputs(instance, &settings, time)?;
    let (a_name, b_name) = kind.source_clips(instance.context);
    let a = source(effect, a_name, time + settings.offset_a as f64)?;
    let b = match b_name {
        Some(b) => source(effect, b, time + settings.offset_b as f64)?,
        None => None,
    };
    let mut timing = None;
    if kind.has_b() {
        if let Some(image) = source(effect, TIMING_CLIP, time)? {
            let matte = Arc::new(mattes::timing_matte(&image)?);
            inputs.warp.settings.transition = mattes::timed(matte.clone(), &settings);
            timing = Some(matte);
        }
    }
    let mask = if settings.view.is_picture() {
        source(effect, MASK_CLIP, time)?
    } else {
        None
    };
    // The output's scale and depth, from the colour plane unless the host
    // asks for other planes alone.
    let first = match planes::colour_asked(&args.planes) {
        true => ofx_layer::planes::COLOUR,
        false => args.planes[0].as_str(),
    };
    let out = planes::output_image(effect, time, first)?;
    // The spec: non-optional clips are always connected during a render.
    let rod = regions::output_region(instance, effect, time)?.ok_or_else(|| {
        Failure::BadInput(format!("no source clip of {} is connected", kind.label))
    })?;
    // Triangles pin the border of the frame, so the whole frame warps.
    inputs.warp.region = Some(regions::warp_region(effect, &rod));
    let out_scale = out.info().pixel_scale();
    let depth = source_depth(&a, &b, out.info().depth)?;
    let sources = [&a, &b].map(|s| s.as_ref().map(source_of));
    let work = match inputs.warp.method() {
        Method::Auto => Some(Arc::new(work_images(&a, &b, depth)?)),
        _ => None,
    };
    let request = Request {
        time,
        window,
        sequential,
        interactive,
        settings,
        inputs,
        sources,
        depth,
        out_scale,
        project: regions::project(effect, &rod),
        work,
        timing,
        ids: false,
        fixed: None,
    };
    let lent = Lent {
        sources: [a, b],
        mask,
        out,
    };
    Ok((request, lent))
}

/// The params at `time`; params the host could not read are said once.
fn read_settings(
    kind: &'static NodeKind,
    effect: &EffectHandle,
    instance: &NodeState,
    time: f64,
) -> Outcome<Settings> {
    let settings = Settings::read(instance.params(), time, kind);
    if let Some(first) = settings.unreadable.first() {
        return Err(Failure::Failed(format!(
            "the host could not give {} of this node's params at frame {time}: {first}",
            settings.unreadable.len()
        )));
    }
    if !settings.missing.is_empty() && instance.first_time("missing params") {
        effect.warning(
            c"net.morphfx.MissingParams",
            &format!(
                "the host could not read these params; their defaults are used: {}",
                settings.missing.join(", ")
            ),
        );
    }
    Ok(settings)
}

/// What a source image's properties say.
fn source_of(image: &HostImage) -> Source {
    let i = image.info();
    Source {
        scale: i.pixel_scale(),
        covers: canonical(i.bounds, i.pixel_scale()),
        premultiplied: i.premultiplied,
    }
}

/// Both sources are read at one depth (the descriptor says so); a missing
/// one takes the other's, or the output's.
fn source_depth(a: &Option<HostImage>, b: &Option<HostImage>, out: Depth) -> Outcome<Depth> {
    match (
        a.as_ref().map(HostImage::info),
        b.as_ref().map(HostImage::info),
    ) {
        (Some(a), Some(b)) if a.depth != b.depth => Err(Failure::BadInput(
            "Source A and Source B have different bit depths".into(),
        )),
        (Some(i), _) | (None, Some(i)) => Ok(i.depth),
        (None, None) => Ok(out),
    }
}

/// Both sources' pixels as `auto` work images.
fn work_images(
    a: &Option<HostImage>,
    b: &Option<HostImage>,
    depth: Depth,
) -> Outcome<[WorkImage; 2]> {
    let (Some(a), Some(b)) = (a, b) else {
        return Err(Failure::BadInput(
            "method \"auto\" finds its warp from two images: connect both sources (Morph node)"
                .into(),
        ));
    };
    Ok(with_depth!(depth, S => [
        WorkImage::from_view(&a.view::<S>()?),
        WorkImage::from_view(&b.view::<S>()?),
    ]))
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

/// Method `auto`: the correspondence of the two work images, which the
/// maps are then made from like any method's.
fn correspond(instance: &NodeState, request: &mut Request) -> Outcome {
    if let Some([a, b]) = request.work.as_deref() {
        let covers = |k: usize| request.sources[k].map_or(RectD::default(), |s| s.covers);
        let c = warm::correspondence(
            instance,
            &request.inputs,
            (request.time, request.sequential),
            (a, covers(0)),
            (b, covers(1)),
        )?;
        request.inputs.warp.correspondence = Some(c);
    }
    Ok(())
}

/// Everything the pixels depend on, computed (or found in the caches) from
/// what [`gather`] read: the maps for the render window, the dissolve
/// weights, the transition rates. Pure given the instance's caches: no
/// host call.
fn prepare<'r>(
    kind: &'static NodeKind,
    instance: &'r NodeState,
    request: &'r Request,
) -> Outcome<Job<'r>> {
    let inputs = &request.inputs;
    let view = request.settings.view;
    // The two-pass mesh warp makes pixels (per render window), not a map:
    // pictures take that path, ST maps and the grid the one-pass map.
    let mesh = inputs.warp.method() == Method::Mesh;
    if mesh {
        inputs.warp.mesh_pair()?; // a missing mesh is bad input before any pixel
    }
    // Fant's filter averages: nearest sampling (IDs) takes the one-pass map.
    let two_pass = mesh
        && inputs.warp.settings.mesh.pass == Pass::TwoPass
        && request.settings.filter != Filter::Nearest;
    let picture = view.is_picture();
    // A non-uniform colour transition weighs every pixel of the dissolve.
    let weighted = matches!(view, View::Morph | View::Folds)
        && kind.has_b()
        && !inputs
            .warp
            .settings
            .transition
            .colour()
            .is_uniform_at(inputs.t);
    // The two-pass mesh warp makes pixels, not maps; weights need maps.
    let by_map = !(two_pass && picture) || weighted;
    // The folds view measures the maps but shows the morph as the Morph
    // view draws it.
    let by_two_pass = two_pass && (picture || view == View::Folds) && !weighted;
    // Folds are measured by central differences: one pixel more each side.
    let w = request.window;
    let window = match view {
        View::Folds => RectI::new(w.x1 - 1, w.y1 - 1, w.x2 + 1, w.y2 + 1),
        _ => w,
    };
    // The inputs' key, printed once for both maps and the weights.
    let inputs_key = Key::of(&request.inputs);
    let map = |side| map(instance, request, &inputs_key, side, window);
    // Weighted implies the Morph view of the Morph node: both maps drawn.
    // Both sides at once: a redo after a drag spends much of its time
    // waiting (on memory the last draw evicted, on the pool waking), and
    // two of them overlap their waits.
    let (map_a, map_b) = rayon::join(
        || (needs_a(view) && by_map).then(|| map(Side::A)).transpose(),
        || {
            (needs_b(kind, view) && by_map)
                .then(|| map(Side::B))
                .transpose()
        },
    );
    let (map_a, map_b) = (map_a?, map_b?);
    let weights = match (weighted, &map_a, &map_b) {
        (true, Some(ma), Some(mb)) => Some(weights(instance, request, &inputs_key, ma, mb)?),
        _ => None,
    };
    let rates = match view {
        View::Transition => Some(
            inputs
                .warp
                .geometry_rates(&inputs.features, inputs.t)
                .map_err(bad_input)?,
        ),
        _ => None,
    };
    let (origin, size) = request.project;
    Ok(Job {
        view,
        weights,
        rates,
        t: inputs.t,
        features: &inputs.features,
        map_a,
        map_b,
        meshes: inputs.warp.meshes.as_ref().filter(|_| by_two_pass),
        planes: &instance.planes,
        premultiply: premultiply(&request.sources),
        scale: request.out_scale,
        origin,
        size,
    })
}

fn bad_input(e: morphfx::Error) -> Failure {
    Failure::BadInput(e.to_string())
}

/// The map of `side`'s warp over the render window, from the cache or made.
/// Maps cover the render window, never more: a tile costs its own pixels,
/// and an infinite region of definition costs nothing extra.
/// `inputs_key` is [`Key::of`] the request's inputs.
fn map(
    instance: &NodeState,
    request: &Request,
    inputs_key: &Key,
    side: Side,
    window: RectI,
) -> Outcome<Arc<WarpMap>> {
    let (inputs, scale) = (&request.inputs, request.out_scale);
    let key = Key::with(inputs_key, &(side, window, scale));
    if inputs.warp.method() == Method::Field && request.interactive && !request.sequential {
        return field_map(instance, request, side, window, key);
    }
    instance.warps.get_or_compute(key, || {
        let w: Arc<dyn Warp> = if inputs.warp.method() == Method::ThinPlate {
            let when = (request.time, request.interactive);
            Arc::new(warm::thin_plate(instance, inputs, side, when)?)
        } else {
            make_warp::toward(&inputs.features, side, inputs.t, &inputs.warp)?
        };
        Ok::<_, Failure>(w.map_window(window, scale))
    })
}

/// An interactive render's `field` map: redone from this side's last one
/// when a few lines moved since (a compositor dragging one), else made
/// afresh. The spec lets a plugin approximate for a viewer while the
/// instance is manipulated (`kOfxImageEffectPropInteractiveRenderStatus`);
/// every other render (to disk, on a farm, in sequence) makes its maps
/// afresh, so a written frame never depends on what a viewer showed before.
fn field_map(
    instance: &NodeState,
    request: &Request,
    side: Side,
    window: RectI,
    key: Key,
) -> Outcome<Arc<WarpMap>> {
    let (inputs, scale) = (&request.inputs, request.out_scale);
    let kept = instance.field_maps.get_or_compute(key.clone(), || {
        let warp = make_warp::field_toward(&inputs.features, side, inputs.t, &inputs.warp)?;
        let map = match instance.last_field(side) {
            Some((last, before)) if warp.redoes(window, scale, &before) => {
                drop(before);
                // Taken out of the cache, the map before is edited in place
                // (it is the drag's last step, not worth keeping), unless a
                // render elsewhere still holds it.
                match instance.field_maps.take(&last).map(Arc::try_unwrap) {
                    Some(Ok(owned)) => warp.field_map_from(window, scale, owned),
                    Some(Err(shared)) => warp.field_map_after(window, scale, Some(&shared)),
                    None => warp.field_map(window, scale),
                }
            }
            _ => warp.field_map(window, scale),
        };
        Ok::<_, Failure>(map)
    })?;
    instance.set_last_field(side, key, &kept);
    Ok(kept.map().clone())
}

/// The per-pixel dissolve weights of a non-uniform colour transition.
fn weights(
    instance: &NodeState,
    request: &Request,
    inputs_key: &Key,
    ma: &WarpMap,
    mb: &WarpMap,
) -> Outcome<Arc<transition::Weights>> {
    let inputs = &request.inputs;
    let key = Key::with(inputs_key, &("weights", ma.window, request.out_scale));
    instance.weights.get_or_compute(key, || {
        let colour = inputs
            .warp
            .colour_rates(&inputs.features, inputs.t)
            .map_err(bad_input)?;
        // W1 carries B onto A: the warp of A toward B's positions.
        let w1 =
            make_warp::toward(&inputs.features, Side::A, 1.0, &inputs.warp).map_err(bad_input)?;
        Ok::<_, Failure>(transition::colour_weights(&colour, ma, mb, w1.as_ref()))
    })
}

/// Which sources (A, B) are straight but must come out premultiplied: the
/// output is premultiplied unless every source with an image is straight
/// (see [`clip_preferences`]), and a dissolve adds like to like.
fn premultiply(sources: &[Option<Source>; 2]) -> [bool; 2] {
    let [a, b] = sources.map(|s| s.map(|s| !s.premultiplied));
    let output_straight = a.unwrap_or(true) && b.unwrap_or(true) && (a.is_some() || b.is_some());
    [
        !output_straight && a == Some(true),
        !output_straight && b == Some(true),
    ]
}

fn needs_a(view: View) -> bool {
    matches!(
        view,
        View::Morph
            | View::WarpedA
            | View::StmapA
            | View::Grid
            | View::Transition
            | View::Ghost
            | View::Folds
    )
}

fn needs_b(kind: &NodeKind, view: View) -> bool {
    kind.has_b()
        && matches!(
            view,
            View::Morph | View::WarpedB | View::StmapB | View::Ghost | View::Folds
        )
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

/// Writes the render window of the output: samplers over the lent sources
/// at their depth, rows of the output at its own.
fn draw(kind: &NodeKind, job: &Job<'_>, request: &Request, lent: &mut Lent) -> Outcome {
    let mask = lent.mask.as_ref().map(mask_of).transpose()?;
    with_depth!(lent.out.info().depth, D => {
        let rows = lent.out.rows_mut::<D>(request.window)?;
        draw_rows(kind, job, request, (&lent.sources, &mask), rows)
    })
}

/// [`draw`] into `rows` (the output's, or a motion blur sample's).
fn draw_rows<D: Sample>(
    kind: &NodeKind,
    job: &Job<'_>,
    request: &Request,
    (sources, mask): (&[Option<HostImage>; 2], &Option<MaskPlane<'_>>),
    rows: RowsMut<'_, D>,
) -> Outcome {
    let settings = &request.settings;
    let [a, b] = sources;
    let sampler_parts = |k: usize, s: &Option<HostImage>| {
        let source = request.sources[k];
        (
            source.map_or(request.out_scale, |s| s.scale),
            // Transparent black outside a source with no image.
            if s.is_some() {
                settings.edge
            } else {
                EdgeMode::Black
            },
            source.is_none_or(|s| s.premultiplied),
        )
    };
    let ((a_scale, a_edge, a_pre), (b_scale, b_edge, b_pre)) =
        (sampler_parts(0, a), sampler_parts(1, b));
    let mixed = settings.view.is_picture() && (settings.mix < 1.0 || mask.is_some());
    {
        with_depth!(request.depth, S => {
            let black = [S::default(); 4];
            let src = view_of::<S>(a, &black)?;
            let a = Sampler::new(src, a_scale, settings.filter, a_edge, a_pre);
            let b = Sampler::new(view_of::<S>(b, &black)?, b_scale, settings.filter, b_edge, b_pre);
            let b = kind.has_b().then_some(&b);
            if !mixed {
                job.draw(&a, b, rows);
                return Ok(());
            }
            // The effect in float, then mixed with the unwarped source A
            // (transparent outside it) and stored once.
            let mut effect = Image::new(rows.bounds, rows.channels);
            job.draw(&a, b, effect.view_mut().rows());
            let unwarped_filter = if request.ids { Filter::Nearest } else { Filter::Bilinear };
            let unwarped = Sampler::new(src, a_scale, unwarped_filter, EdgeMode::Black, a_pre);
            let identity = WarpMap::identity(rows.bounds, request.out_scale);
            let source = Warped::Map(&unwarped, &identity);
            let mut plane = mask.as_ref().map(|m| m(rows.bounds, request.out_scale));
            let mut amount = settings.mix as f32;
            if request.ids {
                // IDs are taken whole, from the effect or the source.
                amount = amount.round();
                for m in plane.iter_mut().flat_map(|p| p.data.iter_mut()) {
                    *m = m.round();
                }
            }
            let how = Mix {
                source: if job.premultiply[0] { Warped::Premultiplied(&source) } else { source },
                mask: plane.as_ref(),
                amount,
                invert: settings.mask_invert,
            };
            mix(&effect, &how, rows);
        })
    }
    Ok(())
}

/// The mask's alpha over a window at a scale, from the lent mask image.
type MaskPlane<'a> = Box<dyn Fn(RectI, PixelScale) -> Image + 'a>;

/// The lent mask as a maker of its alpha plane at its own depth: sampled at
/// the output's pixel centres, transparent outside its region.
fn mask_of(image: &HostImage) -> Outcome<MaskPlane<'_>> {
    let scale = image.info().pixel_scale();
    Ok(with_depth!(image.info().depth, M => {
        let view = image.view::<M>()?;
        Box::new(move |window: RectI, out_scale: PixelScale| {
            let s = Sampler::new(view, scale, Filter::Bilinear, EdgeMode::Black, true);
            mask_plane(Warped::Map(&s, &WarpMap::identity(window, out_scale)), window)
        }) as MaskPlane<'_>
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nodes::node::Node;
    use crate::nodes::{Morph, Warp};
    use morphfx::features::Feature;
    use morphfx::make_warp::WarpSettings;
    use ofx_layer::params::Params;
    use ofx_layer::plugin::Context;

    fn source(premultiplied: bool) -> Option<Source> {
        Some(Source {
            scale: PixelScale::UNIT,
            covers: RectD::new(0.0, 0.0, 64.0, 48.0),
            premultiplied,
        })
    }

    /// A render of a 64x48 frame's window (8, 8)-(24, 20), made by hand.
    fn request(t: f64, view: View) -> Request {
        let mut settings = Settings::defaults(<Morph as Node>::KIND);
        settings.view = view;
        let features = vec![Feature::line(
            [Vec2::new(10.0, 10.0), Vec2::new(50.0, 12.0)],
            [Vec2::new(12.0, 16.0), Vec2::new(48.0, 30.0)],
        )];
        let warp = WarpSettings {
            region: Some(RectD::new(0.0, 0.0, 64.0, 48.0)),
            ..WarpSettings::new(settings.warp.clone())
        };
        Request {
            time: 1.0,
            window: RectI::new(8, 8, 24, 20),
            sequential: false,
            interactive: false,
            settings,
            inputs: WarpInputs { features, warp, t },
            sources: [source(true), source(true)],
            depth: Depth::F32,
            out_scale: PixelScale::UNIT,
            project: (Vec2::new(0.0, 0.0), Vec2::new(64.0, 48.0)),
            work: None,
            timing: None,
            ids: false,
            fixed: None,
        }
    }

    /// Prepare makes each side's map exactly as the core does, over the
    /// render window only, and a second render of the same request finds
    /// them in the cache.
    #[test]
    fn prepare_makes_the_cores_maps_for_the_window_once() {
        let instance =
            NodeState::create(<Morph as Node>::KIND, Context::General, Params::unbound());
        let r = request(0.25, View::Morph);
        let job = prepare(<Morph as Node>::KIND, &instance, &r).expect("prepared");
        for (side, got) in [(Side::A, &job.map_a), (Side::B, &job.map_b)] {
            let got = got.as_ref().expect("a map per side");
            let want = make_warp::toward(&r.inputs.features, side, 0.25, &r.inputs.warp)
                .expect("warp")
                .map_window(r.window, PixelScale::UNIT);
            assert_eq!(**got, want, "{side:?}");
        }
        let again = prepare(<Morph as Node>::KIND, &instance, &r).expect("prepared");
        assert!(Arc::ptr_eq(
            job.map_a.as_ref().unwrap(),
            again.map_a.as_ref().unwrap()
        ));
        let later = request(0.75, View::Morph);
        let moved = prepare(<Morph as Node>::KIND, &instance, &later).expect("prepared");
        assert_ne!(job.map_a, moved.map_a, "another progress, another map");
    }

    /// Views take only the maps they draw: the Warp node never makes B's.
    #[test]
    fn prepare_makes_only_the_maps_a_view_draws() {
        let instance =
            NodeState::create(<Morph as Node>::KIND, Context::General, Params::unbound());
        let r = request(0.5, View::StmapB);
        let stmap_b = prepare(<Morph as Node>::KIND, &instance, &r).unwrap();
        assert!(stmap_b.map_a.is_none() && stmap_b.map_b.is_some());
        let r = request(0.5, View::WarpedA);
        let warp = prepare(<Warp as Node>::KIND, &instance, &r).unwrap();
        assert!(warp.map_a.is_some() && warp.map_b.is_none());
    }

    /// A straight source dissolved with a premultiplied one is brought to
    /// premultiplied colour; all-straight sources stay straight.
    #[test]
    fn straight_sources_are_premultiplied_only_beside_premultiplied_ones() {
        assert_eq!(premultiply(&[source(false), source(true)]), [true, false]);
        assert_eq!(premultiply(&[source(false), source(false)]), [false, false]);
        assert_eq!(premultiply(&[source(false), None]), [false, false]);
        assert_eq!(premultiply(&[None, None]), [false, false]);
    }
}
