//! The multi-plane extension as Natron offers it: a source with layers
//! besides its colour (normals, motion, an object ID, a second RGBA pass)
//! goes through the Warp and Morph nodes with the colour's warp. Every
//! plane must equal that plane warped alone as the node's colour; ID
//! planes hold only IDs the source has, and are never blended.

mod common;

use std::sync::{Arc, OnceLock};

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::host::planes::{self, COLOUR};
use morphfx_harness::host::{Bundle, Frame, HostOptions, Instance, OutputSpec};

use common::{bundle_path, Still};

const W: usize = 64;
const H: usize = 48;

/// The bundle in a host with the multi-plane extension (this test binary
/// loads it no other way: the plugin keeps one host's suites).
fn planar() -> &'static Bundle {
    static B: OnceLock<Bundle> = OnceLock::new();
    B.get_or_init(|| {
        let options = HostOptions {
            multi_plane: true,
            ..HostOptions::default()
        };
        Bundle::load_with(&bundle_path(), options).expect("the bundle loads")
    })
}

/// A layer of the source: its name, channel names and values.
struct Layer {
    name: &'static str,
    channels: &'static [&'static str],
    value: fn(i32, i32, usize, f32) -> f32,
}

fn smooth(i: i32, j: i32, c: usize, seed: f32) -> f32 {
    0.5 + 0.45 * (i as f32 * 0.23 + j as f32 * 0.31 + 1.7 * c as f32 + seed).sin()
}

/// Object IDs in 8 × 8 blocks, each its own whole number.
fn object_id(i: i32, j: i32, _: usize, seed: f32) -> f32 {
    ((i / 8) + 7 * (j / 8)) as f32 + 100.0 * seed
}

const LAYERS: [Layer; 4] = [
    Layer {
        name: "N",
        channels: &["X", "Y", "Z"],
        value: smooth,
    },
    Layer {
        name: "motion",
        channels: &["X", "Y"],
        value: smooth,
    },
    Layer {
        name: "objectId",
        channels: &["id"],
        value: object_id,
    },
    Layer {
        name: "diffuse",
        channels: &["R", "G", "B", "A"],
        value: smooth,
    },
];

fn plane_of(layer: &Layer) -> String {
    planes::plane(layer.name, layer.channels)
}

fn image(layer: &Layer, seed: f32) -> Image {
    let n = layer.channels.len();
    Image::from_fn(RectI::from_size(W, H), n, |i, j, c| {
        (layer.value)(i, j, c, seed + layer.name.len() as f32)
    })
}

/// `img` as four channels (the rest zero): how a layer goes through a node
/// as its colour, each channel filtered on its own.
fn padded(img: &Image) -> Image {
    Image::from_fn(img.bounds, 4, |i, j, c| {
        img.pixel(i, j).get(c).copied().unwrap_or(0.0)
    })
}

fn still(img: Image) -> Arc<Still> {
    Arc::new(Still(Arc::new(Frame::from_float_image(img))))
}

/// Connects `clip`: a textured RGBA colour and every layer of [`LAYERS`].
fn connect_layers(inst: &Instance<'_>, clip: &str, seed: f32) {
    common::connect_textured(inst, &[(clip, seed)], (W, H));
    let layers = LAYERS
        .iter()
        .map(|l| (plane_of(l), still(image(l, seed)) as _))
        .collect();
    inst.connect_planes(clip, layers).unwrap();
}

/// Two lines that cross over: a warp that moves every pixel differently.
fn set_lines(inst: &Instance<'_>) {
    let (low, high) = ([[16.0, 18.0], [48.0, 18.0]], [[14.0, 30.0], [50.0, 33.0]]);
    common::set_line_slots(inst, &[(low, high), (high, low)]);
    inst.set_double("progress", &[0.4], None).unwrap();
}

/// A node of the planar host over a `W × H` project, with [`set_lines`].
fn lined(plugin: &str, context: &str) -> Instance<'static> {
    let inst = planar().instance(plugin, context).unwrap();
    inst.set_project(W as f64, H as f64);
    set_lines(&inst);
    inst
}

fn spec() -> OutputSpec {
    OutputSpec {
        identity: false,
        ..OutputSpec::default()
    }
}

fn every_plane() -> Vec<String> {
    std::iter::once(COLOUR.to_owned())
        .chain(LAYERS.iter().map(plane_of))
        .collect()
}

