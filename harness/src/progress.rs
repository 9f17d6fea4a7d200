//! Progress of a long command on standard error.

use std::io::IsTerminal;

/// Frame n/N, fps and ETA on a terminal; plain lines otherwise.
pub struct Progress {
    bar: Option<indicatif::ProgressBar>,
    total: usize,
    start: std::time::Instant,
}

impl Progress {
    pub fn new(total: usize) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = indicatif::ProgressBar::new(total as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{bar:30} frame {pos}/{len}  {per_sec}  ETA {eta}  {msg}",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b
        });
        Progress {
            bar,
            total,
            start: std::time::Instant::now(),
        }
    }
    pub fn tick(&self, n: usize, frame: i64) {
        match &self.bar {
            Some(b) => {
                b.set_message(format!("(frame {frame})"));
                b.set_position(n as u64);
            }
            None if self.total > 1 => {
                let secs = self.start.elapsed().as_secs_f64();
                let fps = n as f64 / secs.max(1e-9);
                let eta = (self.total - n) as f64 / fps.max(1e-9);
                eprintln!(
                    "frame {n}/{} ({frame})  {fps:.2} fps  ETA {eta:.0}s",
                    self.total
                );
            }
            None => {}
        }
    }
    /// Finishes the bar and says where the time went.
    pub fn done(&self, breakdown: &str) {
        if let Some(b) = &self.bar {
            b.finish();
        }
        let secs = self.start.elapsed().as_secs_f64();
        let peak = peak_memory_mib()
            .map(|m| format!("; peak memory {m} MiB"))
            .unwrap_or_default();
        eprintln!(
            "{} frame(s) in {secs:.2} s ({:.2} fps): {breakdown}{peak}",
            self.total,
            self.total as f64 / secs.max(1e-9)
        );
    }
}

/// The process's peak resident size so far (Linux: `VmHWM`), MiB.
pub fn peak_memory_mib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024)
}
