//! Frame buffers behind clips: any depth and component count, bounds anywhere,
//! rows bottom-up in memory, or top-down (negative row bytes) on request.

use std::ffi::c_void;
use std::sync::Arc;

use morphfx::geom::RectI;
use morphfx::image::Image;
use openfx::sys::image_effect_v1::image_effect::*;

use super::props::PropertySet;

#[derive(Debug, Clone, PartialEq)]
pub enum Pixels {
    U8(Vec<u8>),
    U16(Vec<u16>),
    F32(Vec<f32>),
}

#[derive(Debug)]
pub struct Frame {
    /// Pixel bounds at the frame's own scale.
    pub bounds: RectI,
    pub channels: usize,
    pub pixels: std::cell::UnsafeCell<Pixels>,
    /// Rows stored top-down, handed out with negative row bytes.
    pub top_down: bool,
    pub premultiplied: bool,
    /// Pixel aspect ratio: a pixel is `par` canonical units wide.
    pub par: f64,
}

// SAFETY: plugins write to the output frame through raw pointers from render
// threads, each to its own render window; the harness reads only after the
// render returns. Nothing else mutates `pixels` while it is shared.
unsafe impl Sync for Frame {}

impl Frame {
    pub fn from_image(img: &Image, depth: &str, top_down: bool) -> Frame {
        let data = if top_down {
            flip_rows(&img.data, img.width() * img.channels)
        } else {
            img.data.clone()
        };
        let pixels = match depth {
            "OfxBitDepthByte" => Pixels::U8(
                data.iter()
                    .map(|v| (v * 255.0 + 0.5).clamp(0.0, 255.0) as u8)
                    .collect(),
            ),
            "OfxBitDepthShort" => Pixels::U16(
                data.iter()
                    .map(|v| (v * 65535.0 + 0.5).clamp(0.0, 65535.0) as u16)
                    .collect(),
            ),
            _ => Pixels::F32(data),
        };
        Frame {
            bounds: img.bounds,
            channels: img.channels,
            pixels: std::cell::UnsafeCell::new(pixels),
            top_down,
            premultiplied: true,
            par: 1.0,
        }
    }

    /// A float, bottom-up frame holding `img`'s pixels (moved, not copied:
    /// a sequence render hands over a plate a frame).
    pub fn from_float_image(img: Image) -> Frame {
        Frame {
            bounds: img.bounds,
            channels: img.channels,
            pixels: std::cell::UnsafeCell::new(Pixels::F32(img.data)),
            top_down: false,
            premultiplied: true,
            par: 1.0,
        }
    }

    /// The frame as float pixels, bottom-up; moved out when this is the
    /// last reference to a float, bottom-up frame, copied otherwise.
    pub fn into_image(self: Arc<Self>) -> Image {
        match Arc::try_unwrap(self) {
            Ok(f) if !f.top_down => {
                let Frame {
                    bounds,
                    channels,
                    pixels,
                    top_down,
                    premultiplied,
                    par,
                } = f;
                match pixels.into_inner() {
                    Pixels::F32(data) => Image {
                        bounds,
                        channels,
                        data,
                    },
                    other => Frame {
                        bounds,
                        channels,
                        pixels: std::cell::UnsafeCell::new(other),
                        top_down,
                        premultiplied,
                        par,
                    }
                    .to_image(),
                }
            }
            Ok(f) => f.to_image(),
            Err(shared) => shared.to_image(),
        }
    }

    /// A zeroed frame, allocated zeroed (no image made and converted: a
    /// render's output buffer is 33 MB at 1080p).
    pub fn blank(bounds: RectI, channels: usize, depth: &str, top_down: bool) -> Frame {
        let n = bounds.area() * channels;
        let pixels = match depth {
            "OfxBitDepthByte" => Pixels::U8(vec![0; n]),
            "OfxBitDepthShort" => Pixels::U16(vec![0; n]),
            _ => Pixels::F32(vec![0.0; n]),
        };
        Frame {
            bounds,
            channels,
            pixels: std::cell::UnsafeCell::new(pixels),
            top_down,
            premultiplied: true,
            par: 1.0,
        }
    }

