//! `morphfx warp --layers`: a multi-layer EXR (beauty, normals, object IDs)
//! warped whole. Every layer equals that layer warped alone through the
//! ordinary path; the ID layer holds only IDs the source holds. The files
//! are made and read here with the `exr` crate directly, not the harness's
//! own EXR code.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use crate::common;
use crate::common::{morphfx_ok as ok, morphfx_said as morphfx};

use exr::prelude::*;

const W: usize = 72;
const H: usize = 48;
/// A line that moves: the warp is far from the identity.
const LINE: &str = "1=10,10,60,14,18,6,66,22";

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A channel's value at pixel (x, row from the top).
fn value(name: &str, x: usize, y: usize) -> f32 {
    let (xf, yf) = (x as f32, y as f32);
    match name {
        "R" => 0.5 + 0.4 * (xf * 0.31 + yf * 0.17).sin(),
        "G" => 0.5 + 0.4 * (xf * 0.13 - yf * 0.23).cos(),
        "B" => 0.3 + 0.2 * (xf * 0.07).sin(),
        "A" => 1.0,
        "N.X" => (xf * 0.05).sin(),
        "N.Y" => (yf * 0.07).cos(),
        "N.Z" => 0.25 + 0.01 * xf,
        // Object IDs in blocks: 1 to 12.
        "id" => (1 + x / 18 + 4 * (y / 16)) as f32,
        other => panic!("no channel {other}"),
    }
}

/// Float channels named `(name, value it holds)`, for the exr crate.
fn channels(list: &[(&str, &str)]) -> AnyChannels<FlatSamples> {
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = list
        .iter()
        .map(|(name, from)| {
            let samples = (0..W * H).map(|k| value(from, k % W, k / W)).collect();
            AnyChannel::new(*name, FlatSamples::F32(samples))
        })
        .collect();
    AnyChannels::sort(list)
}

/// A single-part float EXR holding `list` (full names), written by the
/// exr crate.
fn write_exr(path: &Path, list: &[(&str, &str)]) {
    let layer = Layer::new(
        Vec2(W, H),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        channels(list),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

/// Every channel of an EXR by full name, top row first.
fn read_exr(path: &Path) -> Vec<(String, Vec<f32>)> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .unwrap();
    let layer = image.layer_data;
    assert_eq!((layer.size.width(), layer.size.height()), (W, H));
    layer
        .channel_data
        .list
        .into_iter()
        .map(|c| {
            let samples = match c.sample_data {
                FlatSamples::F32(v) => v,
                FlatSamples::F16(v) => v.iter().map(|s| s.to_f32()).collect(),
                FlatSamples::U32(v) => v.iter().map(|s| *s as f32).collect(),
            };
            (c.name.to_string(), samples)
        })
        .collect()
}

fn channel<'a>(channels: &'a [(String, Vec<f32>)], name: &str) -> &'a [f32] {
    &channels
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("no channel {name}"))
        .1
}

fn warp(dir: &Path, input: &Path, out: &str, extra: &[&str]) -> PathBuf {
    let out = dir.join(out);
    let mut args = vec!["warp", "--line", LINE, "--input", s(input), "--t", "1"];
    args.extend(["-o", s(&out), "--float"]);
    args.extend(extra);
    ok(&args);
    out
}

