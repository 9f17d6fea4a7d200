//! `morphfx demo`: two procedural faces morphed through the plugin.

use std::path::{Path, PathBuf};

use morphfx::geom::RectI;
use morphfx::image::Image;

use super::job::{Job, MORPH_ID};
use crate::cli::Common;
use crate::host::HostError;
use crate::io::{self, ExrPrecision, Plate};

/// Two procedural plates with recognisable features: a warm disc face on A,
/// a cool rounded square face on B, eyes and mouth in different places.
pub fn demo(bundle_path: &Path, dir: &Path) -> Result<(), HostError> {
    let (w, h) = (320usize, 240usize);
    let b = RectI::from_size(w, h);
    let a = Image::from_fn(b, 4, |i, j, c| demo_face(i, j, c, false, (w, h)));
    let bb = Image::from_fn(b, 4, |i, j, c| demo_face(i, j, c, true, (w, h)));
    let plates = dir.join("plates");
    io::write(
        &plates.join("a.exr"),
        &Plate::new(a, (w, h)),
        ExrPrecision::Float,
    )?;
    io::write(
        &plates.join("b.exr"),
        &Plate::new(bb, (w, h)),
        ExrPrecision::Float,
    )?;
    let (cx, cy) = (160.0, 120.0);
    let scene = demo_scene((cx, cy));
    let s = |p: PathBuf| p.to_string_lossy().into_owned();
    // Writes `scene` to `name.morph.json` and renders frames 1-12 of the morph
    // of the two plates through it into `output` (plus `extra` views).
    let render =
        |name: &str, scene: &serde_json::Value, output: PathBuf, extra: Vec<(String, String)>| {
            let path = dir.join(format!("{name}.morph.json"));
            std::fs::write(
                &path,
                serde_json::to_string_pretty(scene).unwrap_or_default(),
            )
            .map_err(|e| HostError::failed(format!("{}: {e}", path.display())))?;
            Job {
                plugin: MORPH_ID,
                context: "OfxImageEffectContextGeneral",
                sources: vec![
                    ("SourceA".into(), s(plates.join("a.exr"))),
                    ("SourceB".into(), s(plates.join("b.exr"))),
                ],
                view: "morph".into(),
                extra,
                mattes: Vec::new(),
                common: Common {
                    scene: Some(path),
                    line: Vec::new(),
                    t: None,
                    param: Vec::new(),
                    frames: Some("1-12".into()),
                    output: s(output),
                    half: false,
                    float: true,
                    compression: None,
                    raw: false,
                },
            }
            .run(bundle_path)
        };
    render(
        "demo",
        &scene,
        dir.join("morph.####.exr"),
        vec![
            ("morph".into(), s(dir.join("preview/morph.####.png"))),
            ("stmap-a".into(), s(dir.join("stmap_a.####.exr"))),
        ],
    )?;

    // The same morph through the mesh and triangle methods: a 5 × 5 mesh whose
    // inner ring opens from the round face to the square one, and the
    // features above triangulated.
    let (nodes_a, nodes_b) = demo_mesh((w, h), (cx, cy));
    let mut mesh_scene = scene.clone();
    mesh_scene["method"] = "mesh".into();
    mesh_scene["mesh"] = serde_json::json!({ "rows": 5, "cols": 5, "a": nodes_a, "b": nodes_b });
    let mut triangles_scene = scene.clone();
    triangles_scene["method"] = "triangles".into();
    // And found from the plates alone, the features as anchors.
    let mut auto_scene = scene.clone();
    auto_scene["method"] = "auto".into();
    for (name, scene) in [
        ("mesh", mesh_scene),
        ("triangles", triangles_scene),
        ("auto", auto_scene),
    ] {
        render(
            name,
            &scene,
            dir.join(format!("{name}/morph.####.png")),
            Vec::new(),
        )?;
    }
    demo_report(bundle_path, dir);
    Ok(())
}

