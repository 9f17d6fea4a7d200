//! Multi-layer EXRs read and written whole: every channel of a file,
//! grouped into layers by name as compositing packages group them. `N.X`
//! is channel X of layer `N`; R, G, B and A outside any layer are the main
//! picture, `rgba`; any other channel outside a layer is a layer of its
//! own. Parts of a multi-part file name the layers of their channels.

use std::path::Path;

use exr::prelude::*;
use half::f16;
use morphfx::geom::RectI;
use morphfx::image::Image;
use rayon::prelude::*;

use crate::error::HostError;
use crate::io::{self, data_bounds, exr_read_error, ExrPrecision};

/// The main picture's layer name.
pub const RGBA: &str = "rgba";

/// Every channel of an EXR over one data window.
#[derive(Debug, Clone, PartialEq)]
pub struct Layered {
    /// The display window's size, and its top-left corner in the file's
    /// pixel coordinates (as [`crate::plate::Plate`]'s).
    pub size: (usize, usize),
    pub origin: (i32, i32),
    /// The data window in canonical pixels.
    pub bounds: RectI,
    /// Each channel: its full name, and its samples over `bounds`,
    /// canonical rows (bottom-up).
    pub channels: Vec<(String, Vec<f32>)>,
}

/// A layer: its name and its channels (indices into
/// [`Layered::channels`], in the file's order).
#[derive(Debug, Clone, PartialEq)]
pub struct Layer {
    pub name: String,
    pub channels: Vec<usize>,
}

/// The layer a channel belongs to, and the channel's own name in it.
pub fn layer_of(channel: &str) -> (&str, &str) {
    match channel.rsplit_once('.') {
        Some((layer, own)) => (layer, own),
        None if ["R", "G", "B", "A"].contains(&channel.to_ascii_uppercase().as_str()) => {
            (RGBA, channel)
        }
        None => (channel, channel),
    }
}

pub use morphfx::image::holds_ids;

impl Layered {
    /// Every channel of the EXR at `path`.
    pub fn read(path: &Path) -> std::result::Result<Layered, HostError> {
        io::probe(path)?;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .from_file(path)
            .map_err(|e| exr_read_error(path, e))?;
        let display = image.attributes.display_window;
        let first = image
            .layer_data
            .first()
            .ok_or_else(|| HostError::bad(format!("{}: an EXR with no part", path.display())))?;
        let (w, h) = (first.size.width(), first.size.height());
        let position = first.attributes.layer_position;
        let mut channels = Vec::new();
        for part in &image.layer_data {
            if part.size != first.size || part.attributes.layer_position != position {
                return Err(HostError::bad(format!(
                    "{}: its parts cover different data windows; morphfx reads \
                     multi-part files whose parts share one",
                    path.display()
                )));
            }
            let prefix = part.attributes.layer_name.as_ref().map(|n| n.to_string());
            for c in &part.channel_data.list {
                let own = c.name.to_string();
                let name = match &prefix {
                    Some(p) if !own.starts_with(&format!("{p}.")) => format!("{p}.{own}"),
                    _ => own,
                };
                channels.push((name, bottom_up(&c.sample_data, w, h)));
            }
        }
        Ok(Layered {
            size: (display.size.width(), display.size.height()),
            origin: (display.position.x(), display.position.y()),
            bounds: data_bounds(display, position, (w, h)),
            channels,
        })
    }

    /// The layers, in the order their first channels come.
    pub fn layers(&self) -> Vec<Layer> {
        let mut layers: Vec<Layer> = Vec::new();
        for (k, (name, _)) in self.channels.iter().enumerate() {
            let (layer, _) = layer_of(name);
            match layers.iter_mut().find(|l| l.name == layer) {
                Some(l) => l.channels.push(k),
                None => layers.push(Layer {
                    name: layer.to_owned(),
                    channels: vec![k],
                }),
            }
        }
        // The main picture's channels in R, G, B, A order, as it is read.
        for l in layers.iter_mut().filter(|l| l.name == RGBA) {
            let rank = |k: &usize| {
                let name = self.channels[*k].0.to_ascii_uppercase();
                ["R", "G", "B", "A"].iter().position(|c| *c == name)
            };
            l.channels.sort_by_key(rank);
        }
        layers
    }

    /// Up to four channels as one RGBA image over the data window, the
    /// rest zero: how they travel through a render together.
    pub fn group(&self, channels: &[usize]) -> Image {
        let b = self.bounds;
        let planes: Vec<&[f32]> = channels.iter().map(|&k| &self.channels[k].1[..]).collect();
        let mut image = Image::new(b, 4);
        image
            .data
            .par_chunks_mut(4)
            .enumerate()
            .for_each(|(p, px)| {
                for (c, plane) in planes.iter().enumerate().take(4) {
                    px[c] = plane[p];
                }
            });
        image
    }

    /// Writes every channel to `path` as one single-part EXR (scan lines,
    /// channels named as read), atomically.
    pub fn write(
        &self,
        path: &Path,
        precision: ExrPrecision,
        compression: Compression,
    ) -> std::result::Result<(), HostError> {
        let (w, h) = (self.bounds.width(), self.bounds.height());
        let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = self
            .channels
            .iter()
            .map(|(name, samples)| {
                let rows = flipped(samples, w, h);
                let samples = match precision {
                    ExrPrecision::Float => FlatSamples::F32(rows),
                    ExrPrecision::Half => {
                        FlatSamples::F16(rows.into_iter().map(f16::from_f32).collect())
                    }
                };
                AnyChannel::new(name.as_str(), samples)
            })
            .collect();
        let encoding = Encoding {
            compression,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        };
        let mut layer = exr::prelude::Layer::new(
            Vec2(w, h),
            LayerAttributes::default(),
            encoding,
            AnyChannels::sort(channels),
        );
        let (ox, oy) = self.origin;
        let b = self.bounds;
        layer.attributes.layer_position = Vec2(ox + b.x1, oy + self.size.1 as i32 - b.y2);
        let mut image = exr::prelude::Image::from_layer(layer);
        image.attributes.display_window =
            IntegerBounds::new(Vec2(ox, oy), Vec2(self.size.0, self.size.1));
        io::write_atomically(path, |tmp| {
            image
                .write()
                .to_file(tmp)
                .map_err(|e| HostError::failed(format!("cannot write EXR: {e}")))
        })
    }
}

/// A channel's samples as floats, its rows turned bottom-up.
fn bottom_up(samples: &FlatSamples, w: usize, h: usize) -> Vec<f32> {
    let floats: Vec<f32> = match samples {
        FlatSamples::F16(v) => v.iter().map(|s| s.to_f32()).collect(),
        FlatSamples::F32(v) => v.clone(),
        FlatSamples::U32(v) => v.iter().map(|s| *s as f32).collect(),
    };
    flipped(&floats, w, h)
}

/// Rows reversed: bottom-up to top-down, or back.
fn flipped(samples: &[f32], w: usize, h: usize) -> Vec<f32> {
    let mut out = Vec::with_capacity(w * h);
    for row in samples.chunks_exact(w.max(1)).rev().take(h) {
        out.extend_from_slice(row);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channels_group_into_layers_by_name() {
        assert_eq!(layer_of("R"), (RGBA, "R"));
        assert_eq!(layer_of("a"), (RGBA, "a"));
        assert_eq!(layer_of("N.X"), ("N", "X"));
        assert_eq!(layer_of("crypto00.R"), ("crypto00", "R"));
        assert_eq!(layer_of("diffuse.indirect.B"), ("diffuse.indirect", "B"));
        assert_eq!(layer_of("Z"), ("Z", "Z"));
    }
}
