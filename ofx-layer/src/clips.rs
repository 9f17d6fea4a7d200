//! The effect handle, its clips and the images they hand out, as safe types.

use std::ffi::{c_void, CStr, CString};

use morphfx::geom::{PixelScale, RectD, RectI, Vec2};
use morphfx::image::{ImageView, Layout, RowsMut, Sample};
use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::message::*;
use openfx::sys::image_effect_v1::param::*;

use super::context::Context;
use super::host::{self, Suites};
use super::params::ParamSet;
use super::planes;
use super::props::PropSet;
use super::{check, Failure, Outcome};

#[derive(Clone, Copy)]
pub struct EffectHandle {
    handle: OfxImageEffectHandle,
    suites: Suites,
}

impl EffectHandle {
    /// The effect behind a host's handle.
    ///
    /// # Safety
    /// `handle` is null (refused) or an image effect handle (descriptor or
    /// instance) the host passed to the current action, valid for as long as
    /// the returned value is used: the host keeps instance handles alive
    /// until destroyInstance and descriptors until unload.
    pub unsafe fn from_raw(handle: *const c_void) -> Outcome<Self> {
        if handle.is_null() {
            return Err(Failure::Status(
                kOfxStatErrBadHandle,
                "null effect handle".into(),
            ));
        }
        Ok(EffectHandle {
            handle: handle as OfxImageEffectHandle,
            suites: host::suites()?,
        })
    }

    /// A handle to no effect, with suites that have no functions: what an
    /// effect's default actions are tested with (they touch no host).
    #[cfg(test)]
    pub(crate) fn unbound() -> EffectHandle {
        use openfx::sys::generic::property::OfxPropertySuiteV1;
        // SAFETY: each suite is a struct of `Option`s of function pointers,
        // for which all-zero bytes are `None`.
        static PROP: OfxPropertySuiteV1 = unsafe { std::mem::zeroed() };
        // SAFETY: as above.
        static EFFECT: OfxImageEffectSuiteV1 = unsafe { std::mem::zeroed() };
        // SAFETY: as above.
        static PARAM: OfxParameterSuiteV1 = unsafe { std::mem::zeroed() };
        EffectHandle {
            handle: std::ptr::null_mut(),
            suites: Suites {
                prop: &PROP,
                effect: &EFFECT,
                param: &PARAM,
                message: None,
                message_v2: None,
                interact: None,
                draw: None,
                progress: None,
                plane: None,
            },
        }
    }

    pub(super) fn props(&self) -> Outcome<PropSet> {
        let f = self
            .suites
            .effect
            .getPropertySet
            .ok_or_else(|| Failure::Failed("no getPropertySet".into()))?;
        let mut p: OfxPropertySetHandle = std::ptr::null_mut();
        // SAFETY: handle is the host's effect handle for this action; out-pointer live.
        check(unsafe { f(self.handle, &mut p) }, "getPropertySet")?;
        // SAFETY: the host just returned it for this effect, which owns it.
        unsafe { PropSet::from_raw(p) }
    }

    /// The context the host made the instance in.
    pub fn context(&self) -> Outcome<Context> {
        let name = self.props()?.get_string(kOfxImageEffectPropContext, 0)?;
        Context::from_host(&name)
    }

    /// The project's images as (origin, size), canonical, when the host
    /// says: the spec's project size placed at the project offset (the
    /// extent is rooted at 0,0 and is not the size).
    pub fn project(&self) -> Option<(Vec2, Vec2)> {
        let p = self.props().ok()?;
        let size = p.get_doubles::<2>(kOfxImageEffectPropProjectSize).ok()?;
        let origin = p
            .get_doubles::<2>(kOfxImageEffectPropProjectOffset)
            .unwrap_or([0.0, 0.0]);
        (size[0] > 0.0 && size[1] > 0.0)
            .then(|| (Vec2::new(origin[0], origin[1]), Vec2::new(size[0], size[1])))
    }

    pub(super) fn param_set(&self) -> Outcome<ParamSet> {
        let f = self
            .suites
            .effect
            .getParamSet
            .ok_or_else(|| Failure::Failed("no getParamSet".into()))?;
        let mut p: OfxParamSetHandle = std::ptr::null_mut();
        // SAFETY: as above.
        check(unsafe { f(self.handle, &mut p) }, "getParamSet")?;
        // SAFETY: the host just returned it for this effect, which owns it.
        unsafe { ParamSet::from_raw(p) }
    }