/// The largest difference between `got`'s channels and the first ones of
/// `want`, where both cover the same pixels.
fn worst(got: &Image, want: &Image) -> f32 {
    let mut worst = 0f32;
    for j in got.bounds.y1..got.bounds.y2 {
        for i in got.bounds.x1..got.bounds.x2 {
            for c in 0..got.channels {
                worst = worst.max((got.pixel(i, j)[c] - want.pixel(i, j)[c]).abs());
            }
        }
    }
    worst
}

#[test]
fn the_nodes_say_they_make_every_plane_of_their_source() {
    let warp = planar()
        .instance("net.morphfx.Warp", "OfxImageEffectContextFilter")
        .unwrap();
    let props = warp.descriptor_props();
    assert_eq!(props.ints(planes::MULTI_PLANAR), vec![1]);
    connect_layers(&warp, "Source", 0.0);
    let answer = warp.clip_planes(0.0).unwrap().expect("an answer");
    assert_eq!(answer.needs("Output"), every_plane());
    assert_eq!(answer.needs("Source"), every_plane());
    assert_eq!(answer.needs("Mask"), vec![COLOUR.to_owned()]);
    assert_eq!(answer.pass_through.as_deref(), Some("Source"));
    // Morph: B is asked only for the planes it has.
    let morph = planar()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    connect_layers(&morph, "SourceA", 0.0);
    common::connect_textured(&morph, &[("SourceB", 1.0)], (W, H));
    let only_n = vec![(plane_of(&LAYERS[0]), still(image(&LAYERS[0], 1.0)) as _)];
    morph.connect_planes("SourceB", only_n).unwrap();
    let answer = morph.clip_planes(0.0).unwrap().expect("an answer");
    assert_eq!(answer.needs("Output"), every_plane());
    assert_eq!(
        answer.needs("SourceB"),
        vec![COLOUR.to_owned(), plane_of(&LAYERS[0])]
    );
}

