//! ZIP-compressed scanline EXR written directly, blocks deflated in parallel
//! by libdeflate (as OpenEXR 3.2 does since it too moved to it).
//!
//! ZIP is what plates and renders are mostly saved as, and the `exr` crate's
//! deflate (miniz_oxide) made writing the slowest stage of a sequence render:
//! 108 ms a 1080p half frame against 23 ms here (docs/PERFORMANCE.md). The
//! format is OpenEXR's single-part scanline file ("Technical Introduction",
//! "OpenEXR File Layout"); other compressions still go through the `exr`
//! crate, and everything is read back by it (tests hold the two to each
//! other and to OpenImageIO).

use std::io::Write;
use std::path::Path;

use exr::prelude::f16;
use half::slice::HalfFloatSliceExt;
use libdeflater::{CompressionLvl, Compressor};
use rayon::prelude::*;

use crate::error::HostError;
use crate::plate::{rgba, ExrPrecision, Plate};

/// The `compression` attribute's values for the two ZIP flavours.
const ZIPS: u8 = 2;
const ZIP: u8 = 3;

/// Writes `plate` as RGBA at `precision`, ZIP-compressed in blocks of
/// `lines` scan lines (1: ZIPS, 16: ZIP). An error says what failed; the
/// caller names the file (`io::write_as`, which writes a temporary one).
pub fn write(
    path: &Path,
    plate: &Plate,
    precision: ExrPrecision,
    lines: usize,
) -> Result<(), HostError> {
    let img = &plate.image;
    let (w, h) = (img.width(), img.height());
    let b = img.bounds;
    let (ox, oy) = plate.origin;
    let y_min = oy + plate.size.1 as i32 - b.y2;
    let x_min = ox + b.x1;
    let header = header(
        precision,
        if lines == 1 { ZIPS } else { ZIP },
        [x_min, y_min, x_min + w as i32 - 1, y_min + h as i32 - 1],
        [
            ox,
            oy,
            ox + plate.size.0 as i32 - 1,
            oy + plate.size.1 as i32 - 1,
        ],
    );
    let starts: Vec<usize> = (0..h).step_by(lines.max(1)).collect();
    let chunks: Vec<Vec<u8>> = starts
        .par_iter()
        .map_init(
            || Compressor::new(CompressionLvl::new(4).unwrap_or_default()),
            |deflate, &top| {
                let rows = top..(top + lines).min(h);
                let raw = block(plate, rows, precision);
                let packed = zip(deflate, &raw);
                let y = y_min + top as i32;
                let mut chunk = Vec::with_capacity(8 + packed.len());
                chunk.extend_from_slice(&y.to_le_bytes());
                chunk.extend_from_slice(&(packed.len() as i32).to_le_bytes());
                chunk.extend_from_slice(&packed);
                chunk
            },
        )
        .collect();
    let err = |e: std::io::Error| HostError::failed(format!("cannot write EXR: {e}"));
    let mut file = std::io::BufWriter::new(std::fs::File::create(path).map_err(err)?);
    file.write_all(&header).map_err(err)?;
    // The offset table: where each block starts in the file.
    let mut at = (header.len() + 8 * chunks.len()) as u64;
    for c in &chunks {
        file.write_all(&at.to_le_bytes()).map_err(err)?;
        at += c.len() as u64;
    }
    for c in &chunks {
        file.write_all(c).map_err(err)?;
    }
    file.flush().map_err(err)
}