/// The demo plates: a round face (A) and a square one (B) on a gradient.
pub fn demo_face(i: i32, j: i32, c: usize, square: bool, (w, h): (usize, usize)) -> f32 {
    let (x, y) = (i as f32 + 0.5 - 160.0, j as f32 + 0.5 - 120.0);
    let inside = if square {
        x.abs().max(y.abs() * 1.1) < 85.0
    } else {
        (x * x + y * y).sqrt() < 90.0
    };
    let eyes = if square {
        [(-35.0, 35.0), (35.0, 35.0)]
    } else {
        [(-30.0, 25.0), (30.0, 25.0)]
    };
    let eye = eyes
        .iter()
        .any(|(ex, ey)| ((x - ex).powi(2) + (y - ey).powi(2)).sqrt() < 9.0);
    let mouth_y = if square { -40.0 } else { -35.0 };
    let mouth = (y - mouth_y).abs() < 4.0 && x.abs() < if square { 45.0 } else { 35.0 };
    let bg = [
        0.05 + 0.2 * (j as f32 / h as f32),
        0.08,
        0.12 + 0.2 * (i as f32 / w as f32),
        1.0,
    ];
    let skin = if square {
        [0.3, 0.55, 0.9, 1.0]
    } else {
        [0.95, 0.6, 0.3, 1.0]
    };
    if eye || mouth {
        [0.02, 0.02, 0.02, 1.0][c]
    } else if inside {
        skin[c] * (1.0 + 0.15 * ((x * 0.15).sin() * (y * 0.15).cos()))
    } else {
        bg[c]
    }
}

/// The demo scene: eyes, mouth and the face's outline, keyed over frames 1-12.
pub fn demo_scene((cx, cy): (f64, f64)) -> serde_json::Value {
    serde_json::json!({
        "format": "morphfx-scene", "version": 1, "method": "field",
        "field": { "a": 0.5, "b": 1.5, "p": 0.5, "interpolation": "endpoints" },
        "features": [
            { "name": "left eye", "type": "point", "a": [[cx - 30.0, cy + 25.0]], "b": [[cx - 35.0, cy + 35.0]] },
            { "name": "right eye", "type": "point", "a": [[cx + 30.0, cy + 25.0]], "b": [[cx + 35.0, cy + 35.0]] },
            { "name": "mouth", "type": "line", "a": [[cx - 35.0, cy - 35.0], [cx + 35.0, cy - 35.0]], "b": [[cx - 45.0, cy - 40.0], [cx + 45.0, cy - 40.0]] },
            { "name": "top", "type": "line", "a": [[cx - 60.0, cy + 66.0], [cx + 60.0, cy + 66.0]], "b": [[cx - 80.0, cy + 77.0], [cx + 80.0, cy + 77.0]] },
            { "name": "bottom", "type": "line", "a": [[cx + 60.0, cy - 66.0], [cx - 60.0, cy - 66.0]], "b": [[cx + 80.0, cy - 77.0], [cx - 80.0, cy - 77.0]] },
            { "name": "left", "type": "line", "a": [[cx - 90.0, cy - 30.0], [cx - 90.0, cy + 30.0]], "b": [[cx - 85.0, cy - 40.0], [cx - 85.0, cy + 40.0]] },
            { "name": "right", "type": "line", "a": [[cx + 90.0, cy + 30.0], [cx + 90.0, cy - 30.0]], "b": [[cx + 85.0, cy + 40.0], [cx + 85.0, cy - 40.0]] }
        ],
        "progress": [[1, 0.0], [12, 1.0]]
    })
}

/// A 5 × 5 mesh over the frame whose inner ring opens from the round
/// face to the square one: (A's nodes, B's nodes).
pub fn demo_mesh((w, h): (usize, usize), (cx, cy): (f64, f64)) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let mut nodes_a = Vec::new();
    let mut nodes_b = Vec::new();
    for r in 0..5 {
        for c in 0..5 {
            let p = [c as f64 * w as f64 / 4.0, r as f64 * h as f64 / 4.0];
            let inner = (1..4).contains(&r) && (1..4).contains(&c);
            let q = if inner && (r, c) != (2, 2) {
                [cx + (p[0] - cx) * 1.12, cy + (p[1] - cy) * 1.12]
            } else {
                p
            };
            nodes_a.push(p);
            nodes_b.push(q);
        }
    }
    (nodes_a, nodes_b)
}

/// Says where the demo wrote what.
pub fn demo_report(bundle_path: &Path, dir: &Path) {
    let plates = dir.join("plates");
    let scene_path = dir.join("demo.morph.json");
    println!(
        "MorphFX demo rendered through {}",
        crate::host::bundle_binary(bundle_path).display()
    );
    println!("  plates:   {}", plates.display());
    println!("  scene:    {}", scene_path.display());
    println!(
        "  morph:    {} (frames 1-12, float EXR)",
        dir.join("morph.####.exr").display()
    );
    println!(
        "  previews: {}",
        dir.join("preview/morph.####.png").display()
    );
    println!(
        "  ST maps:  {} (A's warp per frame)",
        dir.join("stmap_a.####.exr").display()
    );
    println!(
        "  methods:  {}, {} and {} (the same morph by mesh, by triangles and by auto, PNG)",
        dir.join("mesh/morph.####.png").display(),
        dir.join("triangles/morph.####.png").display(),
        dir.join("auto/morph.####.png").display()
    );
}
