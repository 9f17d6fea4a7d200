//! `morphfx track`: features keyed once, followed through the footage.

use std::path::Path;

use morphfx::track::TrackSettings;

mod follow;

use follow::Track;

use crate::host::HostError;
use crate::sequence::parse_frames;

/// `morphfx track`, its options checked.
pub fn track_job(
    scene: &Path,
    a: &str,
    b: Option<&str>,
    frames: &str,
    output: Option<&Path>,
    radius: usize,
    min_correlation: f64,
) -> Result<(), HostError> {
    if !(2..=64).contains(&radius) {
        return Err(HostError::bad(format!(
            "--radius {radius}: must be 2 to 64 pixels"
        )));
    }
    if !(0.0..1.0).contains(&min_correlation) {
        return Err(HostError::bad(format!(
            "--min-correlation {min_correlation}: must be at least 0 and below 1"
        )));
    }
    Track {
        scene,
        a,
        b,
        frames: parse_frames(frames)?,
        output,
        settings: TrackSettings {
            radius,
            min_correlation,
            ..TrackSettings::default()
        },
    }
    .run()
}
