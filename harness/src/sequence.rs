//! File sequences written with `#` padding (`plate.####.exr`) and frame ranges.

use std::path::PathBuf;

use crate::host::HostError;

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

pub fn is_sequence(pattern: &str) -> bool {
    pattern.contains('#')
}

/// `1001-1048`, `1001`, or lists `1,5,9-12`.
pub fn parse_frames(spec: &str) -> Result<Vec<i64>, HostError> {
    let bad = || {
        HostError::bad(format!(
            "--frames {spec}: expected FIRST-LAST, a frame, or a list like 1,5,9-12"
        ))
    };
    let mut frames = Vec::new();
    for part in spec.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (a, b) = match part[1..].find('-') {
            Some(k) => (&part[..k + 1], &part[k + 2..]),
            None => (part, part),
        };
        let (a, b): (i64, i64) = (
            a.trim().parse().map_err(|_| bad())?,
            b.trim().parse().map_err(|_| bad())?,
        );
        if b < a {
            return Err(bad());
        }
        frames.extend(a..=b);
    }
    if frames.is_empty() {
        return Err(bad());
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
}