#[test]
fn every_layer_warps_as_it_would_alone_and_ids_stay_ids() {
    let d = common::scratch("layers");
    let d = Path::new(&d);
    let all = [
        ("R", "R"),
        ("G", "G"),
        ("B", "B"),
        ("A", "A"),
        ("N.X", "N.X"),
        ("N.Y", "N.Y"),
        ("N.Z", "N.Z"),
        ("id", "id"),
    ];
    let multi = d.join("multi.exr");
    write_exr(&multi, &all);
    let warped = read_exr(&warp(d, &multi, "all.exr", &["--layers", "all"]));
    let names: BTreeSet<&str> = warped.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, all.iter().map(|(n, _)| *n).collect());

    // The beauty alone, through the ordinary path.
    let beauty = d.join("beauty.exr");
    write_exr(&beauty, &all[..4]);
    let alone = read_exr(&warp(d, &beauty, "beauty-out.exr", &[]));
    for c in ["R", "G", "B", "A"] {
        assert_eq!(channel(&warped, c), channel(&alone, c), "{c}");
    }
    // The normals alone, as the R, G and B of a plate of their own.
    let normals = d.join("normals.exr");
    write_exr(&normals, &[("R", "N.X"), ("G", "N.Y"), ("B", "N.Z")]);
    let alone = read_exr(&warp(d, &normals, "normals-out.exr", &[]));
    for (c, n) in [("R", "N.X"), ("G", "N.Y"), ("B", "N.Z")] {
        assert_eq!(channel(&warped, n), channel(&alone, c), "{n}");
    }
    // The IDs: sampled nearest, so only the source's IDs, moved with the
    // picture; the same as the IDs warped alone with the nearest filter.
    let ids: BTreeSet<u32> = (0..W * H)
        .map(|k| value("id", k % W, k / W) as u32)
        .collect();
    let out = channel(&warped, "id");
    for v in out {
        assert!(
            ids.contains(&(*v as u32)) && v.fract() == 0.0,
            "{v} is no ID"
        );
    }
    let source: Vec<f32> = (0..W * H).map(|k| value("id", k % W, k / W)).collect();
    assert!(out != source.as_slice(), "the IDs moved with the warp");
    let id_alone = d.join("id.exr");
    write_exr(&id_alone, &[("R", "id"), ("G", "id"), ("B", "id")]);
    let alone = read_exr(&warp(
        d,
        &id_alone,
        "id-out.exr",
        &["--param", "filter=nearest"],
    ));
    assert_eq!(out, channel(&alone, "R"));
    // Blended, the IDs would not stay IDs: the check above can fail.
    let blended = read_exr(&warp(
        d,
        &multi,
        "blended.exr",
        &["--layers", "all", "--id-layers", ""],
    ));
    assert_eq!(channel(&blended, "id"), out, "id is known by its name");
    let plain = read_exr(&warp(d, &id_alone, "id-blended.exr", &[]));
    assert!(
        channel(&plain, "R").iter().any(|v| v.fract() != 0.0),
        "bilinear blends neighbouring IDs"
    );
}

#[test]
fn a_list_of_layers_warps_those_and_user_ids_sample_nearest() {
    let d = common::scratch("layers-list");
    let d = Path::new(&d);
    let multi = d.join("multi.exr");
    write_exr(
        &multi,
        &[
            ("R", "R"),
            ("G", "G"),
            ("B", "B"),
            ("A", "A"),
            ("objects.R", "id"),
        ],
    );
    let out = read_exr(&warp(
        d,
        &multi,
        "objects.exr",
        &["--layers", "objects", "--id-layers", "objects"],
    ));
    assert_eq!(out.len(), 1, "only the layer asked for");
    assert!(channel(&out, "objects.R").iter().all(|v| v.fract() == 0.0));
}

#[test]
fn layers_refuse_what_they_cannot_do_with_exit_2() {
    let d = common::scratch("layers-bad");
    let d = Path::new(&d);
    let multi = d.join("multi.exr");
    write_exr(
        &multi,
        &[("R", "R"), ("G", "G"), ("B", "B"), ("N.X", "N.X")],
    );
    let bytes = std::fs::read(&multi).unwrap();
    let cut = d.join("cut.exr");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let (png, exr) = (d.join("out.png"), d.join("out.exr"));
    // `warp --line LINE --input INPUT --layers LAYERS MORE...` must exit 2
    // saying `says`, with nothing written.
    let refused = |input: &Path, layers: &str, more: &[&str], says: &str| {
        let mut args = vec![
            "warp",
            "--line",
            LINE,
            "--input",
            s(input),
            "--layers",
            layers,
        ];
        args.extend(more);
        let (code, err) = morphfx(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!exr.exists() && !png.exists(), "nothing written");
    };
    refused(&multi, "all", &["-o", s(&png)], "must be an EXR");
    let view = ["-o", s(&exr), "--view", "stmap"];
    refused(&multi, "all", &view, "--view stmap takes no layers");
    let stmap = ["-o", s(&exr), "--stmap", s(&png)];
    refused(
        &multi,
        "all",
        &stmap,
        "write the ST map in a run of its own",
    );
    let out = ["-o", s(&exr)];
    refused(&multi, "P", &out, "no such layer (it has rgba, N)");
    for spec in ["", ","] {
        refused(&multi, spec, &out, "expected rgba, all or a list");
    }
    refused(&cut, "all", &out, "truncated");
    refused(&cut, "all", &out, "cut.exr");
}

