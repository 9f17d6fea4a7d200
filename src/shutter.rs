//! Motion blur's shutter: the times within a frame's shutter a node is
//! rendered at, whose mean is the blurred frame.

use crate::choice::Choice;

/// Where the shutter opens, relative to the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ShutterOffset {
    /// Open half the shutter before the frame, close half after it.
    #[default]
    Centred,
    /// Open at the frame.
    Start,
    /// Close at the frame.
    End,
}

impl Choice for ShutterOffset {
    const ALL: &'static [Self] = &[
        ShutterOffset::Centred,
        ShutterOffset::Start,
        ShutterOffset::End,
    ];
    fn name(self) -> &'static str {
        match self {
            ShutterOffset::Centred => "centred",
            ShutterOffset::Start => "start",
            ShutterOffset::End => "end",
        }
    }
}

/// How a frame is blurred: `samples` renders (0: none, the frame alone)
/// spread over a shutter `length` frames long.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Shutter {
    /// Renders averaged; 0 and 1 render the frame alone.
    pub samples: usize,
    /// How long the shutter is open, in frames.
    pub length: f64,
    /// Where it opens.
    pub offset: ShutterOffset,
}

impl Shutter {
    /// The times frame `frame` is rendered at: the midpoints of `samples`
    /// equal parts of the shutter (`open + length·(k + ½)/N`); the frame
    /// alone without blur or with a shutter that does not open.
    pub fn times(&self, frame: f64) -> Vec<f64> {
        let n = self.samples;
        if n <= 1 || self.length <= 0.0 {
            return vec![frame];
        }
        let open = match self.offset {
            ShutterOffset::Centred => frame - 0.5 * self.length,
            ShutterOffset::Start => frame,
            ShutterOffset::End => frame - self.length,
        };
        (0..n)
            .map(|k| open + self.length * (k as f64 + 0.5) / n as f64)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_sit_at_the_midpoints_of_equal_parts_of_the_shutter() {
        let centred = Shutter {
            samples: 4,
            length: 1.0,
            offset: ShutterOffset::Centred,
        };
        assert_eq!(centred.times(5.0), [4.625, 4.875, 5.125, 5.375]);
        let start = Shutter {
            offset: ShutterOffset::Start,
            length: 0.5,
            samples: 2,
        };
        assert_eq!(start.times(10.0), [10.125, 10.375]);
        let end = Shutter {
            offset: ShutterOffset::End,
            length: 0.5,
            samples: 2,
        };
        assert_eq!(end.times(10.0), [9.625, 9.875]);
        assert_eq!(Shutter::default().times(3.0), [3.0]);
        assert_eq!(
            Shutter {
                samples: 1,
                ..centred
            }
            .times(3.0),
            [3.0]
        );
    }
}
