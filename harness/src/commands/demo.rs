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
                layers: None,
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
            ("ghost".into(), s(dir.join("ghost.####.exr"))),
        ],
    )?;

    // The same morph through the mesh and triangle methods: a mesh whose
    // nodes follow the features (the face opening from round to square, the
    // eyes and mouth moving), and the features triangulated.
    let (nodes_a, nodes_b) = demo_mesh((w, h), &scene)?;
    let mut mesh_scene = scene.clone();
    mesh_scene["method"] = "mesh".into();
    mesh_scene["mesh"] = serde_json::json!({
        "rows": MESH_NODES, "cols": MESH_NODES, "a": nodes_a, "b": nodes_b
    });
    let mut triangles_scene = scene.clone();
    triangles_scene["method"] = "triangles".into();
    // And found from the plates alone: no features (as anchors they pull
    // against the work the search minimises and tear the mouth here).
    let mut auto_scene = scene.clone();
    auto_scene["method"] = "auto".into();
    auto_scene["features"] = serde_json::json!([]);
    for (name, scene) in [
        ("mesh", mesh_scene),
        ("triangles", triangles_scene),
        ("auto", auto_scene),
    ] {
        render(
            name,
            &scene,
            dir.join(format!("{name}/morph.####.png")),
            vec![(
                "ghost".into(),
                s(dir.join(format!("{name}/ghost.####.exr"))),
            )],
        )?;
    }
    let mut ghosts = vec![("field", ghost_figures(&dir.join("ghost.0006.exr"))?)];
    for name in ["mesh", "triangles", "auto"] {
        let figures = ghost_figures(&dir.join(format!("{name}/ghost.0006.exr")))?;
        ghosts.push((name, figures));
    }
    let sheet = contact_sheet(dir)?;
    demo_report(bundle_path, dir, &ghosts, &sheet);
    Ok(())
}

/// What each method of the demo shows, in the words its report uses.
const SHOWS: [(&str, &str); 4] = [
    (
        "field",
        "Beier-Neely line pairs: the eyes ringed, the mouth outlined, \
            the face's outline ray by ray",
    ),
    (
        "mesh",
        "a 33 x 33 mesh (two-pass Catmull-Rom) whose nodes follow the same features",
    ),
    (
        "triangles",
        "every feature point triangulated, each triangle warped affinely",
    ),
    (
        "auto",
        "found from the two pictures alone by least work, no features given",
    ),
];

/// The frames of the demo's morph.
const FRAMES: std::ops::RangeInclusive<i64> = 1..=12;

/// A middle frame's ghost (the mean |warped A − warped B| per pixel):
/// its mean over the frame, and the share of pixels above 0.1, where
/// doubled edges show.
fn ghost_figures(path: &Path) -> Result<(f64, f64), HostError> {
    let ghost = io::read(path)?.image;
    let alpha: Vec<f32> = ghost.data.chunks(4).map(|p| p[3]).collect();
    let n = alpha.len().max(1) as f64;
    let mean = alpha.iter().map(|a| *a as f64).sum::<f64>() / n;
    let bright = alpha.iter().filter(|a| **a > 0.1).count() as f64 / n;
    Ok((mean, bright))
}

