//! Frame IO. EXR is read and written at full precision (half or float), as
//! linear light, premultiplied. PNG, JPEG and TIFF with 8- or 16-bit samples
//! hold straight sRGB code values: they are decoded to linear and
//! premultiplied on read, and PNG and TIFF are unpremultiplied and encoded
//! to sRGB on write, as a compositor's Read and Write nodes do, unless the
//! caller asks for the raw code values ([`Colour::Raw`], both ways as they
//! are); float TIFF is linear already.
//! Outputs go to a temporary name and are renamed when complete.

use std::path::Path;

use exr::prelude::*;
use half::slice::HalfFloatSliceExt;
use morphfx::geom::RectI;
use morphfx::image::Image;
use rayon::prelude::*;

use crate::error::HostError;
use crate::plate::rgba;
pub use crate::plate::{ExrPrecision, Plate};

/// An image file's display window, from its header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DisplayWindow {
    pub size: (usize, usize),
    /// As [`Plate::origin`].
    pub origin: (i32, i32),
}

/// What 8- and 16-bit PNG, JPEG and TIFF samples are taken to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Colour {
    /// sRGB-encoded: decoded to linear light on read, encoded on write.
    #[default]
    Srgb,
    /// Code values kept as they are (`--raw`).
    Raw,
}

/// The sRGB decoding of a code value in `[0, 1]` (IEC 61966-2-1).
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB encoding of linear light, for `[0, 1]`.
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.0031308 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// A plate, 8- and 16-bit formats decoded from sRGB.
pub fn read(path: &Path) -> std::result::Result<Plate, HostError> {
    read_as(path, Colour::Srgb)
}

/// A plate, 8- and 16-bit formats read as `colour` says.
pub fn read_as(path: &Path, colour: Colour) -> std::result::Result<Plate, HostError> {
    if !path.exists() {
        return Err(HostError::bad(format!("{}: no such file", path.display())));
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext == "exr" {
        read_exr(path)
    } else {
        read_other(path, colour)
    }
}

/// What an image file's header says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Header {
    /// The pixel bounds (the data window, canonical).
    pub bounds: RectI,
    pub window: DisplayWindow,
    /// Every channel is half float (an EXR written at half precision).
    pub half: bool,
    /// The file has an alpha channel (without one, alpha reads as 1).
    pub alpha: bool,
    /// How an EXR's pixels are compressed (`None`: not an EXR).
    pub compression: Option<Compression>,
}

/// The most pixels a plate may have: 16384 × 16384 (4 GiB as the float
/// RGBA the render works in). A header asking for more is refused before any
/// pixel is read, whatever the file's size: a corrupt or hostile header
/// must not make the process ask for memory it cannot have.
pub const MAX_PIXELS: usize = 1 << 28;

fn check_size(
    path: &Path,
    what: &str,
    (w, h): (usize, usize),
) -> std::result::Result<(), HostError> {
    if w.saturating_mul(h) > MAX_PIXELS {
        return Err(HostError::bad(format!(
            "{}: its {what} is {w}x{h} pixels, over morphfx's limit of \
                {MAX_PIXELS} pixels (16384x16384) a plate",
            path.display()
        )));
    }
    Ok(())
}

/// A zeroed image, or a clear error where memory for it cannot be had.
fn image_buffer(
    path: &Path,
    bounds: RectI,
    channels: usize,
) -> std::result::Result<Image, HostError> {
    let n = bounds.area().saturating_mul(channels);
    let mut data = Vec::new();
    data.try_reserve_exact(n).map_err(|_| {
        HostError::failed(format!(
            "{}: not enough memory for its {}x{} pixels",
            path.display(),
            bounds.width(),
            bounds.height()
        ))
    })?;
    data.resize(n, 0.0);
    Ok(Image {
        bounds,
        channels,
        data,
    })
}

/// An image file's header only (for checking a whole sequence before
/// rendering without reading it twice), its sizes checked.
pub fn probe(path: &Path) -> std::result::Result<Header, HostError> {
    let header = probe_unchecked(path)?;
    check_size(
        path,
        "data window",
        (header.bounds.width(), header.bounds.height()),
    )?;
    check_size(path, "display window", header.window.size)?;
    Ok(header)
}

