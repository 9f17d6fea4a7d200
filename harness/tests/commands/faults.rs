//! Interruption and disk faults: Ctrl-C or SIGTERM, a full disk and an
//! unwritable folder never leave a partial or corrupt frame under a final
//! name; the run names the file it could not write and exits 2 (an
//! interrupted one also says which frames are whole).

use crate::common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::io::{self, ExrPrecision, Plate};

const SCENE: &str = r#"{"format": "morphfx-scene", "version": 1,
  "features": [{"type": "line", "a": [[5, 5], [40, 8]], "b": [[6, 6], [42, 9]]}]}"#;

/// A `w × h` half plate at `path`: flat grey, or noise (which no
/// compression shrinks much).
fn plate(path: &Path, (w, h): (usize, usize), noisy: bool) {
    let img = Image::from_fn(RectI::from_size(w, h), 4, |i, j, c| {
        if !noisy {
            return 0.5;
        }
        // A hash of the sample's place: noise, the same on every run.
        let mut x = (i as u64) << 32 ^ (j as u64) << 8 ^ c as u64 ^ 0x2545_f491_4f6c_dd1d;
        for _ in 0..3 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
        }
        (x >> 40) as f32 / (1u64 << 24) as f32
    });
    io::write(path, &Plate::new(img, (w, h)), ExrPrecision::Half).unwrap();
}

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    n.sort();
    n
}

/// `morphfx ARGS` in `dir` through `sh -c SETUP; exec ...`.
fn morphfx_in(dir: &Path, setup: &str, args: &[&str]) -> Command {
    let mut c = Command::new("sh");
    c.current_dir(dir)
        .arg("-c")
        .arg(format!("{setup}; exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_morphfx"))
        .arg("--bundle")
        .arg(common::bundle_path())
        .args(args);
    c
}

/// `morphfx morph` of sequence `a.####.exr` with itself over `frames`
/// into `out/m.####.exr`, in `dir`, after `setup`.
fn morph_into_out(dir: &Path, setup: &str, frames: &str) -> Command {
    morphfx_in(
        dir,
        setup,
        &[
            "morph",
            "--scene",
            "s.morph.json",
            "--a",
            "a.####.exr",
            "--b",
            "a.####.exr",
            "--frames",
            frames,
            "-o",
            "out/m.####.exr",
        ],
    )
}

#[test]
fn a_full_disk_stops_at_the_frame_it_cannot_hold_and_names_it() {
    let d = common::scratch("full-disk");
    std::fs::write(d.join("s.morph.json"), SCENE).unwrap();
    // Frames 1 and 2 compress to a few hundred bytes, 3 and 4 cannot.
    for f in 1..=4 {
        plate(&d.join(format!("a.{f:04}.exr")), (128, 96), f >= 3);
    }
    std::fs::create_dir(d.join("out")).unwrap();
    // Files beyond 64 blocks of 512 bytes cannot be written: the process
    // sees the error a full disk gives, mid-file (SIGXFSZ ignored, so the
    // write fails instead of the process dying).
    let out = morph_into_out(&d, "trap '' XFSZ; ulimit -f 64", "1-4")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("out/m.0003.exr: not written") && err.contains("File too large"),
        "{err}"
    );
    assert_eq!(names(&d.join("out")), ["m.0001.exr", "m.0002.exr"]);
    for f in 1..=2 {
        let frame = io::read(&d.join(format!("out/m.{f:04}.exr"))).unwrap();
        assert_eq!(frame.image.bounds, RectI::from_size(128, 96));
    }
}

#[test]
fn an_unwritable_folder_is_named_and_nothing_is_written() {
    let d = common::scratch("unwritable");
    std::fs::write(d.join("s.morph.json"), SCENE).unwrap();
    plate(&d.join("a.exr"), (64, 48), false);
    std::fs::write(d.join("file"), b"a file, not a folder").unwrap();
    // A folder in the way of a file, and sysfs, which nobody (root
    // included) may make files in.
    for (output, says) in [
        ("file/o.exr", "file: cannot create folder"),
        ("/sys/morphfx-o.exr", "/sys/morphfx-o.exr: not written"),
    ] {
        let out = morphfx_in(
            &d,
            "true",
            &[
                "warp",
                "--scene",
                "s.morph.json",
                "--input",
                "a.exr",
                "-o",
                output,
            ],
        )
        .output()
        .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{output}: {err}");
        assert!(err.contains(says), "{output}: {err}");
        assert!(!Path::new(output).exists() && !d.join(output).exists());
    }
    assert_eq!(names(&d), ["a.exr", "file", "s.morph.json"]);
}

#[test]
fn an_interrupted_run_leaves_only_whole_frames_and_says_which() {
    for signal in ["INT", "TERM"] {
        let d = common::scratch(&format!("interrupt-{signal}"));
        std::fs::write(d.join("s.morph.json"), SCENE).unwrap();
        plate(&d.join("a.exr"), (160, 120), true);
        for f in 1..=1000 {
            std::os::unix::fs::symlink(d.join("a.exr"), d.join(format!("a.{f:04}.exr"))).unwrap();
        }
        std::fs::create_dir(d.join("out")).unwrap();
        let mut child = morph_into_out(&d, "true", "1-1000")
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Interrupt it once a few frames are down, mid-shot.
        let start = Instant::now();
        while !d.join("out/m.0003.exr").exists() {
            assert!(start.elapsed() < Duration::from_secs(120), "no frames");
            std::thread::sleep(Duration::from_millis(2));
        }
        let kill = Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(kill.success());
        let status = child.wait().unwrap();
        let mut err = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
        assert_eq!(status.code(), Some(2), "{signal}: {err}");
        // "morphfx: error: out/m.{N+1}.exr: not written: interrupted; N frame(s) written whole, 1 to N, none after"
        let n: usize = err
            .split("interrupted; ")
            .nth(1)
            .and_then(|s| s.split_whitespace().next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("{signal}: no count of frames written: {err}"));
        assert!((3..1000).contains(&n), "{signal}: {n} frames: {err}");
        assert!(
            err.contains(&format!("out/m.{:04}.exr: not written", n + 1))
                && err.contains(&format!("1 to {n}, none after")),
            "{signal}: {err}"
        );
        let expected: Vec<String> = (1..=n).map(|f| format!("m.{f:04}.exr")).collect();
        assert_eq!(names(&d.join("out")), expected, "{signal}");
        for name in &expected {
            let frame = io::read(&d.join("out").join(name)).unwrap();
            assert_eq!(frame.image.bounds, RectI::from_size(160, 120), "{name}");
        }
    }
}
