//! File sequences written with `#` padding (`plate.####.exr`) and frame ranges.

use std::path::PathBuf;

use crate::error::HostError;

/// `plate.####.exr` at frame 1001 → `plate.1001.exr`; a name without `#` is itself.
pub fn frame_path(pattern: &str, frame: i64) -> PathBuf {
    let Some(start) = pattern.find('#') else {
        return PathBuf::from(pattern);
    };
    let len = pattern[start..].chars().take_while(|&c| c == '#').count();
    let number = if frame < 0 {
        format!("-{:0len$}", -frame, len = len)
    } else {
        format!("{frame:0len$}")
    };
    PathBuf::from(format!(
        "{}{number}{}",
        &pattern[..start],
        &pattern[start + len..]
    ))
}

/// `--frames` in Open Job Description's range form: `x` steps become `:`
/// (OpenJD takes `1001-1011:5`, not OpenCue's and Nuke's `1001-1011x5`).
pub fn openjd_frames(spec: &str) -> String {
    spec.replace('x', ":")
}

pub fn is_sequence(pattern: &str) -> bool {
    pattern.contains('#')
}

/// The most frames one `--frames` may name: far beyond any shot, and a
/// list no machine struggles to hold.
const MAX_FRAMES: usize = 1_000_000;

/// `--frames` as farms and users write it: `1001-1048`, `1001`, stepped
/// ranges `1001-1011x5` (OpenCue, Nuke) and `1001-1011:5` (Open Job
/// Description), and lists of any of these, `1001,1005-1010`. A stepped
/// range starts at its first frame and keeps every step-th up to its last.
pub fn parse_frames(spec: &str) -> Result<Vec<i64>, HostError> {
    let bad = |why: &str| {
        HostError::bad(format!(
            "--frames {spec}: {why} (expected a frame, FIRST-LAST, FIRST-LASTxSTEP or \
             FIRST-LAST:STEP, or a list of them like 1001,1005-1010)"
        ))
    };
    let mut frames = Vec::new();
    for part in spec.split(',').map(str::trim) {
        if part.is_empty() {
            return Err(bad("an empty item"));
        }
        let (range, step) = match part.split_once(['x', ':']) {
            Some((range, step)) => {
                let step: i64 = step.trim().parse().map_err(|_| bad("bad step"))?;
                if step < 1 {
                    return Err(bad("the step must be 1 or more"));
                }
                (range, Some(step))
            }
            None => (part, None),
        };
        // A leading '-' is a negative first frame, not the range's dash.
        let (a, b) = match range[1..].find('-') {
            Some(k) => (&range[..k + 1], &range[k + 2..]),
            None if step.is_some() => return Err(bad("a step needs a range")),
            None => (range, range),
        };
        let a: i64 = a.trim().parse().map_err(|_| bad("bad frame number"))?;
        let b: i64 = b.trim().parse().map_err(|_| bad("bad frame number"))?;
        if b < a {
            return Err(bad("the last frame comes before the first"));
        }
        let step = step.unwrap_or(1);
        let count = (b as i128 - a as i128) / step as i128 + 1;
        if count + frames.len() as i128 > MAX_FRAMES as i128 {
            return Err(bad(&format!("more than {MAX_FRAMES} frames")));
        }
        frames.extend((0..count as i64).map(|k| a + k * step));
    }
    // A frame named twice would be rendered and written twice, and a
    // farm's chunks holding it would race on its file.
    let mut seen = std::collections::HashSet::with_capacity(frames.len());
    if let Some(f) = frames.iter().find(|f| !seen.insert(**f)) {
        return Err(bad(&format!("frame {f} is named twice")));
    }
    Ok(frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pads_frames_with_hashes() {
        assert_eq!(
            frame_path("a/plate.####.exr", 1001),
            PathBuf::from("a/plate.1001.exr")
        );
        assert_eq!(frame_path("p.##.exr", 7), PathBuf::from("p.07.exr"));
        assert_eq!(frame_path("p.exr", 7), PathBuf::from("p.exr"));
    }

    #[test]
    fn parses_ranges_and_lists() {
        assert_eq!(parse_frames("1001-1003").unwrap(), vec![1001, 1002, 1003]);
        assert_eq!(parse_frames("5").unwrap(), vec![5]);
        assert_eq!(parse_frames("1,4-5").unwrap(), vec![1, 4, 5]);
        assert!(parse_frames("9-3").is_err());
        assert!(parse_frames("x").is_err());
    }

    #[test]
    fn parses_stepped_ranges_as_farms_write_them() {
        // OpenCue and Nuke write x, Open Job Description a colon.
        assert_eq!(parse_frames("1001-1011x5").unwrap(), vec![1001, 1006, 1011]);
        assert_eq!(parse_frames("1001-1011:5").unwrap(), vec![1001, 1006, 1011]);
        // The last frame is kept only when the step lands on it.
        assert_eq!(parse_frames("1-10x4").unwrap(), vec![1, 5, 9]);
        assert_eq!(parse_frames("1-1:3").unwrap(), vec![1]);
        assert_eq!(
            parse_frames("1001,1005-1010").unwrap(),
            vec![1001, 1005, 1006, 1007, 1008, 1009, 1010]
        );
        assert_eq!(
            parse_frames("1-3, 10-14:2").unwrap(),
            vec![1, 2, 3, 10, 12, 14]
        );
        assert_eq!(parse_frames("-3--1").unwrap(), vec![-3, -2, -1]);
    }

    #[test]
    fn refuses_what_no_farm_writes_saying_why() {
        for (spec, why) in [
            ("1-10x0", "the step must be 1 or more"),
            ("1-10:-2", "the step must be 1 or more"),
            ("1-10x", "bad step"),
            ("5x2", "a step needs a range"),
            ("10-1:2", "the last frame comes before the first"),
            ("1,,3", "an empty item"),
            ("", "an empty item"),
            ("1-b", "bad frame number"),
            ("0-9000000000000", "more than 1000000 frames"),
            ("1-600000,1-600000", "more than 1000000 frames"),
        ] {
            let err = parse_frames(spec).expect_err(spec);
            assert!(err.message.contains(why), "{spec}: {}", err.message);
            assert_eq!(err.kind, crate::error::ErrorKind::BadInput);
        }
    }
}