fn probe_unchecked(path: &Path) -> std::result::Result<Header, HostError> {
    if !path.exists() {
        return Err(HostError::bad(format!("{}: no such file", path.display())));
    }
    let is_exr = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if !is_exr {
        use ::image::ImageDecoder;
        let cannot = |e: &dyn std::fmt::Display| {
            HostError::bad(format!("{}: cannot read image: {e}", path.display()))
        };
        let decoder = ::image::ImageReader::open(path)
            .map_err(|e| cannot(&e))?
            .with_guessed_format()
            .map_err(|e| cannot(&e))?
            .into_decoder()
            .map_err(|e| cannot(&e))?;
        let (w, h) = decoder.dimensions();
        let (w, h) = (w as usize, h as usize);
        let alpha = decoder.color_type().has_alpha();
        let window = DisplayWindow {
            size: (w, h),
            origin: (0, 0),
        };
        return Ok(Header {
            bounds: RectI::from_size(w, h),
            window,
            half: false,
            alpha,
            compression: None,
        });
    }
    let meta = read_exr_meta(path)?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| HostError::bad(format!("{}: EXR has no layers", path.display())))?;
    let display = header.shared_attributes.display_window;
    let pos = header.own_attributes.layer_position;
    let (w, h) = (header.layer_size.width(), header.layer_size.height());
    let window = DisplayWindow {
        size: (display.size.width(), display.size.height()),
        origin: (display.position.x(), display.position.y()),
    };
    let half = header
        .channels
        .list
        .iter()
        .all(|c| c.sample_type == exr::meta::attribute::SampleType::F16);
    let alpha = header.channels.list.iter().any(|c| is_alpha(&c.name));
    Ok(Header {
        bounds: data_bounds(display, pos, (w, h)),
        window,
        half,
        alpha,
        compression: Some(header.compression),
    })
}

/// Counts the bytes a reader hands on: where an EXR's headers end.
struct Counted<R> {
    inner: R,
    read: u64,
}

impl<R: std::io::Read> std::io::Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read += n as u64;
        Ok(n)
    }
}

