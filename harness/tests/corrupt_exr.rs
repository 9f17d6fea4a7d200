//! Every plate of the corrupt EXR corpus (`tests/data/corrupt-exr`, whose
//! README says what damage each carries) is answered as a user needs it:
//! exit status 2 and a message naming the file and what is wrong with it,
//! nothing written, in bounded time and memory; never a crash, an abort or
//! an internal error.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;

use morphfx_harness::io;

/// (file, what the message must say); every one exits 2.
const REFUSED: [(&str, &str); 24] = [
    ("empty.exr", "truncated"),
    ("magic-only.exr", "truncated"),
    ("bad-magic.exr", "corrupt: file identifier missing"),
    (
        "version-9.exr",
        "file versions other than 2.0 are not supported",
    ),
    ("header-cut.exr", "truncated"),
    ("attribute-size-huge.exr", "truncated"),
    ("attribute-size-negative.exr", "corrupt: attribute size"),
    (
        "compression-unknown.exr",
        "corrupt: missing or invalid compression",
    ),
    (
        "data-window-huge.exr",
        "corrupt: missing or invalid data window",
    ),
    (
        "data-window-32k.exr",
        "32768x32768 pixels, over morphfx's limit",
    ),
    (
        "display-window-huge.exr",
        "corrupt: missing or invalid display window",
    ),
    (
        "no-channels.exr",
        "corrupt: at least one channel is required",
    ),
    ("tile-size-zero.exr", "corrupt: tile size"),
    ("tile-size-huge.exr", "corrupt: tile size"),
    ("offset-past-end.exr", "truncated"),
    (
        "offset-max.exr",
        "corrupt: an offset in it points outside it",
    ),
    ("offset-into-header.exr", "corrupt"),
    ("offsets-all-zero.exr", "corrupt"),
    ("offset-table-cut.exr", "truncated"),
    ("chunk-size-huge.exr", "corrupt"),
    ("chunk-size-negative.exr", "corrupt"),
    ("chunk-y-outside.exr", "corrupt: block position 1000"),
    ("zip-stream-garbage.exr", "corrupt: compressed ZIP16 data"),
    ("pixels-cut.exr", "truncated"),
];

/// Damaged, yet every pixel is still where the file says: read as the
/// good plate reads. (OpenEXR refuses an inverted data window; the exr
/// crate we read with orders its corners, and the pixels come out right.)
const READ: [(&str, &str); 1] = [("data-window-inverted.exr", "good-zip.exr")];

const SCENE: &str = r#"{"format": "morphfx-scene", "version": 1, "method": "field",
  "field": {"a": 0.001, "b": 2, "p": 0.5, "evaluation": "exact"},
  "features": [{"name": "bar", "type": "line", "a": [[2, 2], [12, 2]], "b": [[3, 1], [13, 1]]}]}"#;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/corrupt-exr")
}

/// `morphfx warp` of `plate` into `out` under 4 GiB of address space and a
/// 30 s deadline: its exit status and stderr.
fn warp(dir: &Path, plate: &Path, out: &Path) -> (i32, String) {
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(r#"ulimit -v 4194304; exec "$0" "$@""#)
        .arg(env!("CARGO_BIN_EXE_morphfx"))
        .arg("--bundle")
        .arg(common::bundle_path())
        .args(["warp", "--scene"])
        .arg(dir.join("s.morph.json"))
        .arg("--input")
        .arg(plate)
        .arg("-o")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("morphfx starts");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            panic!("{}: no answer in 30 s", plate.display());
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    (status.code().unwrap_or(-1), err)
}

#[test]
fn every_corrupt_plate_is_refused_naming_the_file_and_the_damage() {
    let d = common::scratch("corrupt-exr");
    std::fs::write(d.join("s.morph.json"), SCENE).unwrap();
    for (name, says) in REFUSED {
        let out = d.join(format!("out-{name}"));
        let (code, err) = warp(&d, &corpus().join(name), &out);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(err.contains(name) && err.contains(says), "{name}: {err}");
        assert!(
            !err.contains("internal error") && !err.contains("panicked"),
            "{name}: {err}"
        );
        assert!(!out.exists(), "{name}: an output was written");
    }
    let left: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name())
        .filter(|n| n != "s.morph.json")
        .collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
}

#[test]
fn the_corpus_covers_every_damaged_file_and_its_good_plates_read() {
    let d = common::scratch("corrupt-exr-good");
    std::fs::write(d.join("s.morph.json"), SCENE).unwrap();
    let mut listed: Vec<&str> = REFUSED.iter().chain(&READ).map(|(n, _)| *n).collect();
    listed.extend(["good-zip.exr", "good-none.exr", "good-tiled.exr"]);
    for entry in std::fs::read_dir(corpus()).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        if name.ends_with(".exr") {
            assert!(listed.contains(&name.as_str()), "{name} has no expectation");
        }
    }
    let render = |name: &str| {
        let out = d.join(format!("out-{name}"));
        let (code, err) = warp(&d, &corpus().join(name), &out);
        assert_eq!(code, 0, "{name}: {err}");
        io::read(&out).unwrap().image
    };
    let good = render("good-zip.exr");
    // The three encodings of one plate give one picture.
    for other in ["good-none.exr", "good-tiled.exr"] {
        assert_eq!(render(other).data, good.data, "{other}");
    }
    for (name, like) in READ {
        assert_eq!(render(name).data, render(like).data, "{name}");
    }
}