/// Magic number, version 2 (single-part scanline) and the header's
/// attributes, ending in a zero byte.
fn header(precision: ExrPrecision, compression: u8, data: [i32; 4], display: [i32; 4]) -> Vec<u8> {
    let mut h = Vec::new();
    h.extend_from_slice(&20000630i32.to_le_bytes());
    h.extend_from_slice(&2i32.to_le_bytes());
    let pixel_type: i32 = match precision {
        ExrPrecision::Half => 1,
        ExrPrecision::Float => 2,
    };
    let mut channels = Vec::new();
    for name in ["A", "B", "G", "R"] {
        channels.extend_from_slice(name.as_bytes());
        channels.push(0);
        channels.extend_from_slice(&pixel_type.to_le_bytes());
        channels.extend_from_slice(&[0, 0, 0, 0]); // pLinear, reserved
        channels.extend_from_slice(&1i32.to_le_bytes()); // x sampling
        channels.extend_from_slice(&1i32.to_le_bytes()); // y sampling
    }
    channels.push(0);
    let boxed = |b: [i32; 4]| b.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>();
    let attributes: [(&str, &str, Vec<u8>); 8] = [
        ("channels", "chlist", channels),
        ("compression", "compression", vec![compression]),
        ("dataWindow", "box2i", boxed(data)),
        ("displayWindow", "box2i", boxed(display)),
        ("lineOrder", "lineOrder", vec![0]),
        ("pixelAspectRatio", "float", 1f32.to_le_bytes().to_vec()),
        (
            "screenWindowCenter",
            "v2f",
            [0f32.to_le_bytes(), 0f32.to_le_bytes()].concat(),
        ),
        ("screenWindowWidth", "float", 1f32.to_le_bytes().to_vec()),
    ];
    for (name, kind, value) in attributes {
        h.extend_from_slice(name.as_bytes());
        h.push(0);
        h.extend_from_slice(kind.as_bytes());
        h.push(0);
        h.extend_from_slice(&(value.len() as i32).to_le_bytes());
        h.extend_from_slice(&value);
    }
    h.push(0);
    h
}

/// The scan lines `rows` (from the top) as the file stores them: line by
/// line, each channel's samples in turn (A, B, G, R), little-endian.
fn block(plate: &Plate, rows: std::ops::Range<usize>, precision: ExrPrecision) -> Vec<u8> {
    let img = &plate.image;
    let (w, h, c) = (img.width(), img.height(), img.channels);
    let size = match precision {
        ExrPrecision::Half => 2,
        ExrPrecision::Float => 4,
    };
    let mut out = Vec::with_capacity(rows.len() * w * 4 * size);
    // One channel of one row at a time, so the half conversion runs over a
    // slice (F16C, eight samples an instruction) instead of sample by sample.
    let mut lane = vec![0f32; w];
    let mut halves = vec![f16::ZERO; w];
    for row in rows {
        let j = h - 1 - row;
        let line = &img.data[j * w * c..(j + 1) * w * c];
        // A, B, G, R, each pixel as every writer makes it RGBA.
        for channel in [3usize, 2, 1, 0] {
            if c == 4 {
                for (d, px) in lane.iter_mut().zip(line.chunks_exact(4)) {
                    *d = px[channel];
                }
            } else {
                for (d, px) in lane.iter_mut().zip(line.chunks_exact(c)) {
                    *d = rgba(px)[channel];
                }
            }
            match precision {
                ExrPrecision::Half => {
                    halves.convert_from_f32_slice(&lane);
                    out.extend(halves.iter().flat_map(|v| v.to_le_bytes()));
                }
                ExrPrecision::Float => out.extend(lane.iter().flat_map(|v| v.to_le_bytes())),
            }
        }
    }
    out
}

/// OpenEXR's ZIP: bytes split into even and odd halves, each byte stored as
/// its difference from the one before, then deflated (zlib format); stored
/// raw when that would not be smaller, as the format allows.
fn zip(deflate: &mut Compressor, raw: &[u8]) -> Vec<u8> {
    let half = raw.len().div_ceil(2);
    let mut t = vec![0u8; raw.len()];
    let (even, odd) = t.split_at_mut(half);
    for (k, pair) in raw.chunks(2).enumerate() {
        even[k] = pair[0];
        if let Some(&b) = pair.get(1) {
            odd[k] = b;
        }
    }
    let mut p = t.first().copied().unwrap_or(0);
    for v in t.iter_mut().skip(1) {
        let d = (*v as i32 - p as i32 + 128 + 256) as u8;
        p = *v;
        *v = d;
    }
    let mut packed = vec![0u8; deflate.zlib_compress_bound(t.len())];
    match deflate.zlib_compress(&t, &mut packed) {
        Ok(n) if n < raw.len() => {
            packed.truncate(n);
            packed
        }
        _ => raw.to_vec(),
    }
}