/// An EXR's headers, and its chunk table checked against the file's length:
/// a file cut short (a copy that stopped, a full disk) is refused here, from
/// its header, before anything is rendered or written, rather than when its
/// pixels are decoded frames later. Damage inside the pixels themselves
/// still surfaces only when they are decoded.
fn read_exr_meta(path: &Path) -> std::result::Result<exr::meta::MetaData, HostError> {
    use std::io::{Read, Seek, SeekFrom};
    let io_error = |e: std::io::Error| exr_read_error(path, e.into());
    let file = std::fs::File::open(path).map_err(io_error)?;
    let length = file.metadata().map_err(io_error)?.len();
    let mut counted = Counted {
        inner: std::io::BufReader::new(file),
        read: 0,
    };
    let meta = exr::meta::MetaData::read_from_buffered(&mut counted, false)
        .map_err(|e| exr_read_error(path, e))?;
    if meta.headers.iter().any(|h| h.deep) {
        return Ok(meta); // refused later, by the reader that skips deep data
    }
    // A header too large to render is named as such, not as cut short.
    if let Some(h) = meta.headers.first() {
        let display = h.shared_attributes.display_window.size;
        check_size(
            path,
            "data window",
            (h.layer_size.width(), h.layer_size.height()),
        )?;
        check_size(path, "display window", (display.width(), display.height()))?;
    }
    // The offset tables follow the headers: one u64 per chunk.
    let chunks: u64 = meta.headers.iter().map(|h| h.chunk_count as u64).sum();
    let table_end = counted.read.saturating_add(chunks.saturating_mul(8));
    let cut = |what: String| {
        HostError::bad(format!(
            "{}: cannot read EXR: the file ends before its header or \
                pixels do: it is truncated ({what}; the file has {length} \
                bytes)",
            path.display()
        ))
    };
    if table_end > length {
        return Err(cut(format!("its chunk table ends at byte {table_end}")));
    }
    let mut table = vec![0u8; (chunks * 8) as usize];
    counted.read_exact(&mut table).map_err(io_error)?;
    let last = table
        .chunks_exact(8)
        .map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
        .max()
        .unwrap_or(0);
    // Every chunk opens with its position (a part number first in a
    // multi-part file; four tile numbers for tiles, one line for scan
    // lines), then its byte count.
    let part = if meta.requirements.has_multiple_layers {
        4
    } else {
        0
    };
    let place = |h: &exr::meta::header::Header| match h.blocks {
        exr::meta::BlockDescription::ScanLines => 4,
        exr::meta::BlockDescription::Tiles(_) => 16,
    };
    let first = place(&meta.headers[0]);
    if meta.headers.iter().any(|h| place(h) != first) {
        // Parts of both kinds: which one the last chunk belongs to decides
        // where its size lies; the decoder checks it.
        return Ok(meta);
    }
    let lead = part + first;
    // Where the pixels could reach at most, had nothing been cut.
    let room: u64 = meta
        .headers
        .iter()
        .map(|h| h.max_pixel_file_bytes() as u64)
        .sum();
    if last < table_end || last > table_end.saturating_add(room.saturating_mul(2)) {
        // An offset into the header, or beyond any such file: corrupt,
        // and the reader names it.
        return Ok(meta);
    }
    if last.saturating_add(lead + 4) > length {
        return Err(cut(format!("its last chunk starts at byte {last}")));
    }
    let mut reader = counted.inner;
    let mut size = [0u8; 4];
    reader
        .seek(SeekFrom::Start(last + lead))
        .and_then(|_| reader.read_exact(&mut size))
        .map_err(io_error)?;
    let end = last + lead + 4 + u64::from(i32::from_le_bytes(size).max(0) as u32);
    if end > length {
        return Err(cut(format!("its last chunk ends at byte {end}")));
    }
    Ok(meta)
}

/// Whether EXR channel `name` is `what` (`R`, `alpha`, ...), alone or as
/// the last part of a layer's name (`beauty.A`).
fn channel_is(name: &exr::meta::attribute::Text, what: &str) -> bool {
    name.eq_case_insensitive(what) || name.to_string().ends_with(&format!(".{what}"))
}

fn is_alpha(name: &exr::meta::attribute::Text) -> bool {
    channel_is(name, "A") || channel_is(name, "alpha")
}

/// An EXR data window in canonical pixels: EXR y grows downwards, canonical y
/// upwards from the display window's bottom.
pub(crate) fn data_bounds(
    display: exr::meta::attribute::IntegerBounds,
    pos: exr::math::Vec2<i32>,
    (w, h): (usize, usize),
) -> RectI {
    let (dx, dy_top) = (display.position.x(), display.position.y());
    let dh = display.size.height() as i32;
    RectI::new(
        pos.x() - dx,
        dy_top + dh - (pos.y() + h as i32),
        pos.x() - dx + w as i32,
        dy_top + dh - pos.y(),
    )
}

/// What went wrong reading an EXR, in words a user can act on (the exr
/// crate's own say "reference to missing bytes" for a cut-short file).
pub(crate) fn exr_read_error(path: &Path, e: exr::error::Error) -> HostError {
    use exr::error::Error;
    use std::io::ErrorKind;
    let truncated = match &e {
        Error::Invalid(m) => m.contains("missing bytes"),
        Error::Io(io) => io.kind() == ErrorKind::UnexpectedEof,
        _ => false,
    };
    let what = match e {
        _ if truncated => {
            "the file ends before its header or pixels do: it is truncated".to_string()
        }
        Error::Invalid(m) => format!("the file is corrupt: {m}"),
        Error::Io(io) if io.kind() == ErrorKind::InvalidInput => {
            format!("the file is corrupt: an offset in it points outside it ({io})")
        }
        Error::NotSupported(m) => format!("it uses what morphfx cannot read: {m}"),
        other => other.to_string(),
    };
    HostError::bad(format!("{}: cannot read EXR: {what}", path.display()))
}