    pub(super) fn define_clip(&self, name: &str) -> Outcome<PropSet> {
        let f = self
            .suites
            .effect
            .clipDefine
            .ok_or_else(|| Failure::Failed("no clipDefine".into()))?;
        let n = CString::new(name).unwrap_or_default();
        let mut p: OfxPropertySetHandle = std::ptr::null_mut();
        // SAFETY: descriptor handle from the host; name NUL-terminated; out-pointer live.
        let status = unsafe { f(self.handle, n.as_ptr(), &mut p) };
        check(status, &format!("defining clip {name}"))?;
        // SAFETY: the host just returned the clip descriptor's properties.
        unsafe { PropSet::from_raw(p) }
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
        let status = unsafe { f(self.handle, n.as_ptr(), &mut h, std::ptr::null_mut()) };
        check(status, &format!("clip {name}"))?;
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

    /// Opens the host's progress bar for a long task (a no-op without the
    /// progress suite).
    pub fn progress_start(&self, label: &str) {
        let Some(f) = self.suites.progress.and_then(|s| s.progressStart) else {
            return;
        };
        let label = CString::new(label.replace('\0', " ")).unwrap_or_default();
        // SAFETY: the host's function, given our instance handle and a C string.
        unsafe { f(self.handle as *mut c_void, label.as_ptr()) };
    }

    /// Reports `done` in `[0, 1]`; false when the user pressed cancel
    /// (`kOfxStatReplyNo`).
    pub fn progress_update(&self, done: f64) -> bool {
        let Some(f) = self.suites.progress.and_then(|s| s.progressUpdate) else {
            return true;
        };
        // SAFETY: the host's function, given our instance handle.
        unsafe { f(self.handle as *mut c_void, done) != kOfxStatReplyNo }
    }

    /// Closes the progress bar `progress_start` opened.
    pub fn progress_end(&self) {
        if let Some(f) = self.suites.progress.and_then(|s| s.progressEnd) {
            // SAFETY: the host's function, given our instance handle.
            unsafe { f(self.handle as *mut c_void) };
        }
    }

    /// Posts a message through the host's message suite (if it has one).
    fn message(&self, kind: &CStr, id: &CStr, text: &str) {
        let Some(suite) = self.suites.message else {
            return;
        };
        let Some(f) = suite.message else { return };
        let text = super::printf_literal(text);
        // SAFETY: the host's message function, given our effect handle, a
        // message type and id it knows, and a format with no conversion
        // (every `%` doubled), so no variadic argument is read.
        unsafe {
            f(
                self.handle as *mut c_void,
                kind.as_ptr(),
                id.as_ptr(),
                text.as_ptr(),
            );
        }
    }

    /// Posts a warning (message suite), once per call.
    pub fn warning(&self, id: &CStr, text: &str) {
        self.message(kOfxMessageWarning, id, text);
    }

    pub(super) fn error(&self, id: &CStr, text: &str) {
        self.message(kOfxMessageError, id, text);
    }

    /// Sets the node's persistent error (message suite v2), which stays on
    /// the node until [`EffectHandle::clear_persistent`]. False when the host has
    /// no v2 suite (the caller then posts a transient message).
    pub(crate) fn persistent_error(&self, id: &CStr, text: &str) -> bool {
        self.persistent(kOfxMessageError, id, text)
    }

    /// As the persistent error a failed render sets, a warning: something refused
    /// that leaves the node working (hosts show no error badge for it).
    pub fn persistent_warning(&self, id: &CStr, text: &str) -> bool {
        self.persistent(kOfxMessageWarning, id, text)
    }

    fn persistent(&self, kind: &CStr, id: &CStr, text: &str) -> bool {
        let Some(f) = self.suites.message_v2.and_then(|s| s.setPersistentMessage) else {
            return false;
        };
        let text = super::printf_literal(text);
        // SAFETY: the host's function, given our instance handle, a message
        // type and id it knows, and a format with no conversion (every `%`
        // doubled), so no variadic argument is read.
        let status = unsafe {
            f(
                self.handle as *mut c_void,
                kind.as_ptr(),
                id.as_ptr(),
                text.as_ptr(),
            )
        };
        status == kOfxStatOK
    }

    /// Clears the node's persistent message (a failed render's error, or a
    /// [`EffectHandle::persistent_warning`]).
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
    fn props(&self) -> Outcome<PropSet> {
        let f = self
            .suites
            .effect
            .clipGetPropertySet
            .ok_or_else(|| Failure::Failed("no clipGetPropertySet".into()))?;
        let mut p: OfxPropertySetHandle = std::ptr::null_mut();
        // SAFETY: clip handle from clipGetHandle; out-pointer live.
        check(unsafe { f(self.handle, &mut p) }, "clipGetPropertySet")?;
        // SAFETY: the host just returned the clip's properties.
        unsafe { PropSet::from_raw(p) }
    }

    pub fn is_connected(&self) -> bool {
        self.props()
            .and_then(|p| p.get_int(kOfxImageClipPropConnected, 0))
            .map(|c| c != 0)
            .unwrap_or(false)
    }

    /// Whether the clip's colour is straight, not premultiplied by its
    /// alpha (`kOfxImageEffectPropPreMultiplication`); premultiplied where
    /// the host does not say.
    pub fn is_straight(&self) -> bool {
        self.props()
            .and_then(|p| p.get_string(kOfxImageEffectPropPreMultiplication, 0))
            .is_ok_and(|s| s.as_bytes() == kOfxImageUnPreMultiplied.to_bytes())
    }

    /// The frames the clip has images for (`kOfxImageEffectPropFrameRange`),
    /// when the host says.
    pub fn frame_range(&self) -> Option<(f64, f64)> {
        let [a, b] = self
            .props()
            .ok()?
            .get_doubles(kOfxImageEffectPropFrameRange)
            .ok()?;
        (a.is_finite() && b.is_finite() && a <= b).then_some((a, b))
    }

    /// Region of definition at `time`, canonical coordinates.
    pub fn rod(&self, time: f64) -> Outcome<RectD> {
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
        let status = unsafe { f(self.handle, time, &mut r) };
        check(status, &format!("RoD of clip {}", self.name))?;
        Ok(RectD::new(r.x1, r.y1, r.x2, r.y2))
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
        self.lent(status, p, time, planes::COLOUR)
    }

    /// The planes the host says the clip has (multi-planar hosts; colour
    /// alone where it says nothing).
    pub fn planes_present(&self) -> Vec<String> {
        match self
            .props()
            .and_then(|p| p.get_strings(planes::PLANES_PRESENT))
        {
            Ok(planes) if !planes.is_empty() => planes,
            _ => vec![planes::COLOUR.to_owned()],
        }
    }

    /// The clip's image of `plane` at `time`, through the plane suite where
    /// the host is multi-planar (colour too: Natron hands a multi-planar
    /// effect the output's colour buffer only that way), else the colour
    /// as [`Clip::image`]; `None` when the host has none, which the
    /// extension says to take as transparent black.
    pub fn image_plane(&self, time: f64, plane: &str) -> Outcome<Option<HostImage>> {
        let suite = self
            .suites
            .plane
            .and_then(|s| s.clipGetImagePlane)
            .filter(|_| host::multi_planar());
        let Some(f) = suite else {
            if planes::is_colour(plane) {
                return self.image(time);
            }
            return Err(Failure::Failed("the host has no plane suite".into()));
        };
        let name = std::ffi::CString::new(plane)
            .map_err(|_| Failure::Failed(format!("plane {plane:?} has a NUL in its name")))?;
        let mut p: OfxPropertySetHandle = std::ptr::null_mut();
        // SAFETY: clip handle from the host; the plane a NUL-terminated
        // string; a null region asks for the whole image.
        let status = unsafe { f(self.handle, time, name.as_ptr(), std::ptr::null(), &mut p) };
        self.lent(status, p, time, plane)
    }

    /// The image a get-image call lent (`p`), owned so that it is released.
    fn lent(
        &self,
        status: OfxStatus,
        p: OfxPropertySetHandle,
        time: f64,
        plane: &str,
    ) -> Outcome<Option<HostImage>> {
        if status == kOfxStatFailed || (status == kOfxStatOK && p.is_null()) {
            return Ok(None);
        }
        let what = match planes::is_colour(plane) {
            true => format!("image of clip {} at {time}", self.name),
            false => format!(
                "plane {} of clip {} at {time}",
                planes::name_of(plane),
                self.name
            ),
        };
        check(status, &what)?;
        // SAFETY: the host just lent us this image; it stays valid until
        // clipReleaseImage, which only HostImage's Drop calls.
        let props = unsafe { PropSet::from_raw(p)? };
        let mut image = HostImage {
            release: Some((props, self.suites)),
            info: ImageInfo::default(),
            clip: self.name.clone(),
        };
        // Read after the image owns the handle, so a bad property still releases it.
        image.info = image_info(&props, &self.name)?;
        Ok(Some(image))
    }
}

/// A host bit depth.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Depth {
    U8,
    U16,
    F32,
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for u8 {}
    impl Sealed for u16 {}
    impl Sealed for f32 {}
}

