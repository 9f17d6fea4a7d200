//! `morphfx bench`: a generated shot morphed and timed as a user runs it,
//! beside OpenImageIO copying the same plates.

pub mod drag;

use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::Instant;

use morphfx::geom::RectI;
use morphfx::image::Image;

use crate::cli::Common;
use crate::commands::job::{Job, MORPH_ID};
use crate::host::HostError;
use crate::io::{self, ExrPrecision, Plate};
use crate::sequence::frame_path;

/// [`bench()`] in `dir`, kept; without one, in a temporary folder removed
/// when it ends (a 1080p run writes about 330 MB).
pub fn bench_in(
    bundle_path: &Path,
    dir: Option<&Path>,
    frames: usize,
    size: (usize, usize),
) -> Result<(), HostError> {
    if let Some(dir) = dir {
        return bench(bundle_path, dir, frames, size);
    }
    let scratch = std::env::temp_dir().join(format!("morphfx-bench-{}", std::process::id()));
    let result = bench(bundle_path, &scratch, frames, size);
    let _ = std::fs::remove_dir_all(&scratch);
    result
}

/// Plate sequences A and B of `frames` frames (a drifting pattern each), a
/// scene of 20 keyframed lines, then the morph of the whole range timed as a
/// user runs it: read plates, render through the bundle, write float EXR.
pub fn bench(
    bundle_path: &Path,
    dir: &Path,
    frames: usize,
    (w, h): (usize, usize),
) -> Result<(), HostError> {
    if frames == 0 || w < 16 || h < 16 {
        return Err(HostError::bad("bench needs at least 1 frame of 16x16"));
    }
    let plates = dir.join("plates");
    eprintln!(
        "writing {frames} frames of {w}x{h} plates A and B to {}",
        plates.display()
    );
    for f in 1..=frames as i64 {
        for (name, seed) in [("a", 0.0f32), ("b", 2.1)] {
            let drift = f as f32 * 1.5;
            let image = Image::from_fn(RectI::from_size(w, h), 4, |i, j, c| {
                let (x, y) = (i as f32 + drift, j as f32);
                if c == 3 {
                    1.0
                } else {
                    0.5 + 0.4 * ((x * 0.013 + seed) * (c as f32 + 1.0)).sin() * (y * 0.021).cos()
                }
            });
            io::write(
                &frame_path(
                    &plates.join(format!("{name}.####.exr")).to_string_lossy(),
                    f,
                ),
                &Plate::new(image, (w, h)),
                // Half float, as camera plates and their scans come.
                ExrPrecision::Half,
            )?;
        }
    }
    // 20 lines over the frame, moving a little between the first and last key.
    let (fw, fh) = (w as f64, h as f64);
    let line = |k: usize, shift: f64| {
        let (x, y) = (
            fw * (0.1 + 0.8 * ((k * 7) % 20) as f64 / 20.0),
            fh * (0.1 + 0.8 * ((k * 13) % 20) as f64 / 20.0),
        );
        let len = fw * 0.06;
        serde_json::json!({
            "type": "line",
            "a": [[x, y], [x + len, y + 0.3 * len]],
            "b": [[x + shift, y - shift], [x + len + shift, y + 0.3 * len + 0.5 * shift]]
        })
    };
    let key = |frame: usize, shift: f64| serde_json::json!({ "frame": frame, "features": (0..20).map(|k| line(k, shift)).collect::<Vec<_>>() });
    let scene = serde_json::json!({
        "format": "morphfx-scene", "version": 1, "method": "field",
        "keyframes": [key(1, fw * 0.01), key(frames, fw * 0.02)],
        "progress": [[1, 0.0], [frames, 1.0]]
    });
    let scene_path = dir.join("bench.morph.json");
    std::fs::write(&scene_path, scene.to_string())
        .map_err(|e| HostError::failed(format!("{}: {e}", scene_path.display())))?;
    let s = |p: PathBuf| p.to_string_lossy().into_owned();
    eprintln!("rendering the morph of frames 1-{frames}");
    let started = Instant::now();
    Job {
        plugin: MORPH_ID,
        context: "OfxImageEffectContextGeneral",
        sources: vec![
            ("SourceA".into(), s(plates.join("a.####.exr"))),
            ("SourceB".into(), s(plates.join("b.####.exr"))),
        ],
        view: "morph".into(),
        extra: vec![],
        mattes: Vec::new(),
        common: Common {
            scene: Some(scene_path),
            line: Vec::new(),
            t: None,
            param: Vec::new(),
            frames: Some(format!("1-{frames}")),
            output: s(dir.join("morph.####.exr")),
            half: false,
            float: false,
            compression: None,
            raw: false,
        },
        layers: None,
    }
    .run(bundle_path)?;
    let took = started.elapsed().as_secs_f64();
    compare_with_oiiotool(&plates, frames, took);
    Ok(())
}

/// Times OpenImageIO copying sequence A (read and write, no render), when
/// `oiiotool` is installed, and says how the morph compares: a peer run on
/// the same machine, in the same run.
pub fn compare_with_oiiotool(plates: &Path, frames: usize, morph_secs: f64) {
    let copy = plates.with_file_name("oiiotool-copy");
    let _ = std::fs::create_dir_all(&copy);
    let started = Instant::now();
    let status = std::process::Command::new("oiiotool")
        .arg("--frames")
        .arg(format!("1-{frames}"))
        .arg(plates.join("a.#.exr"))
        .arg("-o")
        .arg(copy.join("a.#.exr"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
    match status {
        Ok(s) if s.success() => {
            let secs = started.elapsed().as_secs_f64();
            eprintln!(
                "oiiotool copies sequence A ({frames} frames) in {secs:.2} s: \
                    the morph took {:.2}x that",
                morph_secs / secs.max(1e-9)
            );
            if let Ok(ours) = copy_sequence(plates, &copy, frames) {
                eprintln!(
                    "morphfx's own EXR IO copies it in {ours:.2} s: {:.2}x oiiotool",
                    ours / secs.max(1e-9)
                );
            }
        }
        _ => eprintln!("(oiiotool not found: install openimageio-tools to compare with it)"),
    }
    let _ = std::fs::remove_dir_all(&copy);
}

/// Seconds to read and write sequence A frame by frame with our EXR IO, in
/// the plates' own format: the IO alone, as oiiotool's copy measures it.
pub fn copy_sequence(plates: &Path, to: &Path, frames: usize) -> Result<f64, HostError> {
    let started = Instant::now();
    for f in 1..=frames as i64 {
        let from = frame_path(&plates.join("a.####.exr").to_string_lossy(), f);
        let header = io::probe(&from)?;
        let precision = if header.half {
            ExrPrecision::Half
        } else {
            ExrPrecision::Float
        };
        let format = io::OutputFormat {
            compression: header
                .compression
                .unwrap_or(exr::prelude::Compression::ZIP16),
            ..io::OutputFormat::new(precision)
        };
        let plate = io::read(&from)?;
        io::write_as(
            &frame_path(&to.join("a.####.exr").to_string_lossy(), f),
            &plate,
            format,
        )?;
    }
    Ok(started.elapsed().as_secs_f64())
}