fn read_exr(path: &Path) -> std::result::Result<Plate, HostError> {
    probe(path)?;
    let img = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| exr_read_error(path, e))?;
    let display = img.attributes.display_window;
    let layer = &img.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    let pos = layer.attributes.layer_position;
    let find = |names: &[&str]| {
        layer
            .channel_data
            .list
            .iter()
            .position(|c| names.iter().any(|n| channel_is(&c.name, n)))
    };
    let (r, g, b, a, y) = (
        find(&["R", "red"]),
        find(&["G", "green"]),
        find(&["B", "blue"]),
        find(&["A", "alpha"]),
        find(&["Y"]),
    );
    // Map channels: RGB(A) as they are; Y as grey; otherwise the first channels in order.
    let list = &layer.channel_data.list;
    let picks: Vec<Option<usize>> = match (r, g, b, y) {
        (Some(r), Some(g), Some(b), _) => vec![Some(r), Some(g), Some(b), a],
        (_, _, _, Some(y)) => vec![Some(y), Some(y), Some(y), a],
        _ if list.len() == 1 => vec![Some(0), Some(0), Some(0), None],
        _ => (0..4).map(|k| (k < list.len()).then_some(k)).collect(),
    };
    let bounds = data_bounds(display, pos, (w, h));
    let mut image = image_buffer(path, bounds, 4)?;
    let sources: Vec<Option<&FlatSamples>> = picks
        .iter()
        .map(|pick| pick.map(|k| &list[k].sample_data))
        .collect();
    // Rows in parallel: the file's rows run top-down, ours bottom-up. A
    // channel's row is made floats in one slice conversion (F16C for
    // halves), then spread into the pixels.
    image
        .data
        .par_chunks_mut((w * 4).max(1))
        .enumerate()
        .for_each_init(
            || vec![0f32; w],
            |lane, (j, out)| {
                let first = (h - 1 - j) * w;
                for (c, source) in sources.iter().enumerate() {
                    match source {
                        Some(FlatSamples::F16(v)) => v[first..first + w].convert_to_f32_slice(lane),
                        Some(FlatSamples::F32(v)) => lane.copy_from_slice(&v[first..first + w]),
                        Some(FlatSamples::U32(v)) => lane
                            .iter_mut()
                            .zip(&v[first..first + w])
                            .for_each(|(d, s)| *d = *s as f32),
                        None => lane.fill(1.0),
                    }
                    for (px, s) in out.chunks_exact_mut(4).zip(lane.iter()) {
                        px[c] = *s;
                    }
                }
            },
        );
    Ok(Plate {
        image,
        size: (display.size.width(), display.size.height()),
        origin: (display.position.x(), display.position.y()),
    })
}

fn read_other(path: &Path, colour: Colour) -> std::result::Result<Plate, HostError> {
    probe(path)?;
    let img = ::image::open(path)
        .map_err(|e| HostError::bad(format!("{}: cannot read image: {e}", path.display())))?;
    let float = matches!(
        img.color(),
        ::image::ColorType::Rgb32F | ::image::ColorType::Rgba32F
    );
    let decode = colour == Colour::Srgb && !float;
    let mut rgba = img.to_rgba32f();
    if decode {
        // PNG, JPEG and 8/16-bit TIFF hold straight colour; the render
        // works premultiplied, as EXR stores it.
        for p in rgba.pixels_mut() {
            let a = p.0[3];
            for c in &mut p.0[..3] {
                *c = srgb_to_linear(*c) * a;
            }
        }
    }
    let (w, h) = (rgba.width() as usize, rgba.height() as usize);
    let mut image = image_buffer(path, RectI::from_size(w, h), 4)?;
    for (x, yr, p) in rgba.enumerate_pixels() {
        let j = h - 1 - yr as usize;
        let k = (j * w + x as usize) * 4;
        image.data[k..k + 4].copy_from_slice(&p.0);
    }
    Ok(Plate::new(image, (w, h)))
}

