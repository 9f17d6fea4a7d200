//! Every plate of the corrupt EXR corpus (`tests/data/corrupt-exr`, whose
//! README says what damage each carries) is answered as a user needs it:
//! exit status 2 and a message naming the file and what is wrong with it,
//! nothing written, in bounded time and memory; never a crash, an abort or
//! an internal error.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common;

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

/// `morphfx ARGS` under 4 GiB of address space and a 30 s deadline: its
/// exit status and stderr.
fn morphfx(args: &[&OsStr]) -> (i32, String) {
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(r#"ulimit -v 4194304; exec "$0" "$@""#)
        .arg(env!("CARGO_BIN_EXE_morphfx"))
        .arg("--bundle")
        .arg(common::bundle_path())
        .args(args)
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
            panic!("{args:?}: no answer in 30 s");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    (status.code().unwrap_or(-1), err)
}

/// `morphfx warp` of `plate` into `out`.
fn warp(dir: &Path, plate: &Path, out: &Path) -> (i32, String) {
    let scene = dir.join("s.morph.json");
    morphfx(&[
        "warp".as_ref(),
        "--scene".as_ref(),
        scene.as_ref(),
        "--input".as_ref(),
        plate.as_ref(),
        "-o".as_ref(),
        out.as_ref(),
    ])
}

/// Every place a plate enters `morphfx`: a command, and the option the
/// damaged plate is given to (the others get a good plate). `{bad}` is the
/// damaged plate, `{good}` a good one, `{out}` the output, `{seq}` a
/// two-frame sequence whose second frame is the damaged plate.
const ROLES: [&str; 15] = [
    "warp --scene {scene} --input {bad} -o {out}.exr",
    "warp --scene {scene} --input {good} --mask {bad} -o {out}.exr",
    "morph --scene {scene} --a {bad} --b {good} --t 0.5 -o {out}.exr",
    "morph --scene {scene} --a {good} --b {bad} --t 0.5 -o {out}.exr",
    "morph --scene {scene} --a {good} --b {good} --mask {bad} --t 0.5 -o {out}.exr",
    "morph --scene {scene} --a {good} --b {good} --timing {bad} --t 0.5 -o {out}.exr",
    "morph --scene {scene} --a {good} --b {seq} --frames 1-2 --t 0.5 -o {out}.####.exr",
    "morph --scene {scene} --a {good} --b {good} --timing {seq} --frames 1-2 -o {out}.####.exr",
    "overlay --scene {scene} --a {bad} --b {good} -o {out}.png",
    "overlay --scene {scene} --a {good} --b {bad} -o {out}.png",
    "snap --scene {scene} --a {good} --b {bad} -o {out}.json",
    "track --scene {keyed} --a {seq} --frames 1-2 -o {out}.json",
    "track --scene {keyed} --a {goodseq} --b {seq} --frames 1-2 -o {out}.json",
    "suggest --a {bad} --b {good} -o {out}.json",
    "suggest --a {good} --b {bad} -o {out}.json",
];

const KEYED: &str = r#"{"format": "morphfx-scene", "version": 1,
  "keyframes": [{"frame": 1, "features": [{"type": "point", "a": [[8, 4]], "b": [[8, 4]]}]}]}"#;

/// Runs `role` with `bad` in the damaged plate's place, in folder `dir`
/// (which holds the scenes): exit status, stderr, and the files it left
/// beside the inputs.
fn run_role(dir: &Path, role: &str, bad: &Path) -> (i32, String, Vec<String>) {
    let stem = bad.file_stem().unwrap().to_string_lossy().into_owned();
    let good = corpus().join("good-zip.exr");
    let seq = dir.join(format!("{stem}.####.exr"));
    std::fs::copy(&good, dir.join(format!("{stem}.0001.exr"))).unwrap();
    std::fs::copy(bad, dir.join(format!("{stem}.0002.exr"))).unwrap();
    let good_seq = dir.join("good.####.exr");
    for f in 1..=2 {
        std::fs::copy(&good, dir.join(format!("good.000{f}.exr"))).unwrap();
    }
    let before = listing(dir);
    let out = dir.join(format!("out-{stem}"));
    let args: Vec<std::ffi::OsString> = role
        .split(' ')
        .map(|w| match w {
            "{scene}" => dir.join("s.morph.json").into_os_string(),
            "{keyed}" => dir.join("keyed.morph.json").into_os_string(),
            "{bad}" => bad.as_os_str().to_owned(),
            "{good}" => good.as_os_str().to_owned(),
            "{goodseq}" => good_seq.as_os_str().to_owned(),
            "{seq}" => seq.as_os_str().to_owned(),
            w if w.starts_with("{out}") => format!("{}{}", out.display(), &w[5..]).into(),
            w => w.into(),
        })
        .collect();
    let args: Vec<&OsStr> = args.iter().map(|a| a.as_os_str()).collect();
    let (code, err) = morphfx(&args);
    let left = listing(dir)
        .into_iter()
        .filter(|n| !before.contains(n))
        .collect();
    (code, err, left)
}