/// A sample type a host image can hold, with the bit depth that says so.
/// Sealed: only `u8`, `u16` and `f32` are OFX depths, and [`HostImage`]'s
/// views are sound only for a type whose depth the image's matches.
pub trait HostSample: Sample + sealed::Sealed {
    const DEPTH: Depth;
}
impl HostSample for u8 {
    const DEPTH: Depth = Depth::U8;
}
impl HostSample for u16 {
    const DEPTH: Depth = Depth::U16;
}
impl HostSample for f32 {
    const DEPTH: Depth = Depth::F32;
}

/// An image the host lent us; released when dropped.
pub struct HostImage {
    /// The image's property set and the suites to release it with (`None`
    /// for an image over memory of our own, in tests).
    release: Option<(PropSet, Suites)>,
    /// What the properties said about the memory, read once when lent.
    info: ImageInfo,
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

impl ImageInfo {
    /// Canonical units per pixel: the render scale and the pixel aspect.
    pub fn pixel_scale(&self) -> PixelScale {
        PixelScale::new(self.render_scale.0, self.render_scale.1, self.par)
    }
}

impl Default for ImageInfo {
    fn default() -> Self {
        ImageInfo {
            data: std::ptr::null_mut(),
            bounds: RectI::default(),
            row_bytes: 0,
            depth: Depth::F32,
            channels: 4,
            premultiplied: true,
            par: 1.0,
            render_scale: (1.0, 1.0),
        }
    }
}

/// Reads an image's properties.
fn image_info(p: &PropSet, clip: &str) -> Outcome<ImageInfo> {
    let bad = |what: String| Failure::BadInput(format!("clip {clip}: {what}"));
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
    let components = p.get_string(kOfxImageEffectPropComponents, 0)?;
    let channels = planes::channels_of(&components)
        .ok_or_else(|| bad(format!("unsupported components {components}")))?;
    let [x1, y1, x2, y2] = p.get_ints::<4>(kOfxImagePropBounds)?;
    let premult = p
        .get_string(kOfxImageEffectPropPreMultiplication, 0)
        .unwrap_or_default();
    let scale = |k| {
        p.get_double(kOfxImageEffectPropRenderScale, k)
            .unwrap_or(1.0)
    };
    Ok(ImageInfo {
        data: p.get_pointer(kOfxImagePropData, 0)?,
        bounds: RectI::new(x1, y1, x2, y2),
        row_bytes: p.get_int(kOfxImagePropRowBytes, 0)? as isize,
        depth,
        channels,
        premultiplied: premult.as_bytes() != kOfxImageUnPreMultiplied.to_bytes(),
        par: p
            .get_double(kOfxImagePropPixelAspectRatio, 0)
            .unwrap_or(1.0),
        render_scale: (scale(0), scale(1)),
    })
}

impl HostImage {
    /// An image over memory the caller owns, released by nobody: how tests
    /// exercise the layout checks without a host.
    ///
    /// # Safety
    /// `info.data` addresses `info.bounds` rows of `info.row_bytes` bytes
    /// holding samples of `info.depth`, as a host's image would, valid for
    /// as long as the returned image lives.
    #[cfg(test)]
    pub(crate) unsafe fn over(info: ImageInfo) -> HostImage {
        HostImage {
            release: None,
            info,
            clip: "test".into(),
        }
    }

