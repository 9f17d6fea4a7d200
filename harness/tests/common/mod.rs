//! Shared by the harness's integration tests: where the built bundle is, and
//! a scratch folder per test.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The bundle `cargo xtask test` built (MORPHFX_BUNDLE), else the
/// checkout's. Refused, in one line that says what to run, when it is
/// missing or older than the plugin's sources: tests of a stale bundle
/// would pass or fail for code that is no longer there.
pub fn bundle_path() -> PathBuf {
    static CHECKED: std::sync::OnceLock<Result<PathBuf, String>> = std::sync::OnceLock::new();
    CHECKED
        .get_or_init(|| {
            let path = std::env::var("MORPHFX_BUNDLE")
                .map(PathBuf::from)
                .unwrap_or_else(|_| {
                    Path::new(env!("CARGO_MANIFEST_DIR"))
                        .join("../target/bundle/MorphFX.ofx.bundle")
                });
            check_bundle(&path).map(|()| path)
        })
        .clone()
        .unwrap_or_else(|why| panic!("{why}: run `cargo xtask test`, which builds it first"))
}

/// The bundle's binary exists and is newer than every source it is built from.
fn check_bundle(bundle: &Path) -> Result<(), String> {
    let arch = if cfg!(target_arch = "aarch64") {
        "Linux-arm-64"
    } else {
        "Linux-x86-64"
    };
    let binary = bundle.join("Contents").join(arch).join("MorphFX.ofx");
    let built = std::fs::metadata(&binary)
        .and_then(|m| m.modified())
        .map_err(|_| format!("no plugin bundle at {}", bundle.display()))?;
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut newest: Option<(std::time::SystemTime, PathBuf)> = None;
    for dir in ["src", "ofx/src"] {
        newest_in(&root.join(dir), &mut newest);
    }
    for file in ["Cargo.toml", "ofx/Cargo.toml", "Cargo.lock"] {
        newest_in(&root.join(file), &mut newest);
    }
    match newest {
        Some((changed, source)) if changed > built => Err(format!(
            "the plugin bundle at {} is older than {}",
            bundle.display(),
            source.display()
        )),
        _ => Ok(()),
    }
}

fn newest_in(path: &Path, newest: &mut Option<(std::time::SystemTime, PathBuf)>) {
    if path.is_dir() {
        for entry in std::fs::read_dir(path).into_iter().flatten().flatten() {
            newest_in(&entry.path(), newest);
        }
    } else if let Ok(t) = std::fs::metadata(path).and_then(|m| m.modified()) {
        if newest.as_ref().is_none_or(|(n, _)| t > *n) {
            *newest = Some((t, path.to_owned()));
        }
    }
}