fn listing(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect()
}

#[test]
fn every_corrupt_plate_is_refused_in_every_role_naming_the_file() {
    let d = common::scratch("corrupt-exr");
    std::fs::write(d.join("s.morph.json"), SCENE).unwrap();
    std::fs::write(d.join("keyed.morph.json"), KEYED).unwrap();
    for role in ROLES {
        for (name, says) in REFUSED {
            let (code, err, left) = run_role(&d, role, &corpus().join(name));
            let stem = name.trim_end_matches(".exr");
            let context = format!("`{role}` with {name}: {err}");
            assert_eq!(code, 2, "{context}");
            assert!(err.contains(stem) && err.contains(says), "{context}");
            assert!(
                !err.contains("internal error") && !err.contains("panicked"),
                "{context}"
            );
            // Frame 1 of a sequence is good and may be written whole; the
            // damaged frame never is, nor any partial file.
            let written: Vec<_> = left
                .iter()
                .filter(|n| !(n.starts_with("out-") && n.contains(".0001.")))
                .collect();
            assert!(written.is_empty(), "{context}: left {written:?}");
        }
    }
}

/// Damaged PNG, JPEG and TIFF plates, made here from a good one, are
/// refused as the EXRs are, whichever input they are given to.
#[test]
fn damaged_png_jpeg_and_tiff_plates_are_refused_in_every_role() {
    let d = common::scratch("corrupt-other");
    std::fs::write(d.join("s.morph.json"), SCENE).unwrap();
    std::fs::write(d.join("keyed.morph.json"), KEYED).unwrap();
    let good = io::read(&corpus().join("good-zip.exr")).unwrap();
    for ext in ["png", "jpg", "tif"] {
        let whole = d.join(format!("whole.{ext}"));
        io::write(&whole, &good, io::ExrPrecision::Half).unwrap();
        let bytes = std::fs::read(&whole).unwrap();
        std::fs::remove_file(&whole).unwrap();
        let name = format!("cut-{ext}.{ext}");
        let bad = d.join(&name);
        std::fs::write(&bad, &bytes[..bytes.len() * 2 / 3]).unwrap();
        for role in ROLES.iter().filter(|r| !r.contains("{seq}")) {
            let (code, err, left) = run_role(&d, role, &bad);
            let context = format!("`{role}` with {name}: {err}");
            assert_eq!(code, 2, "{context}");
            assert!(err.contains(&name), "{context}");
            assert!(
                left.iter().all(|n| !n.starts_with("out-")),
                "{context}: {left:?}"
            );
        }
    }
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

/// A real plate cut short, as a copy that stopped leaves it, in the middle
/// of a sequence: refused from its header before the first frame is
/// rendered, so nothing at all is written.
#[test]
fn a_cut_plate_in_a_sequence_is_refused_before_any_frame_is_written() {
    let d = common::scratch("corrupt-cut-sequence");
    std::fs::write(d.join("s.morph.json"), SCENE).unwrap();
    let plate = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/forest.exr");
    let bytes = std::fs::read(&plate).unwrap();
    for f in 1..=3 {
        std::fs::write(d.join(format!("a.000{f}.exr")), &bytes).unwrap();
    }
    std::fs::write(d.join("a.0003.exr"), &bytes[..bytes.len() / 2]).unwrap();
    let scene = d.join("s.morph.json");
    let (a, out) = (d.join("a.####.exr"), d.join("out.####.exr"));
    let (code, err) = morphfx(&[
        "morph".as_ref(),
        "--scene".as_ref(),
        scene.as_ref(),
        "--a".as_ref(),
        a.as_ref(),
        "--b".as_ref(),
        plate.as_ref(),
        "--frames".as_ref(),
        "1-3".as_ref(),
        "--t".as_ref(),
        "0.5".as_ref(),
        "-o".as_ref(),
        out.as_ref(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("a.0003.exr") && err.contains("truncated"),
        "{err}"
    );
    let written: Vec<_> = listing(&d)
        .into_iter()
        .filter(|n| n.starts_with("out") || n.contains("partial"))
        .collect();
    assert!(written.is_empty(), "written: {written:?}");
}
