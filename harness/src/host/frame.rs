//! Frame buffers behind clips: any depth and component count, bounds anywhere,
//! rows bottom-up in memory, or top-down (negative row bytes) on request.

use std::ffi::c_void;
use std::sync::Arc;

use morphfx::geom::RectI;
use morphfx::image::Image;
use openfx::sys::image_effect_v1::image_effect::*;

use super::props::PropertySet;

#[derive(Debug, PartialEq)]
pub enum Pixels {
    U8(Vec<u8>),
    U16(Vec<u16>),
    F32(Vec<f32>),
    /// Floats the frame does not own, lent by [`lend`] for one scope.
    Lent(Lent),
}

/// Where lent floats lie. Only [`lend`] makes one, and it outlives none of
/// the frames that hold it (no `Clone`: it cannot be copied out of one).
#[derive(Debug, PartialEq)]
pub struct Lent {
    ptr: *const f32,
    len: usize,
}

/// Rows of floats a caller lends to the host for one scope: a picture the
/// host hands the plugin as a source without copying it.
#[derive(Debug, Clone, Copy)]
pub struct LentRows<'a> {
    pub width: usize,
    pub height: usize,
    pub channels: usize,
    /// Top row first.
    pub data: &'a [f32],
}

/// Frames over `pictures` (float, top-down sources) for `body` to connect,
/// render from and let go of: the host reads the caller's rows in place.
/// Every frame must be gone when `body` returns (clips disconnected,
/// images released); one that outlived it would point at rows the caller
/// may free, so the process aborts then rather than go on unsound.
pub fn lend<R>(
    pictures: &[LentRows<'_>],
    body: impl FnOnce(Vec<Arc<Frame>>) -> R,
) -> Result<R, String> {
    for (k, p) in pictures.iter().enumerate() {
        let expected = p
            .width
            .checked_mul(p.height)
            .and_then(|n| n.checked_mul(p.channels));
        if expected != Some(p.data.len()) || p.width > i32::MAX as usize / 2 {
            return Err(format!(
                "picture {}: {} floats for {}x{}x{}",
                k + 1,
                p.data.len(),
                p.height,
                p.width,
                p.channels
            ));
        }
    }
    let frames: Vec<Arc<Frame>> = pictures
        .iter()
        .map(|p| {
            Arc::new(Frame {
                bounds: RectI::new(0, 0, p.width as i32, p.height as i32),
                channels: p.channels,
                pixels: std::cell::UnsafeCell::new(Pixels::Lent(Lent {
                    ptr: p.data.as_ptr(),
                    len: p.data.len(),
                })),
                top_down: true,
                premultiplied: true,
                par: 1.0,
            })
        })
        .collect();
    /// Checks, even as a panic unwinds, that the scope's frames are gone.
    struct Scope(Vec<Arc<Frame>>);
    impl Drop for Scope {
        fn drop(&mut self) {
            let held = |f: &Arc<Frame>| Arc::strong_count(f) > 1 || Arc::weak_count(f) > 0;
            if self.0.iter().any(held) {
                eprintln!("morphfx host: a lent picture outlived its render; aborting");
                std::process::abort();
            }
        }
    }
    let scope = Scope(frames.clone());
    let out = body(frames);
    drop(scope);
    Ok(out)
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
// render returns. Nothing else mutates `pixels` while it is shared. Lent
// rows are only read, and live as long as the frame (see `lend`).
unsafe impl Sync for Frame {}
// SAFETY: as for Sync: owned pixels are plain vectors, and lent rows are a
// shared borrow that `lend` keeps alive for every thread the frame visits.
unsafe impl Send for Frame {}

impl Lent {
    fn floats(&self) -> &[f32] {
        // SAFETY: `lend` made this from a live `&[f32]` of `len` floats that
        // outlives every frame holding it, and nothing writes through it.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

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
                let (bounds, channels) = (f.bounds, f.channels);
                match f.into_floats() {
                    Ok(data) => Image {
                        bounds,
                        channels,
                        data,
                    },
                    Err(f) => f.to_image(),
                }
            }
            Ok(f) => f.to_image(),
            Err(shared) => shared.to_image(),
        }
    }

    /// The samples as they lie in memory, moved out, when they are floats;
    /// the frame back otherwise.
    pub fn into_floats(self) -> Result<Vec<f32>, Frame> {
        let Frame {
            bounds,
            channels,
            pixels,
            top_down,
            premultiplied,
            par,
        } = self;
        match pixels.into_inner() {
            Pixels::F32(data) => Ok(data),
            other @ (Pixels::U8(_) | Pixels::U16(_) | Pixels::Lent(_)) => Err(Frame {
                bounds,
                channels,
                pixels: std::cell::UnsafeCell::new(other),
                top_down,
                premultiplied,
                par,
            }),
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

    /// Every sample NaN (floats) or the depth's largest value (integers):
    /// what a pixel no render wrote reads as in a debug build.
    pub fn poison(&mut self) {
        match self.pixels.get_mut() {
            Pixels::U8(v) => v.fill(u8::MAX),
            Pixels::U16(v) => v.fill(u16::MAX),
            Pixels::F32(v) => v.fill(f32::NAN),
            Pixels::Lent(_) => {}
        }
    }

    pub fn depth(&self) -> &'static str {
        // SAFETY: reading the variant only; writers never change it.
        match unsafe { &*self.pixels.get() } {
            Pixels::U8(_) => "OfxBitDepthByte",
            Pixels::U16(_) => "OfxBitDepthShort",
            Pixels::F32(_) | Pixels::Lent(_) => "OfxBitDepthFloat",
        }
    }

    /// The frame as float pixels, bottom-up (after renders have finished).
    pub fn to_image(&self) -> Image {
        // SAFETY: called when no render is writing (see the Sync note).
        let data: Vec<f32> = match unsafe { &*self.pixels.get() } {
            Pixels::U8(v) => v.iter().map(|&x| x as f32 / 255.0).collect(),
            Pixels::U16(v) => v.iter().map(|&x| x as f32 / 65535.0).collect(),
            Pixels::F32(v) => v.clone(),
            Pixels::Lent(lent) => lent.floats().to_vec(),
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
                // Sources only: the plugin reads them (OFX gives sources to read).
                Pixels::Lent(lent) => (4, lent.ptr as *mut c_void),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A lent frame reads the caller's rows in place: the host's image is
    /// the caller's memory, top row last in canonical order.
    #[test]
    fn a_lent_picture_is_read_in_place() {
        let rows: Vec<f32> = (0..2 * 3 * 4).map(|v| v as f32).collect();
        let lent = LentRows {
            width: 3,
            height: 2,
            channels: 4,
            data: &rows,
        };
        let seen = lend(&[lent], |frames| {
            let f = &frames[0];
            let props = f.image_props((1.0, 1.0), 0.0);
            let data = match props.get(&kOfxImagePropData.to_string_lossy()) {
                Some(crate::host::props::Value::P(p)) => p[0],
                other => panic!("no data pointer: {other:?}"),
            };
            // Top-down: the bottom row (canonical y = 0) is the caller's last.
            (
                data == rows[12..].as_ptr() as usize,
                f.to_image().pixel(0, 1).to_vec(),
            )
        })
        .unwrap();
        assert!(seen.0, "the plugin is handed the caller's own bottom row");
        assert_eq!(seen.1, vec![0.0, 1.0, 2.0, 3.0]);
    }

    /// Rows that do not hold the picture they claim are refused, before
    /// any frame is made over them.
    #[test]
    fn rows_of_the_wrong_length_are_refused() {
        let rows = vec![0.0f32; 10];
        let lent = LentRows {
            width: 3,
            height: 2,
            channels: 4,
            data: &rows,
        };
        let err = lend(&[lent], |_| ()).unwrap_err();
        assert!(err.contains("10 floats for 2x3x4"), "{err}");
    }
}
