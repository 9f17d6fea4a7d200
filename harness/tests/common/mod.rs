//! Shared by the harness's integration tests: where the built bundle is, and
//! a scratch folder per test.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The bundle `cargo xtask test` built (MORPHFX_BUNDLE), else the checkout's.
pub fn bundle_path() -> PathBuf {
    std::env::var("MORPHFX_BUNDLE")
        .map(PathBuf::from)
        .unwrap_or_else(|_| {
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/bundle/MorphFX.ofx.bundle")
        })
}

/// An empty folder for one test of this process.
#[allow(dead_code)] // not every test file needs one
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("morphfx-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `morphfx --bundle <the built bundle> ARGS...`, run to completion.
#[allow(dead_code)] // not every test file runs the binary
pub fn run_morphfx(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_morphfx"))
        .arg("--bundle")
        .arg(bundle_path())
        .args(args)
        .output()
        .expect("morphfx runs")
}

/// An opaque `w × h` float EXR at `path` whose pixel centres take `colour`
/// (canonical position in, RGB out); returns the image written.
#[allow(dead_code)] // not every test file writes generated plates
pub fn colour_plate(
    path: &Path,
    w: usize,
    h: usize,
    colour: impl Fn(morphfx::geom::Vec2) -> [f32; 3],
) -> morphfx::image::Image {
    use morphfx_harness::io::{self, ExrPrecision, Plate};
    let image =
        morphfx::image::Image::from_fn(morphfx::geom::RectI::from_size(w, h), 4, |i, j, c| {
            if c == 3 {
                1.0
            } else {
                colour(morphfx::geom::Vec2::new(i as f64 + 0.5, j as f64 + 0.5))[c]
            }
        });
    let plate = Plate::new(image.clone(), (w, h));
    io::write(path, &plate, ExrPrecision::Float).unwrap();
    image
}

/// The built bundle, loaded once per test binary.
#[allow(dead_code)] // not every test file loads it in-process
pub fn bundle() -> &'static morphfx_harness::host::Bundle {
    static B: std::sync::OnceLock<morphfx_harness::host::Bundle> = std::sync::OnceLock::new();
    B.get_or_init(|| {
        morphfx_harness::host::Bundle::load(&bundle_path())
            .expect("the bundle loads (build it with `cargo xtask bundle`)")
    })
}

/// A clip source that shows one frame at every time.
#[allow(dead_code)] // not every test file connects clips
pub struct Still(pub std::sync::Arc<morphfx_harness::host::Frame>);

impl morphfx_harness::host::FrameSource for Still {
    fn frame(&self, _time: f64) -> Result<std::sync::Arc<morphfx_harness::host::Frame>, String> {
        Ok(self.0.clone())
    }
}
