//! Frames read ahead of and written behind the work on them.
//!
//! [`ReadAhead`]: the next frame a sequence will ask for, read on another
//! thread. [`WriteBehind`]: a writer thread takes finished frames from a
//! bounded queue (memory stays bounded: at most `depth` frames wait), writes
//! them in order, each atomically, and the first failure stops the run at
//! the next frame, with the file named.

use std::path::PathBuf;
use std::sync::mpsc::{sync_channel, SyncSender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::error::HostError;
use crate::io::{self, OutputFormat, Plate};
use crate::sync::Locked;

/// One frame being read on another thread, ahead of need.
pub struct ReadAhead<T> {
    pending: Option<(i64, JoinHandle<Result<T, HostError>>)>,
}

impl<T: Send + 'static> Default for ReadAhead<T> {
    fn default() -> Self {
        ReadAhead { pending: None }
    }
}

impl<T: Send + 'static> ReadAhead<T> {
    /// Starts `load`ing `frame` on another thread, unless a read is under way.
    pub fn start(
        &mut self,
        frame: i64,
        load: impl FnOnce() -> Result<T, HostError> + Send + 'static,
    ) {
        if self.pending.is_none() {
            self.pending = Some((frame, std::thread::spawn(load)));
        }
    }

    /// `frame`, waited for, when it is the one being read; `None` otherwise.
    pub fn take(&mut self, frame: i64) -> Option<Result<T, HostError>> {
        let (_, job) = self.pending.take_if(|(f, _)| *f == frame)?;
        Some(joined(job))
    }

    /// A read that finished but was never asked for (the reader did not
    /// need that frame), to keep or drop; it makes room for the next.
    pub fn take_finished(&mut self) -> Option<(i64, Result<T, HostError>)> {
        let (frame, job) = self.pending.take_if(|(_, job)| job.is_finished())?;
        Some((frame, joined(job)))
    }
}

fn joined<T>(job: JoinHandle<Result<T, HostError>>) -> Result<T, HostError> {
    job.join()
        .map_err(|_| HostError::failed("a frame reader panicked"))?
}

type Job = (PathBuf, Plate, OutputFormat);

pub struct WriteBehind {
    queue: Option<SyncSender<Job>>,
    writer: Option<JoinHandle<Duration>>,
    failed: Arc<Mutex<Option<HostError>>>,
}

impl WriteBehind {
    /// A writer with room for `depth` frames waiting.
    pub fn new(depth: usize) -> WriteBehind {
        let (queue, jobs) = sync_channel::<Job>(depth);
        let failed = Arc::new(Mutex::new(None));
        let seen = failed.clone();
        let writer = std::thread::spawn(move || {
            let mut busy = Duration::ZERO;
            for (path, plate, format) in jobs {
                if seen.locked().is_some() {
                    continue; // drain: nothing more is written after a failure
                }
                let started = Instant::now();
                if let Err(e) = io::write_as(&path, &plate, format) {
                    *seen.locked() = Some(e);
                }
                busy += started.elapsed();
            }
            busy
        });
        WriteBehind {
            queue: Some(queue),
            writer: Some(writer),
            failed,
        }
    }

    fn failure(&self) -> Option<HostError> {
        self.failed.locked().clone()
    }

    /// Queues a frame (waiting while the queue is full); an earlier frame's
    /// write failure comes back here.
    pub fn write(
        &self,
        path: PathBuf,
        plate: Plate,
        format: OutputFormat,
    ) -> Result<(), HostError> {
        if let Some(e) = self.failure() {
            return Err(e);
        }
        let queue = self.queue.as_ref().expect("open until finish");
        queue
            .send((path, plate, format))
            .map_err(|_| HostError::failed("the frame writer stopped"))
    }

    /// Waits for every queued frame; the time the writer spent writing.
    pub fn finish(mut self) -> Result<Duration, HostError> {
        drop(self.queue.take());
        let busy = self
            .writer
            .take()
            .expect("joined once")
            .join()
            .map_err(|_| HostError::failed("the frame writer panicked"))?;
        match self.failure() {
            Some(e) => Err(e),
            None => Ok(busy),
        }
    }
}

impl Drop for WriteBehind {
    /// An early return (a render error) still lets queued frames finish,
    /// each whole or not at all.
    fn drop(&mut self) {
        drop(self.queue.take());
        if let Some(w) = self.writer.take() {
            let _ = w.join();
        }
    }
}
