//! A mesh warp rendered in tiles, as hosts that support tiles ask for it,
//! has the bits of the whole frame: the two-pass and one-pass pictures,
//! the ST maps and the folds view, at full and half render scale. (Before
//! the one-pass map's grid was fixed in the image, 8 tiles of its ST map
//! differed from the whole frame in 1 362 samples.)

mod common;

use morphfx_harness::host::OutputSpec;

use common::bundle;

const W: usize = 96;
const H: usize = 64;

/// A 4 × 4 grid over the frame with B's two middle nodes moved.
fn scene(pass: &str) -> String {
    let nodes = |moved: bool| {
        let mut out = Vec::new();
        for r in 0..4 {
            for c in 0..4 {
                let (mut x, mut y) = (c as f64 * 32.0, r as f64 * 64.0 / 3.0);
                if moved && (r == 1 || r == 2) && (c == 1 || c == 2) {
                    x += if c == 1 { 6.0 } else { -4.0 };
                    y += if r == 1 { 3.0 } else { -5.0 };
                }
                out.push(format!("[{x}, {y}]"));
            }
        }
        format!("[{}]", out.join(", "))
    };
    format!(
        r#"{{"method": "mesh", "mesh": {{"rows": 4, "cols": 4, "pass": "{pass}",
            "a": {}, "b": {}}}}}"#,
        nodes(false),
        nodes(true)
    )
}

#[test]
fn a_mesh_rendered_in_tiles_has_the_whole_frames_bits() {
    let inst = bundle()
        .instance("net.morphfx.Morph", "OfxImageEffectContextGeneral")
        .unwrap();
    common::connect_textured(&inst, &[("SourceA", 0.0), ("SourceB", 1.9)], (W, H));
    inst.set_project(W as f64, H as f64);
    inst.set_int("line_count", 0).unwrap();
    inst.set_double("progress", &[0.4], None).unwrap();
    for pass in ["two-pass", "one-pass"] {
        inst.set_string("scene_text", &scene(pass)).unwrap();
        for view in ["morph", "stmap-a", "folds"] {
            inst.set_choice("view", view).unwrap();
            for scale in [1.0, 0.5] {
                let spec = |tiles| OutputSpec {
                    depth: "OfxBitDepthFloat",
                    identity: false,
                    render_scale: (scale, scale),
                    tiles,
                    ..OutputSpec::default()
                };
                let whole = inst.render(0.0, spec(1)).unwrap().to_image();
                for tiles in [2, 5, 8] {
                    let tiled = inst.render(0.0, spec(tiles)).unwrap().to_image();
                    let differ = whole
                        .data
                        .iter()
                        .zip(&tiled.data)
                        .filter(|(a, b)| a.to_bits() != b.to_bits())
                        .count();
                    assert_eq!(
                        differ, 0,
                        "{pass}, {view} view, render scale {scale}, {tiles} tiles: samples \
                         that differ from the whole frame's"
                    );
                }
            }
        }
    }
}