/// How an output file is written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputFormat {
    /// EXR sample type.
    pub precision: ExrPrecision,
    /// EXR compression.
    pub compression: Compression,
    /// PNG, JPEG and TIFF: sRGB-encoded or raw code values.
    pub colour: Colour,
}

impl OutputFormat {
    /// `precision`, ZIP (16-line blocks), sRGB for 8-bit formats.
    pub fn new(precision: ExrPrecision) -> Self {
        OutputFormat {
            precision,
            compression: Compression::ZIP16,
            colour: Colour::Srgb,
        }
    }
}

/// The compressions `--compression` names, OpenImageIO's names.
pub const COMPRESSIONS: [(&str, Compression); 9] = [
    ("none", Compression::Uncompressed),
    ("rle", Compression::RLE),
    ("zips", Compression::ZIP1),
    ("zip", Compression::ZIP16),
    ("piz", Compression::PIZ),
    ("pxr24", Compression::PXR24),
    ("b44", Compression::B44),
    ("dwaa", Compression::DWAA(None)),
    ("dwab", Compression::DWAB(None)),
];

/// The compression named `name` (see [`COMPRESSIONS`]).
pub fn compression_named(name: &str) -> Option<Compression> {
    COMPRESSIONS
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, c)| *c)
}

/// Writes `plate` at `precision`, ZIP-compressed; see [`write_as`].
pub fn write(
    path: &Path,
    plate: &Plate,
    precision: ExrPrecision,
) -> std::result::Result<(), HostError> {
    write_as(path, plate, OutputFormat::new(precision))
}

/// Writes `plate` (RGBA, or fewer channels) to `path` atomically: a temporary
/// file in the same folder, renamed over the final name only when complete.
pub fn write_as(
    path: &Path,
    plate: &Plate,
    format: OutputFormat,
) -> std::result::Result<(), HostError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if !matches!(
        ext.as_str(),
        "exr" | "png" | "tif" | "tiff" | "jpg" | "jpeg"
    ) {
        return Err(HostError::bad(format!(
            "{}: unknown output format (use .exr or .png)",
            path.display()
        )));
    }
    write_atomically(path, |tmp| match ext.as_str() {
        "exr" => write_exr(tmp, plate, format),
        _ => write_other(tmp, plate, &ext, format.colour),
    })
}

/// Runs `write` on a temporary file in `path`'s folder (made if need be),
/// then renames it over `path`: a reader never sees half a file, and a
/// failed write leaves whatever stood there before.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> std::result::Result<(), HostError>,
) -> std::result::Result<(), HostError> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)
        .map_err(|e| HostError::bad(format!("{}: cannot create folder: {e}", dir.display())))?;
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("out");
    let tmp = dir.join(format!(".{name}.partial-{}", std::process::id()));
    let result = write(&tmp).and_then(|_| {
        std::fs::rename(&tmp, path)
            .map_err(|e| HostError::failed(format!("cannot rename it into place: {e}")))
    });
    result.map_err(|cause| {
        let _ = std::fs::remove_file(&tmp);
        // Said of the name the user asked for (the temporary one means
        // nothing to them); whatever stood under it before stands still.
        HostError::bad(format!(
            "{}: not written: {}",
            path.display(),
            cause.message
        ))
    })
}

fn rgba_at(plate: &Plate, x: usize, row_from_top: usize) -> [f32; 4] {
    let img = &plate.image;
    let (w, h, c) = (img.width(), img.height(), img.channels);
    let k = ((h - 1 - row_from_top) * w + x) * c;
    rgba(&img.data[k..k + c])
}