    /// What the host said about the image.
    pub fn info(&self) -> &ImageInfo {
        &self.info
    }

    /// Refuses a layout that views of `T` could not cover soundly.
    fn checked_layout<T: HostSample>(&self) -> Outcome<()> {
        let info = &self.info;
        let size = std::mem::size_of::<T>();
        let bad = |what: String| Failure::BadInput(format!("clip {}: {what}", self.clip));
        if T::DEPTH != info.depth {
            return Err(Failure::Failed(format!(
                "clip {}: a {:?} image read as {:?} samples",
                self.clip,
                info.depth,
                T::DEPTH
            )));
        }
        if info.data.is_null() && !info.bounds.is_empty() {
            return Err(bad("image has no pixel data".into()));
        }
        if info.row_bytes % size as isize != 0
            || !(info.data as usize).is_multiple_of(std::mem::align_of::<T>())
        {
            return Err(bad("image rows are not aligned to its pixel type".into()));
        }
        let row_len = info.bounds.width() * info.channels * size;
        if info.bounds.height() > 1 && (info.row_bytes.unsigned_abs()) < row_len {
            return Err(bad("image row bytes are smaller than a row".into()));
        }
        Ok(())
    }

    /// A read-only view over the whole image; an error unless `T` is the
    /// image's own sample type.
    pub fn view<T: HostSample>(&self) -> Outcome<ImageView<'_, T>> {
        self.checked_layout::<T>()?;
        let info = &self.info;
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
        // samples of the image's depth, valid for reading until
        // clipReleaseImage, which only our Drop calls. `checked_layout` made
        // sure T is that depth's type, the pointer and stride are aligned to
        // T, and rows do not overlap; the slice borrows `self`, so it cannot
        // outlive the image.
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