#[cfg(test)]
mod tests {
    use morphfx::geom::RectI;
    use morphfx::image::Image;

    use super::*;
    use crate::io;

    /// A plate of `channels` whose data window (canonical `bounds`) lies
    /// inside a 40 × 30 display window whose corner is at (3, -2) in the
    /// file; values with every bit pattern a half cannot round away.
    fn plate(channels: usize, bounds: RectI) -> Plate {
        let image = Image::from_fn(bounds, channels, |i, j, c| {
            ((i * 7 + j * 13 + c as i32 * 5) as f32 * 0.173).sin() * 3.0
        });
        Plate {
            image,
            size: (40, 30),
            origin: (3, -2),
        }
    }

    /// What a reader should find: RGBA as `io::write` has always made it
    /// (one channel in all four, RGB opaque), values as stored at
    /// `precision`.
    fn expected(p: &Plate, precision: ExrPrecision) -> Image {
        let img = &p.image;
        let round = |v: f32| match precision {
            ExrPrecision::Half => f16::from_f32(v).to_f32(),
            ExrPrecision::Float => v,
        };
        Image::from_fn(img.bounds, 4, |i, j, c| {
            let px = img.pixel(i, j);
            round(match (img.channels, c) {
                (1, _) => px[0],
                (3, 3) => 1.0,
                (_, c) => px[c],
            })
        })
    }

    #[test]
    fn the_exr_crate_reads_back_what_we_wrote_for_both_zips_precisions_and_layouts() {
        let dir = std::env::temp_dir().join(format!("morphfx-exr-zip-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for lines in [1, 16] {
            for precision in [ExrPrecision::Half, ExrPrecision::Float] {
                for channels in [1, 3, 4] {
                    // 37 × 21 rows: the last ZIP block is short.
                    let p = plate(channels, RectI::new(-2, 5, 35, 26));
                    let path = dir.join(format!("z{lines}_{channels}_{precision:?}.exr"));
                    write(&path, &p, precision, lines).unwrap();
                    let back = io::read(&path).unwrap();
                    let at = format!("{lines} lines, {channels} channels, {precision:?}");
                    assert_eq!((back.size, back.origin), ((40, 30), (3, -2)), "{at}");
                    assert_eq!(back.image, expected(&p, precision), "{at}");
                    let header = io::probe(&path).unwrap();
                    let zip = if lines == 1 {
                        exr::prelude::Compression::ZIP1
                    } else {
                        exr::prelude::Compression::ZIP16
                    };
                    assert_eq!(header.compression, Some(zip), "{at}");
                }
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn incompressible_blocks_are_stored_raw_and_still_read() {
        // Noise does not deflate below its size: the block goes in raw.
        let noise = Image::from_fn(RectI::from_size(16, 4), 4, |i, j, c| {
            let mut x = 0x2545_f491_4f6c_dd1du64 ^ ((i * 131 + j * 7 + c as i32) as u64) << 20;
            for _ in 0..3 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
            }
            f32::from_bits(0x3f80_0000 | (x as u32 >> 9))
        });
        let p = Plate::new(noise, (16, 4));
        let path = std::env::temp_dir().join(format!("morphfx-noise-{}.exr", std::process::id()));
        write(&path, &p, ExrPrecision::Float, 16).unwrap();
        assert_eq!(io::read(&path).unwrap().image, p.image);
        let _ = std::fs::remove_file(&path);
    }
}