fn write_exr(
    path: &Path,
    plate: &Plate,
    format: OutputFormat,
) -> std::result::Result<(), HostError> {
    match format.compression {
        Compression::ZIP16 => return crate::exr_zip::write(path, plate, format.precision, 16),
        Compression::ZIP1 => return crate::exr_zip::write(path, plate, format.precision, 1),
        _ => {}
    }
    let img = &plate.image;
    let (w, h) = (img.width(), img.height());
    let b = img.bounds;
    let dh = plate.size.1 as i32;
    // Scan lines, as compositing packages write and read fastest.
    let encoding = Encoding {
        compression: format.compression,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let err = |e: exr::error::Error| HostError::failed(format!("cannot write EXR: {e}"));
    let (ox, oy) = plate.origin;
    let position = Vec2(ox + b.x1, oy + dh - b.y2);
    let display = IntegerBounds::new(Vec2(ox, oy), Vec2(plate.size.0, plate.size.1));
    let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = ["R", "G", "B", "A"]
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let samples = match format.precision {
                ExrPrecision::Float => FlatSamples::F32(channel(plate, c, |v| v)),
                ExrPrecision::Half => FlatSamples::F16(channel(plate, c, f16::from_f32)),
            };
            AnyChannel::new(*name, samples)
        })
        .collect();
    let mut layer = Layer::new(
        Vec2(w, h),
        LayerAttributes::default(),
        encoding,
        AnyChannels::sort(channels),
    );
    layer.attributes.layer_position = position;
    let mut image = exr::prelude::Image::from_layer(layer);
    image.attributes.display_window = display;
    image.write().to_file(path).map_err(err)
}

/// Channel `c` (R, G, B, A; A is 1 where the plate has none) of `plate` in
/// the file's row order (top-down), converted by `convert`; rows in parallel.
fn channel<T: Send + Default + Clone>(
    plate: &Plate,
    c: usize,
    convert: impl Fn(f32) -> T + Sync,
) -> Vec<T> {
    let img = &plate.image;
    let (w, h) = (img.width(), img.height());
    let mut out = vec![T::default(); w * h];
    out.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(row, dst)| {
            for (x, d) in dst.iter_mut().enumerate() {
                *d = convert(rgba_at(plate, x, row)[c]);
            }
        });
    out
}

fn write_other(
    path: &Path,
    plate: &Plate,
    ext: &str,
    colour: Colour,
) -> std::result::Result<(), HostError> {
    let img = &plate.image;
    let (w, h) = (img.width(), img.height());
    let mut out = ::image::RgbaImage::new(w as u32, h as u32);
    let code = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    // PNG and TIFF hold straight colour (their convention, and what hosts'
    // writers store): the premultiplied render is divided by its alpha.
    // JPEG has no alpha: its colour stays premultiplied, the picture over
    // black.
    let straight = ext != "jpg" && ext != "jpeg";
    for (x, y, p) in out.enumerate_pixels_mut() {
        let mut v = rgba_at(plate, x as usize, y as usize);
        if colour == Colour::Srgb && straight && v[3] > 0.0 && v[3] < 1.0 {
            let a = v[3];
            for c in &mut v[..3] {
                *c /= a;
            }
        }
        p.0 = match colour {
            Colour::Srgb => [
                code(linear_to_srgb(v[0])),
                code(linear_to_srgb(v[1])),
                code(linear_to_srgb(v[2])),
                code(v[3]),
            ],
            Colour::Raw => v.map(code),
        };
    }
    let format = match ext {
        "png" => ::image::ImageFormat::Png,
        "jpg" | "jpeg" => ::image::ImageFormat::Jpeg,
        _ => ::image::ImageFormat::Tiff,
    };
    let result = if format == ::image::ImageFormat::Jpeg {
        ::image::DynamicImage::ImageRgba8(out)
            .to_rgb8()
            .save_with_format(path, format)
    } else {
        out.save_with_format(path, format)
    };
    result.map_err(|e| HostError::failed(format!("cannot write: {e}")))
}

/// Writes `text` to `path` atomically: a temporary file in the same
/// folder, renamed over the final name only when whole.
pub fn write_text(path: &Path, text: &str) -> std::result::Result<(), HostError> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("scene");
    let tmp = dir.join(format!(".{name}.partial-{}", std::process::id()));
    std::fs::write(&tmp, text)
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            HostError::bad(format!("{}: cannot write: {e}", path.display()))
        })
}
