//! The effect handle, its clips and the images they hand out, as safe types.

use std::ffi::{c_void, CStr, CString};

use morphfx::geom::RectI;
use morphfx::image::{ImageView, Layout, RowsMut, Sample};
use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::message::*;
use openfx::sys::image_effect_v1::param::*;

use super::host::{self, Suites};
use super::params::Params;
use super::props::PropSet;
use super::{check, Failure, Outcome};

#[derive(Clone, Copy)]
pub struct Effect {
    handle: OfxImageEffectHandle,
    suites: Suites,
}

impl Effect {
    pub fn new(handle: *const c_void) -> Outcome<Self> {
        if handle.is_null() {
            return Err(Failure::Status(
                kOfxStatErrBadHandle,
                "null effect handle".into(),
            ));
        }
        Ok(Effect {
            handle: handle as OfxImageEffectHandle,
            suites: host::suites()?,
        })
    }

    pub fn props(&self) -> Outcome<PropSet> {
        let f = self
            .suites
            .effect
            .getPropertySet
            .ok_or_else(|| Failure::Failed("no getPropertySet".into()))?;
        let mut p: OfxPropertySetHandle = std::ptr::null_mut();
        // SAFETY: handle is the host's effect handle for this action; out-pointer live.
        check(unsafe { f(self.handle, &mut p) }, "getPropertySet")?;
        PropSet::new(p)
    }

    pub fn param_set(&self) -> Outcome<OfxParamSetHandle> {
        let f = self
            .suites
            .effect
            .getParamSet
            .ok_or_else(|| Failure::Failed("no getParamSet".into()))?;
        let mut p: OfxParamSetHandle = std::ptr::null_mut();
        // SAFETY: as above.
        check(unsafe { f(self.handle, &mut p) }, "getParamSet")?;
        Ok(p)
    }

    pub fn params(&self) -> Outcome<Params> {
        Params::new(self.param_set()?)
    }

    pub fn define_clip(&self, name: &str) -> Outcome<PropSet> {
        let f = self
            .suites
            .effect
            .clipDefine
            .ok_or_else(|| Failure::Failed("no clipDefine".into()))?;
        let n = CString::new(name).unwrap_or_default();
        let mut p: OfxPropertySetHandle = std::ptr::null_mut();
        // SAFETY: descriptor handle from the host; name NUL-terminated; out-pointer live.
        check(
            unsafe { f(self.handle, n.as_ptr(), &mut p) },
            &format!("defining clip {name}"),
        )?;
        PropSet::new(p)
    }

    pub fn clip(&self, name: &str) -> Outcome<Clip> {
        let f = self
            .suites
            .effect
            .clipGetHandle
            .ok_or_else(|| Failure::Failed("no clipGetHandle".into()))?;
        let n = CString::new(name).unwrap_or_default();
        let mut h: OfxImageClipHandle = std::ptr::null_mut();
        // SAFETY: instance handle from the host; name NUL-terminated; out-pointer live.
        check(
            unsafe { f(self.handle, n.as_ptr(), &mut h, std::ptr::null_mut()) },
            &format!("clip {name}"),
        )?;
        if h.is_null() {
            return Err(Failure::Status(
                kOfxStatErrBadHandle,
                format!("clip {name}: null handle"),
            ));
        }
        Ok(Clip {
            handle: h,
            suites: self.suites,
            name: name.to_owned(),
        })
    }

    /// Whether the host asked us to stop rendering.
    pub fn aborted(&self) -> bool {
        match self.suites.effect.abort {
            // SAFETY: instance handle from the host.
            Some(f) => unsafe { f(self.handle) != 0 },
            None => false,
        }
    }

    /// Posts a message through the host's message suite (if it has one).
    pub fn message(&self, kind: &CStr, id: &CStr, text: &str) {
        let Some(suite) = self.suites.message else {
            return;
        };
        let Some(f) = suite.message else { return };
        let text = CString::new(text.replace('\0', " ")).unwrap_or_default();
        // SAFETY: the host's message function, given our effect handle, a
        // message type and id it knows, and a "%s" format with one C string.
        unsafe {
            f(
                self.handle as *mut c_void,
                kind.as_ptr(),
                id.as_ptr(),
                c"%s".as_ptr(),
                text.as_ptr(),
            );
        }
    }

    pub fn error(&self, id: &CStr, text: &str) {
        self.message(kOfxMessageError, id, text);
    }