/// Every plane's buffer holds NaN in a debug build (the tests') until the
/// plugin writes it, as the colour output's does: pixels outside a render
/// window read NaN in each plane, and those inside are the full render's.
#[test]
fn unwritten_pixels_of_every_plane_read_nan() {
    let inst = lined("net.morphfx.Warp", "OfxImageEffectContextFilter");
    connect_layers(&inst, "Source", 0.0);
    let full = inst.render_planes(0.0, spec(), &every_plane()).unwrap();
    let window = RectI::new(8, 8, 40, 30);
    let part = OutputSpec {
        window: Some(window),
        ..spec()
    };
    let part = inst.render_planes(0.0, part, &every_plane()).unwrap();
    for ((plane, want), (_, got)) in full.iter().zip(&part) {
        let (want, got) = (want.to_image(), got.to_image());
        for j in want.bounds.y1..want.bounds.y2 {
            for i in want.bounds.x1..want.bounds.x2 {
                let (g, w) = (got.pixel(i, j), want.pixel(i, j));
                let inside =
                    (window.x1..window.x2).contains(&i) && (window.y1..window.y2).contains(&j);
                if inside {
                    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert_eq!(bits(g), bits(w), "{plane} ({i}, {j}) in the window");
                } else {
                    let poisoned = g.iter().all(|v| v.is_nan());
                    assert_eq!(
                        poisoned,
                        cfg!(debug_assertions),
                        "{plane} ({i}, {j}): {g:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn every_plane_equals_that_plane_warped_alone() {
    let inst = lined("net.morphfx.Warp", "OfxImageEffectContextFilter");
    connect_layers(&inst, "Source", 0.0);
    let colour_alone = inst.render(0.0, spec()).unwrap().to_image();
    let rendered = inst.render_planes(0.0, spec(), &every_plane()).unwrap();
    assert_eq!(rendered.len(), 1 + LAYERS.len());
    let colour = rendered[0].1.to_image();
    assert!(
        colour
            .data
            .iter()
            .zip(&colour_alone.data)
            .all(|(a, b)| a.to_bits() == b.to_bits()),
        "the colour plane has the bits of a render without planes"
    );
    for (layer, (plane, out)) in LAYERS.iter().zip(&rendered[1..]) {
        assert_eq!(plane, &plane_of(layer));
        let out = out.to_image();
        assert_eq!(out.channels, layer.channels.len(), "{}", layer.name);
        let source = image(layer, 0.0);
        let ids = layer.name == "objectId";
        // The same plane as the node's colour, through the same warp.
        inst.connect("Source", still(padded(&source))).unwrap();
        inst.set_choice("filter", if ids { "nearest" } else { "bilinear" })
            .unwrap();
        let alone = inst.render(0.0, spec()).unwrap().to_image();
        inst.set_choice("filter", "bilinear").unwrap();
        let moved = out
            .data
            .iter()
            .zip(&source.data)
            .filter(|(a, b)| a != b)
            .count();
        // IDs are constant in blocks: only pixels near block edges change.
        let share = if ids { 20 } else { 4 };
        assert!(
            moved > out.data.len() / share,
            "{}: the warp moves it ({moved})",
            layer.name
        );
        let tolerance = if ids { 0.0 } else { 1e-5 };
        let differs = worst(&out, &alone);
        assert!(
            differs <= tolerance,
            "{}: {differs} from the plane warped alone",
            layer.name
        );
        if ids {
            let known: Vec<u32> = source.data.iter().map(|v| v.to_bits()).collect();
            assert!(
                out.data.iter().all(|v| known.contains(&v.to_bits())),
                "the ID plane holds only IDs the source has"
            );
        }
    }
    // A layer the user lists in ID Layers is sampled nearest too.
    inst.set_string("id_layers", "motion, N").unwrap();
    let n = &LAYERS[0];
    let out = inst.render_planes(0.0, spec(), &[plane_of(n)]).unwrap();
    inst.connect("Source", still(padded(&image(n, 0.0))))
        .unwrap();
    inst.set_choice("filter", "nearest").unwrap();
    let alone = inst.render(0.0, spec()).unwrap().to_image();
    assert_eq!(
        worst(&out[0].1.to_image(), &alone),
        0.0,
        "N listed: nearest"
    );
    inst.set_choice("filter", "bilinear").unwrap();
    inst.set_string("id_layers", "").unwrap();
    common::connect_textured(&inst, &[("Source", 0.0)], (W, H));
}

/// The Morph node dissolves its planes as its colour, but an ID plane
/// switches from A's IDs to B's at half way, and Mix below one half keeps
/// the source's IDs: no ID is ever a blend of two.
#[test]
fn the_morph_node_never_blends_ids() {
    let inst = lined("net.morphfx.Morph", "OfxImageEffectContextGeneral");
    connect_layers(&inst, "SourceA", 0.0);
    connect_layers(&inst, "SourceB", 1.0);
    let (n, id) = (&LAYERS[0], &LAYERS[2]);
    let asked = [COLOUR.to_owned(), plane_of(n), plane_of(id)];
    let alone = |layer: &Layer, view: &str, filter: &str| {
        inst.connect("SourceA", still(padded(&image(layer, 0.0))))
            .unwrap();
        inst.connect("SourceB", still(padded(&image(layer, 1.0))))
            .unwrap();
        inst.set_choice("view", view).unwrap();
        inst.set_choice("filter", filter).unwrap();
        let out = inst.render(0.0, spec()).unwrap().to_image();
        inst.set_choice("view", "morph").unwrap();
        inst.set_choice("filter", "bilinear").unwrap();
        common::connect_textured(&inst, &[("SourceA", 0.0), ("SourceB", 1.0)], (W, H));
        out
    };
    for (t, ids_from) in [(0.3, "warped-a"), (0.7, "warped-b")] {
        inst.set_double("progress", &[t], None).unwrap();
        let out = inst.render_planes(0.0, spec(), &asked).unwrap();
        let (got_n, got_id) = (out[1].1.to_image(), out[2].1.to_image());
        let differs = worst(&got_n, &alone(n, "morph", "bilinear"));
        assert!(differs <= 1e-5, "t {t}: N {differs} from N morphed alone");
        let differs = worst(&got_id, &alone(id, ids_from, "nearest"));
        assert_eq!(differs, 0.0, "t {t}: the IDs are {ids_from}'s");
    }
    // Mix 0.3 rounds to none of the effect: the IDs stay A's, unwarped.
    inst.set_double("mix", &[0.3], None).unwrap();
    let out = inst.render_planes(0.0, spec(), &asked).unwrap();
    let source = image(id, 0.0);
    assert_eq!(
        out[2].1.to_image().data,
        source.data,
        "mix 0.3: A's IDs in place"
    );
    // The colour is mixed as ever (only IDs round the Mix).
    let colour = out[0].1.to_image();
    let mixed = inst.render(0.0, spec()).unwrap().to_image();
    assert_eq!(colour.data, mixed.data);
    inst.set_double("mix", &[1.0], None).unwrap();
}

/// With motion blur, a layer blurs as it would as the node's picture; an
/// ID layer is not blurred (a mean of IDs is no ID): it is the frame's.
/// In a view that is not a picture (the ST map here) the colour shows it,
/// and every other layer is the warped source.
#[test]
fn layers_blur_as_pictures_ids_do_not_and_diagnostics_leave_them_warped() {
    let inst = lined("net.morphfx.Warp", "OfxImageEffectContextFilter");
    inst.set_double("progress", &[0.0], Some(0.0)).unwrap();
    inst.set_double("progress", &[1.0], Some(10.0)).unwrap();
    connect_layers(&inst, "Source", 0.0);
    let (n, id) = (&LAYERS[0], &LAYERS[2]);
    let asked = [plane_of(n), plane_of(id)];
    let planes_at = |blur: i32, view: &str| {
        inst.set_int("motion_blur", blur).unwrap();
        inst.set_choice("view", view).unwrap();
        let out = inst.render_planes(5.0, spec(), &asked).unwrap();
        inst.set_int("motion_blur", 0).unwrap();
        inst.set_choice("view", "warped").unwrap();
        (out[0].1.to_image(), out[1].1.to_image())
    };
    let alone = |layer: &Layer, blur: i32, filter: &str| {
        inst.connect("Source", still(padded(&image(layer, 0.0))))
            .unwrap();
        inst.set_int("motion_blur", blur).unwrap();
        inst.set_choice("filter", filter).unwrap();
        let out = inst.render(5.0, spec()).unwrap().to_image();
        inst.set_int("motion_blur", 0).unwrap();
        inst.set_choice("filter", "bilinear").unwrap();
        common::connect_textured(&inst, &[("Source", 0.0)], (W, H));
        out
    };
    inst.set_double("shutter", &[2.0], None).unwrap();
    let (blurred_n, blurred_id) = planes_at(8, "warped");
    let (sharp_n, sharp_id) = planes_at(0, "warped");
    assert!(worst(&blurred_n, &sharp_n) > 0.01, "the blur moves N");
    assert!(
        worst(&blurred_n, &alone(n, 8, "bilinear")) <= 1e-5,
        "N blurs as a picture"
    );
    assert_eq!(blurred_id.data, sharp_id.data, "the IDs are the frame's");
    assert_eq!(worst(&sharp_id, &alone(id, 0, "nearest")), 0.0);
    let (st_n, st_id) = planes_at(0, "stmap");
    assert!(
        worst(&st_n, &sharp_n) <= 0.0,
        "the ST map view leaves N warped"
    );
    assert_eq!(st_id.data, sharp_id.data);
}

/// A layer Source B lacks dissolves with transparent black.
#[test]
fn a_layer_source_b_lacks_dissolves_with_black() {
    let inst = lined("net.morphfx.Morph", "OfxImageEffectContextGeneral");
    connect_layers(&inst, "SourceA", 0.0);
    common::connect_textured(&inst, &[("SourceB", 1.0)], (W, H));
    inst.connect_planes("SourceB", Vec::new()).unwrap();
    let n = &LAYERS[0];
    let got = inst.render_planes(0.0, spec(), &[plane_of(n)]).unwrap()[0]
        .1
        .to_image();
    let a = image(n, 0.0);
    inst.connect("SourceA", still(padded(&a))).unwrap();
    inst.connect("SourceB", still(Image::new(a.bounds, 4)))
        .unwrap();
    let want = inst.render(0.0, spec()).unwrap().to_image();
    assert!(worst(&got, &want) <= 1e-5);
    // At progress 0.4 black B keeps 0.6 of A, whose N is at most 0.95.
    let most = got.data.iter().fold(0f32, |m, v| m.max(*v));
    assert!(most > 0.4 && most <= 0.6 * 0.95 + 1e-4, "{most}");
}

/// The Mask acts on an ID layer as a switch at one half: where it is
/// below, the source's IDs stay in place; above, the warped IDs.
#[test]
fn the_mask_switches_ids_whole() {
    let inst = lined("net.morphfx.Warp", "OfxImageEffectContextFilter");
    connect_layers(&inst, "Source", 0.0);
    let id = &LAYERS[2];
    let asked = [plane_of(id)];
    let warped = inst.render_planes(0.0, spec(), &asked).unwrap()[0]
        .1
        .to_image();
    for (alpha, want) in [(0.3, image(id, 0.0)), (0.7, warped)] {
        let mask = Image::from_fn(RectI::from_size(W, H), 1, |_, _, _| alpha);
        inst.connect("Mask", still(mask)).unwrap();
        let got = inst.render_planes(0.0, spec(), &asked).unwrap()[0]
            .1
            .to_image();
        assert_eq!(got.data, want.data, "mask {alpha}");
    }
    inst.disconnect("Mask").unwrap();
}