/// Every frame of the morph at half size in a grid of four columns, as
/// one sRGB PNG: the whole demo at a glance.
fn contact_sheet(dir: &Path) -> Result<PathBuf, HostError> {
    const COLUMNS: usize = 4;
    let frames: Vec<Image> = FRAMES
        .map(|f| io::read(&dir.join(format!("morph.{f:04}.exr"))).map(|p| p.image))
        .collect::<Result<_, _>>()?;
    let (w, h) = (frames[0].width() / 2, frames[0].height() / 2);
    let rows = frames.len().div_ceil(COLUMNS);
    let (sw, sh) = (COLUMNS * w, rows * h);
    // Rows of the sheet count from the bottom: the first frame goes top left.
    let sheet = Image::from_fn(RectI::from_size(sw, sh), 4, |i, j, c| {
        let (col, row) = (i as usize / w, (sh - 1 - j as usize) / h);
        let Some(frame) = frames.get(row * COLUMNS + col) else {
            return if c == 3 { 1.0 } else { 0.0 };
        };
        let (x, y) = (
            2 * (i as usize % w),
            2 * (h - 1 - (sh - 1 - j as usize) % h),
        );
        let mut sum = 0.0;
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            sum += frame.pixel((x + dx) as i32, (y + dy) as i32)[c];
        }
        sum / 4.0
    });
    let path = dir.join("contact-sheet.png");
    io::write(&path, &Plate::new(sheet, (sw, sh)), ExrPrecision::Float)?;
    Ok(path)
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
    // Close tones, so the ghost view shows where shapes disagree rather
    // than the change of colour.
    let skin = if square {
        [0.85, 0.62, 0.42, 1.0]
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

/// Points of the outline, one per `OUTLINE_SEGMENTS`-th turn: A's disc and
/// B's square face met by the same ray from the centre.
const OUTLINE_SEGMENTS: usize = 32;

/// The demo scene: eyes and mouth as lines across them, and the face's
/// outline as a closed polyline from the disc to the square, ray by ray, so
/// every edge of A lands on B's (its ghost view stays dark).
pub fn demo_scene((cx, cy): (f64, f64)) -> serde_json::Value {
    let ray = |k: usize| {
        let a = std::f64::consts::TAU * k as f64 / OUTLINE_SEGMENTS as f64;
        let (c, s) = (a.cos(), a.sin());
        // The square face: |x| < 85, |y| < 85 / 1.1 (see `demo_face`).
        let r = (85.0 / c.abs().max(1e-9)).min(85.0 / 1.1 / s.abs().max(1e-9));
        ([cx + 90.0 * c, cy + 90.0 * s], [cx + r * c, cy + r * s])
    };
    let (outline_a, outline_b): (Vec<[f64; 2]>, Vec<[f64; 2]>) =
        (0..OUTLINE_SEGMENTS).map(ray).unzip();
    // The mouth's bar outlined (a line along it left its edges a pixel
    // apart on the two sides), and each eye ringed, so the whole disc
    // moves with it (a line across an eye held only its middle, and the
    // field doubled its top and bottom).
    let bar = |(x, y): (f64, f64), half: f64| {
        let (x0, x1, y0, y1) = (cx + x - half, cx + x + half, cy + y - 4.0, cy + y + 4.0);
        [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
    };
    let ring = |(x, y): (f64, f64)| -> Vec<[f64; 2]> {
        (0..8)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 8.0;
                [cx + x + 9.0 * a.cos(), cy + y + 9.0 * a.sin()]
            })
            .collect()
    };
    serde_json::json!({
        "format": "morphfx-scene", "version": 1, "method": "field",
        "field": { "a": 0.5, "b": 1.5, "p": 0.5, "interpolation": "endpoints" },
        "features": [
            { "name": "left eye", "type": "polyline", "closed": true, "a": ring((-30.0, 25.0)), "b": ring((-35.0, 35.0)) },
            { "name": "right eye", "type": "polyline", "closed": true, "a": ring((30.0, 25.0)), "b": ring((35.0, 35.0)) },
            { "name": "mouth", "type": "polyline", "closed": true, "a": bar((0.0, -35.0), 35.0), "b": bar((0.0, -40.0), 45.0) },
            { "name": "outline", "type": "polyline", "closed": true, "a": outline_a, "b": outline_b }
        ],
        "progress": [[1, 0.0], [12, 1.0]]
    })
}

/// A mesh's nodes on A and on B, row by row.
type MeshNodes = (Vec<[f64; 2]>, Vec<[f64; 2]>);

/// Nodes per side of the demo's mesh: cells of 10 × 7.5 px, fine enough
/// for the eyes (18 px across) to move on their own.
const MESH_NODES: usize = 33;

/// An even mesh over the frame on A, and on B where the scene's features
/// carry each node: the triangles warp of `scene` (exact at every feature
/// point, the frame's border pinned) read at the nodes. (A's nodes, B's.)
pub fn demo_mesh(
    (w, h): (usize, usize),
    scene: &serde_json::Value,
) -> Result<MeshNodes, HostError> {
    use morphfx::features::Side;
    use morphfx::geom::{RectD, Vec2};
    let mut triangles = scene.clone();
    triangles["method"] = "triangles".into();
    let parsed = morphfx::scene::Scene::read(&triangles.to_string())
        .map_err(|e| HostError::failed(format!("the demo scene: {e}")))?;
    let mut settings = parsed.warp_settings_at(0.0);
    settings.region = Some(RectD::new(0.0, 0.0, w as f64, h as f64));
    // B's side at t = 0: each point of A's picture to where it is on B.
    let onto_b = morphfx::make_warp::toward(&parsed.features, Side::B, 0.0, &settings)
        .map_err(|e| HostError::failed(format!("the demo mesh: {e}")))?;
    let last = (MESH_NODES - 1) as f64;
    let mut nodes_a = Vec::new();
    let mut nodes_b = Vec::new();
    for r in 0..MESH_NODES {
        for c in 0..MESH_NODES {
            let p = Vec2::new(c as f64 * w as f64 / last, r as f64 * h as f64 / last);
            let border = r == 0 || c == 0 || r == MESH_NODES - 1 || c == MESH_NODES - 1;
            let q = if border { p } else { onto_b.map(p) };
            nodes_a.push([p.x, p.y]);
            nodes_b.push([q.x, q.y]);
        }
    }
    Ok((nodes_a, nodes_b))
}

/// Says where the demo wrote what, how well its features line up, and,
/// last, the one picture to look at.
pub fn demo_report(bundle_path: &Path, dir: &Path, ghosts: &[(&str, (f64, f64))], sheet: &Path) {
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
    println!(
        "  ghost:    {} and each method's ghost.####.exr (where the warped plates still disagree)",
        dir.join("ghost.####.exr").display(),
    );
    println!(
        "what each method shows, and its ghost at frame 6 (mean; \
        share of pixels above 0.1, where edges double):"
    );
    for (name, (ghost, bright)) in ghosts {
        let shows = SHOWS.iter().find(|(n, _)| n == name).map_or("", |(_, s)| s);
        println!("  {name:<9} {ghost:.3}; {:>4.1}%  {shows}", 100.0 * bright);
    }
    println!("contact sheet: {}", sheet.display());
}