    /// Sets the node's persistent error (message suite v2), which stays on
    /// the node until [`Effect::clear_persistent`]. False when the host has
    /// no v2 suite (the caller then posts a transient message).
    pub fn persistent_error(&self, id: &CStr, text: &str) -> bool {
        let Some(f) = self.suites.message_v2.and_then(|s| s.setPersistentMessage) else {
            return false;
        };
        let text = CString::new(text.replace('\0', " ")).unwrap_or_default();
        // SAFETY: the host's function, given our instance handle, a message
        // type and id it knows, and a "%s" format with one C string.
        let status = unsafe {
            f(
                self.handle as *mut c_void,
                kOfxMessageError.as_ptr(),
                id.as_ptr(),
                c"%s".as_ptr(),
                text.as_ptr(),
            )
        };
        status == kOfxStatOK
    }

    /// Clears the persistent message set by [`Effect::persistent_error`].
    pub fn clear_persistent(&self) {
        if let Some(f) = self
            .suites
            .message_v2
            .and_then(|s| s.clearPersistentMessage)
        {
            // SAFETY: the host's function, given our instance handle.
            unsafe { f(self.handle as *mut c_void) };
        }
    }
}

#[derive(Clone)]
pub struct Clip {
    handle: OfxImageClipHandle,
    suites: Suites,
    pub name: String,
}

impl Clip {
    pub fn props(&self) -> Outcome<PropSet> {
        let f = self
            .suites
            .effect
            .clipGetPropertySet
            .ok_or_else(|| Failure::Failed("no clipGetPropertySet".into()))?;
        let mut p: OfxPropertySetHandle = std::ptr::null_mut();
        // SAFETY: clip handle from clipGetHandle; out-pointer live.
        check(unsafe { f(self.handle, &mut p) }, "clipGetPropertySet")?;
        PropSet::new(p)
    }

    pub fn is_connected(&self) -> bool {
        self.props()
            .and_then(|p| p.get_int(kOfxImageClipPropConnected, 0))
            .map(|c| c != 0)
            .unwrap_or(false)
    }

    /// Region of definition at `time`, canonical coordinates.
    pub fn rod(&self, time: f64) -> Outcome<OfxRectD> {
        let f = self
            .suites
            .effect
            .clipGetRegionOfDefinition
            .ok_or_else(|| Failure::Failed("no clipGetRegionOfDefinition".into()))?;
        let mut r = OfxRectD {
            x1: 0.0,
            y1: 0.0,
            x2: 0.0,
            y2: 0.0,
        };
        // SAFETY: clip handle from the host; out-pointer live.
        check(
            unsafe { f(self.handle, time, &mut r) },
            &format!("RoD of clip {}", self.name),
        )?;
        Ok(r)
    }