    /// The rows of `window` (clipped to the bounds) for writing; an error
    /// unless `T` is the image's own sample type.
    pub fn rows_mut<T: HostSample>(&mut self, window: RectI) -> Outcome<RowsMut<'_, T>> {
        self.checked_layout::<T>()?;
        let info = &self.info;
        let w = window.intersect(&info.bounds);
        let size = std::mem::size_of::<T>() as isize;
        let stride = info.row_bytes / size;
        let mut rows = Vec::with_capacity(w.height());
        for j in w.y1..w.y2 {
            let offset = (j - info.bounds.y1) as isize * stride
                + (w.x1 - info.bounds.x1) as isize * info.channels as isize;
            // SAFETY: as in `view`, the host's buffer holds every row of the
            // bounds in samples of type T (checked); this row segment covers
            // only the render window's columns of one row, so segments are
            // disjoint from each other and from the windows that other render
            // threads write (OFX render windows of concurrent calls do not
            // overlap). `&mut self` keeps this image's rows from being handed
            // out twice.
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
        let Some((props, suites)) = &self.release else {
            return;
        };
        if let Some(f) = suites.effect.clipReleaseImage {
            // SAFETY: the property set is the image handle clipGetImage gave us, released once.
            unsafe {
                f(props.handle());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3x2 RGBA image of `T` over `buf`.
    fn image_over<T: HostSample>(buf: &mut [T], depth: Depth) -> HostImage {
        let info = ImageInfo {
            data: buf.as_mut_ptr() as *mut c_void,
            bounds: RectI::new(0, 0, 3, 2),
            row_bytes: (3 * 4 * std::mem::size_of::<T>()) as isize,
            depth,
            ..ImageInfo::default()
        };
        assert!(buf.len() >= 24);
        // SAFETY: `buf` holds the 2 rows of 3 RGBA samples `info` describes
        // and outlives the image (both die at the end of the caller's test).
        unsafe { HostImage::over(info) }
    }

    fn views<T: HostSample>(image: &mut HostImage) -> [bool; 2] {
        [
            image.view::<T>().is_ok(),
            image.rows_mut::<T>(RectI::new(0, 0, 3, 2)).is_ok(),
        ]
    }

    /// Every (image depth, sample type) pair: only the matching type views
    /// the image, read or write; the rest are refused, never sliced.
    #[test]
    fn only_the_images_own_sample_type_views_it() {
        let mut bytes = vec![0u8; 24];
        let mut shorts = vec![0u16; 24];
        let mut floats = vec![0f32; 24];
        let mut images = [
            image_over(&mut bytes, Depth::U8),
            image_over(&mut shorts, Depth::U16),
            image_over(&mut floats, Depth::F32),
        ];
        for image in images.iter_mut() {
            let depth = image.info().depth;
            assert_eq!(
                views::<u8>(image),
                [depth == Depth::U8; 2],
                "{depth:?} as u8"
            );
            assert_eq!(
                views::<u16>(image),
                [depth == Depth::U16; 2],
                "{depth:?} as u16"
            );
            assert_eq!(
                views::<f32>(image),
                [depth == Depth::F32; 2],
                "{depth:?} as f32"
            );
        }
        // The one the issue found: an 8-bit image read as floats would have
        // been a slice four times its buffer.
        let Err(err) = images[0].view::<f32>() else {
            panic!("an 8-bit image viewed as floats");
        };
        assert!(err.message().contains("U8 image read as F32"), "{err:?}");
    }

    #[test]
    fn a_matching_view_reads_the_hosts_samples() {
        let mut floats: Vec<f32> = (0..24).map(|v| v as f32).collect();
        let image = image_over(&mut floats, Depth::F32);
        let view = image.view::<f32>().expect("view");
        assert_eq!(view.pixel(2, 1), &[20.0, 21.0, 22.0, 23.0][..]);
    }
}
