//! A 1,000-frame render holds memory and open files flat: run under a limit
//! of 64 open files, its peak resident size within a few MB of a 100-frame
//! run's.

use crate::common;

use std::process::Command;

use morphfx::geom::RectI;
use morphfx::image::Image;
use morphfx_harness::io::{self, ExrPrecision, Plate};

/// The peak memory a run reported ("...; peak memory N MiB").
fn peak_mib(stderr: &str) -> u64 {
    let at = stderr
        .rfind("peak memory ")
        .expect("the run reports its peak memory");
    stderr[at + 12..]
        .split_whitespace()
        .next()
        .and_then(|n| n.parse().ok())
        .expect("a number of MiB")
}

#[test]
fn a_thousand_frames_keep_memory_and_open_files_flat() {
    let d = common::scratch("long-run");
    let img = Image::from_fn(RectI::from_size(32, 24), 4, |i, j, c| {
        ((i * 3 + j * 5 + c as i32) % 7) as f32 / 7.0
    });
    io::write(
        &d.join("a.exr"),
        &Plate::new(img, (32, 24)),
        ExrPrecision::Half,
    )
    .unwrap();
    for f in 1..=1000 {
        std::os::unix::fs::symlink(d.join("a.exr"), d.join(format!("a.{f:04}.exr"))).unwrap();
    }
    std::fs::write(
        d.join("s.morph.json"),
        r#"{"format": "morphfx-scene", "version": 1,
            "keyframes": [
              {"frame": 1, "features": [{"type": "line", "a": [[5, 5], [20, 8]], "b": [[6, 6], [22, 9]]}]},
              {"frame": 1000, "features": [{"type": "line", "a": [[8, 5], [25, 8]], "b": [[9, 7], [24, 12]]}]}],
            "progress": [[1, 0], [1000, 1]]}"#,
    )
    .unwrap();
    let run = |frames: &str| {
        let script = format!(
            "ulimit -n 64 && exec \"$0\" --bundle \"$1\" morph --scene s.morph.json \
             --a a.####.exr --b a.####.exr --frames {frames} -o out.####.exr"
        );
        let out = Command::new("sh")
            .current_dir(&d)
            .arg("-c")
            .arg(script)
            .arg(env!("CARGO_BIN_EXE_morphfx"))
            .arg(common::bundle_path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{frames}: {stderr}");
        peak_mib(&stderr)
    };
    let short = run("1-100");
    let long = run("1-1000");
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1002 + 1000);
    assert!(
        long <= short + 8,
        "peak memory grew from {short} MiB (100 frames) to {long} MiB (1000 frames)"
    );
}