    pub fn depth(&self) -> &'static str {
        // SAFETY: reading the variant only; writers never change it.
        match unsafe { &*self.pixels.get() } {
            Pixels::U8(_) => "OfxBitDepthByte",
            Pixels::U16(_) => "OfxBitDepthShort",
            Pixels::F32(_) => "OfxBitDepthFloat",
        }
    }

    /// The frame as float pixels, bottom-up (after renders have finished).
    pub fn to_image(&self) -> Image {
        // SAFETY: called when no render is writing (see the Sync note).
        let data: Vec<f32> = match unsafe { &*self.pixels.get() } {
            Pixels::U8(v) => v.iter().map(|&x| x as f32 / 255.0).collect(),
            Pixels::U16(v) => v.iter().map(|&x| x as f32 / 65535.0).collect(),
            Pixels::F32(v) => v.clone(),
        };
        let row = self.bounds.width() * self.channels;
        let data = if self.top_down {
            flip_rows(&data, row)
        } else {
            data
        };
        Image {
            bounds: self.bounds,
            channels: self.channels,
            data,
        }
    }

    /// `img` stored as this frame is (depth, row order, alpha state, aspect).
    fn like(&self, img: &Image) -> Frame {
        let mut f = Frame::from_image(img, self.depth(), self.top_down);
        f.premultiplied = self.premultiplied;
        f.par = self.par;
        f
    }

    /// One field of an interlaced frame, each of its lines doubled: the
    /// lower field is lines 0, 2, 4, ... (y up), the upper 1, 3, 5, ...
    pub fn field_doubled(&self, upper: bool) -> Frame {
        let src = self.to_image();
        let b = self.bounds;
        let img = Image::from_fn(b, self.channels, |i, j, c| {
            let line = (j - j.rem_euclid(2) + upper as i32).clamp(b.y1, b.y2 - 1);
            src.pixel(i, line)[c]
        });
        self.like(&img)
    }

    /// A box-filtered copy at render scale `scale` (proxy renders).
    pub fn scaled(&self, scale: (f64, f64)) -> Frame {
        let src = self.to_image();
        let b = self.bounds;
        let sb = RectI::new(
            (b.x1 as f64 * scale.0).floor() as i32,
            (b.y1 as f64 * scale.1).floor() as i32,
            (b.x2 as f64 * scale.0).ceil() as i32,
            (b.y2 as f64 * scale.1).ceil() as i32,
        );
        let (fx, fy) = (1.0 / scale.0, 1.0 / scale.1);
        let img = Image::from_fn(sb, self.channels, |i, j, c| {
            // Average the full-resolution pixels whose centres fall in this pixel.
            let (x0, x1) = (
                (i as f64 * fx).ceil() as i32,
                ((i + 1) as f64 * fx).ceil() as i32,
            );
            let (y0, y1) = (
                (j as f64 * fy).ceil() as i32,
                ((j + 1) as f64 * fy).ceil() as i32,
            );
            let (mut sum, mut n) = (0.0, 0);
            for y in y0.max(b.y1)..y1.min(b.y2) {
                for x in x0.max(b.x1)..x1.min(b.x2) {
                    sum += src.pixel(x, y)[c];
                    n += 1;
                }
            }
            if n > 0 {
                sum / n as f32
            } else {
                0.0
            }
        });
        self.like(&img)
    }

    /// The image property set handed to the plugin (owning a reference to us).
    pub fn image_props(self: &Arc<Self>, scale: (f64, f64), time: f64) -> PropertySet {
        let row_elems = self.bounds.width() * self.channels;
        let (elem, base): (usize, *mut c_void) = {
            // SAFETY: taking the buffer's address; the Arc in `owner` keeps it alive.
            match unsafe { &mut *self.pixels.get() } {
                Pixels::U8(v) => (1, v.as_mut_ptr() as *mut c_void),
                Pixels::U16(v) => (2, v.as_mut_ptr() as *mut c_void),
                Pixels::F32(v) => (4, v.as_mut_ptr() as *mut c_void),
            }
        };
        let row_bytes = (row_elems * elem) as isize;
        let h = self.bounds.height() as isize;
        let (data, rb) = if self.top_down && h > 0 {
            // SAFETY: the bottom row is the last one in memory; in bounds.
            (
                unsafe { (base as *mut u8).offset((h - 1) * row_bytes) } as *mut c_void,
                -row_bytes,
            )
        } else {
            (base, row_bytes)
        };
        let mut p = PropertySet::new();
        p.set_ptr(kOfxImagePropData, data);
        p.set_int(
            kOfxImagePropBounds,
            &[
                self.bounds.x1,
                self.bounds.y1,
                self.bounds.x2,
                self.bounds.y2,
            ],
        );
        p.set_int(
            kOfxImagePropRegionOfDefinition,
            &[
                self.bounds.x1,
                self.bounds.y1,
                self.bounds.x2,
                self.bounds.y2,
            ],
        );
        p.set_int(kOfxImagePropRowBytes, &[rb as i32]);
        p.set_str(kOfxImageEffectPropPixelDepth, self.depth());
        p.set_str(
            kOfxImageEffectPropComponents,
            match self.channels {
                1 => "OfxImageComponentAlpha",
                3 => "OfxImageComponentRGB",
                _ => "OfxImageComponentRGBA",
            },
        );
        p.set_str(
            kOfxImageEffectPropPreMultiplication,
            &if self.channels == 4 && !self.premultiplied {
                kOfxImageUnPreMultiplied
            } else if self.channels == 3 {
                kOfxImageOpaque
            } else {
                kOfxImagePreMultiplied
            }
            .to_string_lossy(),
        );
        p.set_double(kOfxImagePropPixelAspectRatio, &[self.par]);
        p.set_double(kOfxImageEffectPropRenderScale, &[scale.0, scale.1]);
        p.set_str(kOfxImagePropField, "OfxImageFieldNone");
        p.set_str(
            kOfxImagePropUniqueIdentifier,
            &format!("{:p}@{time}", Arc::as_ptr(self)),
        );
        p.owner = Some(Box::new(self.clone()));
        p
    }
}

fn flip_rows(data: &[f32], row: usize) -> Vec<f32> {
    if row == 0 {
        return data.to_vec();
    }
    data.chunks(row).rev().flatten().copied().collect()
}

/// `img` with `channels` components, as a host converts between clips:
/// RGBA to RGB drops alpha, RGB to RGBA adds an opaque one, Alpha keeps the
/// alpha (or the luminance-free opacity 1 of an RGB image).
pub fn with_channels(img: &Image, channels: usize) -> Image {
    if img.channels == channels {
        return img.clone();
    }
    let n = img.channels;
    Image::from_fn(img.bounds, channels, |i, j, c| {
        let p = img.pixel(i, j);
        match (n, channels) {
            (4, 1) => p[3],
            (3, 1) => 1.0,
            (1, _) if c == 3 => p[0],
            (1, _) => 0.0,
            (_, _) if c < 3 => p[c.min(n - 1)],
            (4, _) => p[3],
            _ => 1.0,
        }
    })
}