    /// The clip's image at `time`; `None` when the host has none (unconnected
    /// optional clip, or a NULL image).
    pub fn image(&self, time: f64) -> Outcome<Option<HostImage>> {
        let f = self
            .suites
            .effect
            .clipGetImage
            .ok_or_else(|| Failure::Failed("no clipGetImage".into()))?;
        let mut p: OfxPropertySetHandle = std::ptr::null_mut();
        // SAFETY: clip handle from the host; a null region asks for the whole image.
        let status = unsafe { f(self.handle, time, std::ptr::null(), &mut p) };
        if status == kOfxStatFailed || (status == kOfxStatOK && p.is_null()) {
            return Ok(None);
        }
        check(status, &format!("image of clip {} at {time}", self.name))?;
        let img = HostImage {
            props: PropSet::new(p)?,
            suites: self.suites,
            clip: self.name.clone(),
        };
        Ok(Some(img))
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Depth {
    U8,
    U16,
    F32,
}

/// An image the host lent us; released when dropped.
pub struct HostImage {
    props: PropSet,
    suites: Suites,
    clip: String,
}

/// What an image's properties say about its memory.
#[derive(Debug, Clone, Copy)]
pub struct ImageInfo {
    pub data: *mut c_void,
    pub bounds: RectI,
    pub row_bytes: isize,
    pub depth: Depth,
    pub channels: usize,
    pub premultiplied: bool,
    pub par: f64,
    pub render_scale: (f64, f64),
}

impl HostImage {
    pub fn info(&self) -> Outcome<ImageInfo> {
        let p = &self.props;
        let bad = |what: String| Failure::BadInput(format!("clip {}: {what}", self.clip));
        let depth = match p.get_string(kOfxImageEffectPropPixelDepth, 0)?.as_bytes() {
            b"OfxBitDepthByte" => Depth::U8,
            b"OfxBitDepthShort" => Depth::U16,
            b"OfxBitDepthFloat" => Depth::F32,
            other => {
                return Err(bad(format!(
                    "unsupported bit depth {}",
                    String::from_utf8_lossy(other)
                )))
            }
        };
        let channels = match p.get_string(kOfxImageEffectPropComponents, 0)?.as_str() {
            "OfxImageComponentRGBA" => 4,
            "OfxImageComponentRGB" => 3,
            "OfxImageComponentAlpha" => 1,
            other => return Err(bad(format!("unsupported components {other}"))),
        };
        let [x1, y1, x2, y2] = p.get_ints::<4>(kOfxImagePropBounds)?;
        let premult = p
            .get_string(kOfxImageEffectPropPreMultiplication, 0)
            .unwrap_or_default();
        Ok(ImageInfo {
            data: p.get_pointer(kOfxImagePropData, 0)?,
            bounds: RectI::new(x1, y1, x2, y2),
            row_bytes: p.get_int(kOfxImagePropRowBytes, 0)? as isize,
            depth,
            channels,
            premultiplied: premult != "OfxImageUnPreMultiplied",
            par: p
                .get_double(kOfxImagePropPixelAspectRatio, 0)
                .unwrap_or(1.0),
            render_scale: (
                p.get_double(kOfxImageEffectPropRenderScale, 0)
                    .unwrap_or(1.0),
                p.get_double(kOfxImageEffectPropRenderScale, 1)
                    .unwrap_or(1.0),
            ),
        })
    }

    fn checked_layout<T: Sample>(&self, info: &ImageInfo) -> Outcome<()> {
        let size = std::mem::size_of::<T>();
        let bad = |what: &str| Failure::BadInput(format!("clip {}: {what}", self.clip));
        if info.data.is_null() && !info.bounds.is_empty() {
            return Err(bad("image has no pixel data"));
        }
        if info.row_bytes % size as isize != 0
            || !(info.data as usize).is_multiple_of(std::mem::align_of::<T>())
        {
            return Err(bad("image rows are not aligned to its pixel type"));
        }
        let row_len = info.bounds.width() * info.channels * size;
        if info.bounds.height() > 1 && (info.row_bytes.unsigned_abs()) < row_len {
            return Err(bad("image row bytes are smaller than a row"));
        }
        Ok(())
    }

    /// A read-only view over the whole image.
    pub fn view<T: Sample>(&self, info: &ImageInfo) -> Outcome<ImageView<'_, T>> {
        self.checked_layout::<T>(info)?;
        let size = std::mem::size_of::<T>() as isize;
        let (h, row_elems) = (
            info.bounds.height() as isize,
            (info.bounds.width() * info.channels) as isize,
        );
        if h == 0 || row_elems == 0 {
            return ImageView::new(&[], Layout::packed(RectI::default(), info.channels))
                .map_err(Failure::from);
        }
        let stride = info.row_bytes / size;
        let last_row = (h - 1) * stride;
        let (lo, hi) = (last_row.min(0), last_row.max(0) + row_elems);
        // SAFETY: the host guarantees `data` addresses pixel (x1, y1) and that
        // every row y1..y2 at `data + k * rowBytes` holds `width * channels`
        // samples of type T (checked: depth matches T, alignment, row size),
        // valid for reading until clipReleaseImage, which only our Drop calls;
        // the slice borrows `self`, so it cannot outlive the image.
        let data = unsafe {
            std::slice::from_raw_parts((info.data as *const T).offset(lo), (hi - lo) as usize)
        };
        let layout = Layout {
            bounds: info.bounds,
            channels: info.channels,
            base: (-lo) as usize,
            row_stride: stride,
        };
        ImageView::new(data, layout).map_err(Failure::from)
    }

    /// The rows of `window` (clipped to the bounds) for writing.
    pub fn rows_mut<T: Sample>(
        &mut self,
        info: &ImageInfo,
        window: RectI,
    ) -> Outcome<RowsMut<'_, T>> {
        self.checked_layout::<T>(info)?;
        let w = window.intersect(&info.bounds);
        let size = std::mem::size_of::<T>() as isize;
        let stride = info.row_bytes / size;
        let mut rows = Vec::with_capacity(w.height());
        for j in w.y1..w.y2 {
            let offset = (j - info.bounds.y1) as isize * stride
                + (w.x1 - info.bounds.x1) as isize * info.channels as isize;
            // SAFETY: as in `view`, the host's buffer holds every row of the
            // bounds; this row segment covers only the render window's columns
            // of one row, so segments are disjoint from each other and from
            // the windows that other render threads write (OFX render windows
            // of concurrent calls do not overlap). `&mut self` keeps this
            // image's rows from being handed out twice.
            let row = unsafe {
                std::slice::from_raw_parts_mut(
                    (info.data as *mut T).offset(offset),
                    w.width() * info.channels,
                )
            };
            rows.push((j, row));
        }
        Ok(RowsMut {
            bounds: w,
            channels: info.channels,
            rows,
        })
    }
}

impl Drop for HostImage {
    fn drop(&mut self) {
        if let Some(f) = self.suites.effect.clipReleaseImage {
            // SAFETY: the property set is the image handle clipGetImage gave us, released once.
            unsafe {
                f(self.props.handle());
            }
        }
    }
}