/// An empty folder for one test of this process, removed when the test
/// passes. A failing test leaves it, and says where, for a look at what it
/// wrote; passing runs leave nothing, so a suite run many times over (as CI
/// and developers do) does not fill the disk with plates.
#[allow(dead_code)] // not every test file needs one
pub fn scratch(name: &str) -> Scratch {
    let d = std::env::temp_dir().join(format!("morphfx-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    Scratch(d)
}

/// The folder [`scratch`] made; a path wherever one is asked for.
pub struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept for a look: {}", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<std::ffi::OsStr> for Scratch {
    fn as_ref(&self) -> &std::ffi::OsStr {
        self.0.as_os_str()
    }
}

/// Whether a test may skip for want of `tool`: not when `cargo xtask test`
/// found or installed it (`MORPHFX_REQUIRE_TOOLS`), where its absence from
/// the test's view is a failure, not a skip.
#[allow(dead_code)] // only tests that use an outside tool ask
pub fn may_skip_without(tool: &str) -> bool {
    let required = std::env::var("MORPHFX_REQUIRE_TOOLS").unwrap_or_default();
    !required.split(',').any(|t| t == tool)
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

/// `morphfx ARGS...` as [`run_morphfx`]: its exit status and what it said
/// on standard error.
#[allow(dead_code)] // not every test file runs the binary
pub fn morphfx_said(args: &[&str]) -> (i32, String) {
    let out = run_morphfx(args);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `morphfx ARGS...`, which must succeed.
#[allow(dead_code)] // not every test file runs the binary
pub fn morphfx_ok(args: &[&str]) {
    let (code, err) = morphfx_said(args);
    assert_eq!(code, 0, "morphfx {args:?}: {err}");
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

/// Connects to each `(clip, seed)` of `clips` a still `w × h` float RGBA
/// plate of sine texture (opaque, different for each seed).
#[allow(dead_code)] // not every test file connects clips
pub fn connect_textured(
    inst: &morphfx_harness::host::Instance<'_>,
    clips: &[(&str, f32)],
    (w, h): (usize, usize),
) {
    for &(clip, seed) in clips {
        let img =
            morphfx::image::Image::from_fn(morphfx::geom::RectI::from_size(w, h), 4, |i, j, c| {
                if c == 3 {
                    1.0
                } else {
                    0.5 + 0.4 * (i as f32 * 0.41 + j as f32 * 0.27 + seed + c as f32).sin()
                }
            });
        let f = morphfx_harness::host::Frame::from_image(&img, "OfxBitDepthFloat", false);
        inst.connect(clip, std::sync::Arc::new(Still(std::sync::Arc::new(f))))
            .unwrap();
    }
}

/// A line pair: A's two ends, then B's.
#[allow(dead_code)] // not every test file sets line slots
pub type LinePair = ([[f64; 2]; 2], [[f64; 2]; 2]);

/// Sets the node's line slots to `lines`.
#[allow(dead_code)] // not every test file sets line slots
pub fn set_line_slots(inst: &morphfx_harness::host::Instance<'_>, lines: &[LinePair]) {
    inst.set_int("line_count", lines.len() as i32).unwrap();
    for (k, (a, b)) in lines.iter().enumerate() {
        for (end, xy) in [
            ("a_start", a[0]),
            ("a_end", a[1]),
            ("b_start", b[0]),
            ("b_end", b[1]),
        ] {
            inst.set_double(&format!("line{}_{end}", k + 1), &xy, None)
                .unwrap();
        }
    }
}

/// A shot's pyramids held in memory, as the tracker asks for them.
#[allow(dead_code)] // the tracking tests only
pub struct InMemory(pub Vec<std::sync::Arc<morphfx::track::Pyramid>>);

impl morphfx::track::Frames<morphfx::Error> for InMemory {
    fn pyramid(&mut self, frame: i64) -> morphfx::Result<std::sync::Arc<morphfx::track::Pyramid>> {
        Ok(self.0[frame as usize].clone())
    }
}

/// Every frame's grey pyramid, as the tracker builds them.
#[allow(dead_code)] // the tracking tests only
pub fn pyramids(
    frames: &[morphfx::image::Image],
    settings: &morphfx::track::TrackSettings,
) -> InMemory {
    use morphfx::track::{Grey, Pyramid};
    InMemory(
        frames
            .iter()
            .map(|f| {
                std::sync::Arc::new(Pyramid::new(
                    Grey::from_view(&f.view()),
                    settings.levels,
                    16,
                ))
            })
            .collect(),
    )
}

/// The `p` quantile of `sorted`, the nearest rank.
#[allow(dead_code)] // the tracking tests only
pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

/// The bundle loaded once per test binary in a host with overlays and the
/// Draw suite.
#[allow(dead_code)] // the overlay tests only
pub fn overlay_bundle() -> &'static morphfx_harness::host::Bundle {
    use morphfx_harness::host::{Bundle, HostOptions};
    static B: std::sync::OnceLock<Bundle> = std::sync::OnceLock::new();
    B.get_or_init(|| {
        let options = HostOptions {
            overlays: true,
            draw_suite: true,
            multi_plane: false,
        };
        Bundle::load_with(&bundle_path(), options).expect("the bundle loads")
    })
}

/// `inst`'s overlay, drawn through the Draw suite.
#[allow(dead_code)] // the overlay tests only
pub fn overlay<'i>(
    inst: &'i morphfx_harness::host::Instance<'i>,
) -> morphfx_harness::host::overlay::Overlay<'i> {
    morphfx_harness::host::overlay::Overlay::new(inst, true)
        .unwrap()
        .expect("the node declares an overlay")
}

/// The labels an overlay drew, in order.
#[allow(dead_code)] // the overlay tests only
pub fn texts(calls: &[morphfx_harness::host::overlay::DrawCall]) -> Vec<String> {
    use morphfx_harness::host::overlay::DrawCall;
    calls
        .iter()
        .filter_map(|c| match c {
            DrawCall::Text { text, .. } => Some(text.clone()),
            _ => None,
        })
        .collect()
}