#[test]
fn the_parts_of_a_multi_part_file_name_their_layers() {
    let d = common::scratch("layers-parts");
    let d = Path::new(&d);
    let part = |name: &str, list: &[(&str, &str)]| {
        Layer::new(
            Vec2(W, H),
            LayerAttributes::named(name),
            Encoding::SMALL_LOSSLESS,
            channels(list),
        )
    };
    let parts: Layers<_> = [
        part("beauty", &[("R", "R"), ("G", "G"), ("B", "B"), ("A", "A")]),
        part("N", &[("X", "N.X"), ("Y", "N.Y"), ("Z", "N.Z")]),
    ]
    .into_iter()
    .collect();
    let multi = d.join("parts.exr");
    Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions((W, H))),
        parts,
    )
    .write()
    .to_file(&multi)
    .unwrap();
    let out = read_exr(&warp(d, &multi, "parts-out.exr", &["--layers", "N"]));
    let names: Vec<&str> = out.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["N.X", "N.Y", "N.Z"]);
    let single = d.join("single.exr");
    write_exr(
        &single,
        &[("R", "R"), ("N.X", "N.X"), ("N.Y", "N.Y"), ("N.Z", "N.Z")],
    );
    let alone = read_exr(&warp(d, &single, "single-out.exr", &["--layers", "N"]));
    assert_eq!(out, alone);
}

/// Nearest sampling keeps IDs whatever the method; the two-pass mesh warp,
/// whose Fant filter averages, takes the one-pass map for it.
#[test]
fn nearest_keeps_ids_under_every_method() {
    let d = common::scratch("layers-methods");
    let d = Path::new(&d);
    let ids = d.join("ids.exr");
    write_exr(&ids, &[("R", "id"), ("G", "id"), ("B", "id")]);
    let points = r#"[{"type": "point", "a": [[20, 20]], "b": [[24, 23]]},
        {"type": "point", "a": [[50, 30]], "b": [[47, 27]]},
        {"type": "point", "a": [[36, 12]], "b": [[38, 10]]}]"#;
    let mesh = r#"{"rows": 3, "cols": 3,
        "a": [[0,0],[36,0],[72,0],[0,24],[36,24],[72,24],[0,48],[36,48],[72,48]],
        "b": [[0,0],[36,0],[72,0],[0,24],[41,28],[72,24],[0,48],[36,48],[72,48]]}"#;
    for method in ["mesh", "triangles", "thin-plate", "mffd", "hybrid"] {
        let body = if method == "mesh" {
            format!(r#""mesh": {mesh}"#)
        } else {
            format!(r#""features": {points}"#)
        };
        let scene = d.join(format!("{method}.morph.json"));
        let text =
            format!(r#"{{"format": "morphfx-scene", "version": 1, "method": "{method}", {body}}}"#);
        std::fs::write(&scene, text).unwrap();
        let out = d.join(format!("{method}.exr"));
        ok(&[
            "warp",
            "--scene",
            s(&scene),
            "--input",
            s(&ids),
            "--t",
            "1",
            "--param",
            "filter=nearest",
            "-o",
            s(&out),
            "--float",
        ]);
        let warped = read_exr(&out);
        let r = channel(&warped, "R");
        assert!(
            r.iter()
                .all(|v| v.fract() == 0.0 && (1.0..=12.0).contains(v)),
            "{method}"
        );
        let source: Vec<f32> = (0..W * H).map(|k| value("id", k % W, k / W)).collect();
        assert!(r != source.as_slice(), "{method}: the IDs moved");
    }
}
