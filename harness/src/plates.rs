//! Plates of a file or sequence, read on demand (and the next one ahead)
//! as the host hands them to the plugin.

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::host::{frame, Frame, FrameSource, HostError};
use crate::io::{self};
use crate::pipeline::ReadAhead;
use crate::sequence::{frame_path, is_sequence};
use crate::sync::Locked;

/// A frame read from disk: its number, pixels and display-window size.
pub type CachedPlate = (i64, Arc<Frame>, (usize, usize));

/// Reads frames of a file or sequence on demand.
pub struct Plates {
    pub pattern: String,
    pub colour: io::Colour,
    pub cache: Mutex<Vec<CachedPlate>>,
    /// The next frame, read ahead on another thread.
    pub ahead: Mutex<ReadAhead<Loaded>>,
    /// Time spent reading files, for the end-of-run summary.
    pub read_time: Mutex<Duration>,
    /// The first read that failed: the plugin only learns "no image", so the
    /// harness reports the file and why itself.
    pub error: Mutex<Option<HostError>>,
    /// A matte (Mask, Timing): a file with no alpha is handed over as RGB,
    /// which the nodes read by its mean, not as RGBA with alpha 1.
    pub matte: bool,
}

/// A plate as the host hands it over, with its display window's size.
pub type Loaded = (Arc<Frame>, (usize, usize));

impl Plates {
    pub fn new(pattern: &str, colour: io::Colour) -> Arc<Plates> {
        Arc::new(Plates {
            pattern: pattern.to_owned(),
            colour,
            cache: Mutex::new(Vec::new()),
            ahead: Mutex::new(ReadAhead::default()),
            read_time: Mutex::new(Duration::ZERO),
            error: Mutex::new(None),
            matte: false,
        })
    }

    /// A matte's frames: see [`Plates::matte`](field@Plates::matte).
    pub fn matte(pattern: &str, colour: io::Colour) -> Arc<Plates> {
        let mut plates = Arc::into_inner(Plates::new(pattern, colour)).expect("just made");
        plates.matte = true;
        Arc::new(plates)
    }

    pub fn file_frame(&self, frame: i64) -> i64 {
        if is_sequence(&self.pattern) {
            frame
        } else {
            0
        }
    }

    pub fn load(&self, frame: i64) -> Result<Loaded, HostError> {
        let path = frame_path(&self.pattern, frame);
        let started = Instant::now();
        let plate = io::read_as(&path, self.colour)?;
        let image = if self.matte && !io::probe(&path)?.alpha {
            frame::with_channels(&plate.image, 3)
        } else {
            plate.image
        };
        *self.read_time.locked() += started.elapsed();
        Ok((Arc::new(Frame::from_float_image(image)), plate.size))
    }

    /// Starts reading `frame` on another thread, unless it is at hand.
    pub fn read_ahead(self: &Arc<Self>, frame: i64) {
        let frame = self.file_frame(frame);
        let mut ahead = self.ahead.locked();
        // A frame read ahead but never asked for (the plugin did not need
        // it) is kept once read, and makes room.
        if let Some((k, Ok(loaded))) = ahead.take_finished() {
            self.keep(k, &loaded);
        }
        if !self.cache.locked().iter().any(|(k, _, _)| *k == frame) {
            let me = self.clone();
            ahead.start(frame, move || me.load(frame));
        }
    }

    pub fn plate(&self, frame: i64) -> Result<Loaded, HostError> {
        let frame = self.file_frame(frame);
        if let Some((_, f, size)) = self.cache.locked().iter().find(|(k, _, _)| *k == frame) {
            return Ok((f.clone(), *size));
        }
        let pending = self.ahead.locked().take(frame);
        let loaded = pending
            .unwrap_or_else(|| self.load(frame))
            .inspect_err(|e| {
                self.error.locked().get_or_insert_with(|| e.clone());
            })?;
        self.keep(frame, &loaded);
        Ok(loaded)
    }

    /// Keeps `frame` at hand, and the next (read ahead); the others go: a
    /// sequence is rendered in order, each frame once.
    pub fn keep(&self, frame: i64, (f, size): &Loaded) {
        let mut cache = self.cache.locked();
        cache.retain(|(k, _, _)| *k == frame + 1);
        cache.push((frame, f.clone(), *size));
    }
}

impl FrameSource for Plates {
    fn frame(&self, time: f64) -> Result<Arc<Frame>, String> {
        self.plate(time.round() as i64)
            .map(|(f, _)| f)
            .map_err(|e| e.message)
    }
}

/// A picture that is the same at every frame: a single plate, or a
/// picture held in memory.
pub struct Still(pub Arc<Frame>);

impl FrameSource for Still {
    fn frame(&self, _time: f64) -> Result<Arc<Frame>, String> {
        Ok(self.0.clone())
    }
}
