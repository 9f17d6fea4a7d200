//! Effects (descriptors and instances), clips backed by frame buffers, images,
//! and the image effect and message suites.

use std::collections::HashSet;
use std::ffi::{c_char, c_int, c_void, CStr};
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};

use morphfx::geom::RectI;
use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::message::*;
use openfx::sys::image_effect_v1::param::*;

use super::frame::Frame;
use super::params::ParamSet;
use super::props::PropertySet;
use crate::sync::Locked;

/// Supplies a clip's frames.
pub trait FrameSource: Send + Sync {
    /// The frame at `time` at render scale 1, or why there is none.
    fn frame(&self, time: f64) -> Result<Arc<Frame>, String>;

    /// The frames it has images for, when it knows (a sequence); the
    /// clip's `kOfxImageEffectPropFrameRange`.
    fn range(&self) -> Option<(f64, f64)> {
        None
    }

    /// Whether the clip's region of definition is infinite (the spec allows
    /// it: a constant or a Roto upstream) while its images stay finite.
    fn infinite(&self) -> bool {
        false
    }
}

/// The spec's infinite region (`kOfxFlagInfiniteMin` to `kOfxFlagInfiniteMax`).
pub const INFINITE: RectI = RectI {
    x1: i32::MIN,
    y1: i32::MIN,
    x2: i32::MAX,
    y2: i32::MAX,
};

pub struct Clip {
    pub name: String,
    pub props: PropertySet,
    pub source: Mutex<Option<Arc<dyn FrameSource>>>,
    /// The buffer renders write into (output clip).
    pub output: Mutex<Option<Arc<Frame>>>,
    /// Planes besides colour, by plane string (multi-planar hosts).
    pub planes: Mutex<Vec<(String, Arc<dyn FrameSource>)>>,
    /// The buffers of those planes a render writes into (output clip).
    pub output_planes: Mutex<Vec<(String, Arc<Frame>)>>,
    /// The last proxy made: the source frame it came from, its render
    /// scale, and the proxy. A host keeps proxies rather than filtering
    /// the plate again for every render at the same scale.
    proxy: Mutex<Option<Proxy>>,
    effect: *const Effect,
}

/// A proxy: the frame it was made from, its render scale, the proxy.
type Proxy = (Arc<Frame>, (f64, f64), Arc<Frame>);

// SAFETY: `effect` points at the owning Effect, which outlives its clips and is
// itself shared between threads only through its own locks.
unsafe impl Send for Clip {}
// SAFETY: as for Send; every mutable field is behind a Mutex.
unsafe impl Sync for Clip {}

#[derive(Debug, Clone, PartialEq)]
pub struct Message {
    pub kind: String,
    pub id: String,
    pub text: String,
}

pub struct Effect {
    pub props: PropertySet,
    pub params: ParamSet,
    pub clips: Mutex<Vec<Box<Clip>>>,
    pub messages: Mutex<Vec<Message>>,
    /// (render scale x, y) of the render in progress.
    pub render_scale: Mutex<(f64, f64)>,
    /// The field of the render in progress (`OfxImageFieldNone` for
    /// progressive footage): source images are that field, lines doubled.
    pub field: Mutex<&'static str>,
    /// Interlaced footage: the clips' field order (which field comes first).
    pub field_order: Mutex<Option<&'static str>>,
    /// The time line as this effect sees it: (current, first, last).
    pub timeline: Mutex<(f64, f64, f64)>,
    /// Progress the plugin last reported (progress suite), if a task is open.
    pub progress: Mutex<Option<(String, f64)>>,
    /// Every progress the plugin reported, in order (tests read it).
    pub progress_log: Mutex<Vec<f64>>,
    /// The user presses cancel once progress reaches this.
    pub cancel_at: Mutex<Option<f64>>,
    /// The persistent message the plugin set (message suite v2), until it
    /// clears it: what a host shows on the node (Natron draws it red).
    pub persistent: Mutex<Option<Message>>,
}

static LIVE_EFFECTS: Mutex<Option<HashSet<usize>>> = Mutex::new(None);

impl Effect {
    pub fn new() -> Box<Effect> {
        let e = Box::new(Effect {
            props: PropertySet::new(),
            params: ParamSet::default(),
            clips: Mutex::new(Vec::new()),
            messages: Mutex::new(Vec::new()),
            render_scale: Mutex::new((1.0, 1.0)),
            field: Mutex::new("OfxImageFieldNone"),
            field_order: Mutex::new(None),
            timeline: Mutex::new((0.0, 0.0, 0.0)),
            progress: Mutex::new(None),
            progress_log: Mutex::new(Vec::new()),
            cancel_at: Mutex::new(None),
            persistent: Mutex::new(None),
        });
        LIVE_EFFECTS
            .locked()
            .get_or_insert_with(HashSet::new)
            .insert(&*e as *const Effect as usize);
        e
    }

    pub fn handle(&self) -> OfxImageEffectHandle {
        self as *const Effect as OfxImageEffectHandle
    }

    pub fn clip(&self, name: &str) -> Option<&Clip> {
        let clips = self.clips.locked();
        // SAFETY: clips are boxed and never removed while the effect lives.
        clips
            .iter()
            .find(|c| c.name == name)
            .map(|c| unsafe { &*(&**c as *const Clip) })
    }

    pub fn clip_names(&self) -> Vec<String> {
        self.clips.locked().iter().map(|c| c.name.clone()).collect()
    }

    pub fn add_clip(&self, name: &str, props: PropertySet) -> &Clip {
        let clip = Box::new(Clip {
            name: name.to_owned(),
            props,
            source: Mutex::new(None),
            output: Mutex::new(None),
            planes: Mutex::new(Vec::new()),
            output_planes: Mutex::new(Vec::new()),
            proxy: Mutex::new(None),
            effect: self,
        });
        clip.props.set_str(kOfxPropName, name);
        let mut clips = self.clips.locked();
        clips.push(clip);
        // SAFETY: just pushed a box that lives as long as the effect.
        unsafe { &*(&**clips.last().expect("pushed") as *const Clip) }
    }

    pub fn take_messages(&self) -> Vec<Message> {
        std::mem::take(&mut *self.messages.locked())
    }
}

impl Drop for Effect {
    fn drop(&mut self) {
        if let Some(set) = LIVE_EFFECTS.locked().as_mut() {
            set.remove(&(self as *const Effect as usize));
        }
    }
}

pub(super) fn live_effect<'a>(h: *const c_void) -> Option<&'a Effect> {
    let live = LIVE_EFFECTS.locked();
    if live.as_ref().is_some_and(|s| s.contains(&(h as usize))) {
        // SAFETY: registered effects are live boxes (removed on drop).
        Some(unsafe { &*(h as *const Effect) })
    } else {
        None
    }
}

/// The clip behind a handle, `None` for null.
///
/// # Safety
/// `h` is null or a handle this host's clipGetHandle gave out, whose effect
/// is still alive (OFX requires a plugin to pass only such handles).
pub(super) unsafe fn clip_of<'a>(h: OfxImageClipHandle) -> Option<&'a Clip> {
    // SAFETY: clip handles we hand out point at boxed Clips of a live effect.
    unsafe { (h as *const Clip).as_ref() }
}

unsafe extern "C" fn get_property_set(
    h: OfxImageEffectHandle,
    props: *mut OfxPropertySetHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_property_set", || {
        let Some(e) = live_effect(h as *const c_void) else {
            return kOfxStatErrBadHandle;
        };
        if !props.is_null() {
            // SAFETY: checked non-null just above; the plugin passes a pointer to its own variable.
            unsafe { *props = e.props.handle() };
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn get_param_set(
    h: OfxImageEffectHandle,
    set: *mut OfxParamSetHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_param_set", || {
        let Some(e) = live_effect(h as *const c_void) else {
            return kOfxStatErrBadHandle;
        };
        if !set.is_null() {
            // SAFETY: checked non-null just above; the plugin passes a pointer to its own variable.
            unsafe { *set = &e.params as *const ParamSet as OfxParamSetHandle };
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn clip_define(
    h: OfxImageEffectHandle,
    name: *const c_char,
    props: *mut OfxPropertySetHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "clip_define", || {
        let Some(e) = live_effect(h as *const c_void) else {
            return kOfxStatErrBadHandle;
        };
        if name.is_null() {
            return kOfxStatErrBadHandle;
        }
        // SAFETY: NUL-terminated name from the plugin.
        let name = unsafe { CStr::from_ptr(name) }
            .to_string_lossy()
            .into_owned();
        let clip = match e.clip(&name) {
            Some(c) => c,
            None => e.add_clip(&name, PropertySet::new()),
        };
        if !props.is_null() {
            // SAFETY: checked non-null just above; the plugin passes a pointer to its own variable.
            unsafe { *props = clip.props.handle() };
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn clip_get_handle(
    h: OfxImageEffectHandle,
    name: *const c_char,
    clip: *mut OfxImageClipHandle,
    props: *mut OfxPropertySetHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "clip_get_handle", || {
        let Some(e) = live_effect(h as *const c_void) else {
            return kOfxStatErrBadHandle;
        };
        if name.is_null() {
            return kOfxStatErrBadHandle;
        }
        // SAFETY: NUL-terminated name from the plugin.
        let name = unsafe { CStr::from_ptr(name) }.to_string_lossy();
        let Some(c) = e.clip(&name) else {
            return kOfxStatErrUnknown;
        };
        // SAFETY: each out-pointer is written only when non-null; both are the plugin's variables.
        unsafe {
            if !clip.is_null() {
                *clip = c as *const Clip as OfxImageClipHandle;
            }
            if !props.is_null() {
                *props = c.props.handle();
            }
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn clip_get_property_set(
    clip: OfxImageClipHandle,
    props: *mut OfxPropertySetHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "clip_get_property_set", || {
        // SAFETY: the plugin passes a clip handle we gave it (see `clip_of`).
        let Some(c) = (unsafe { clip_of(clip) }) else {
            return kOfxStatErrBadHandle;
        };
        if !props.is_null() {
            // SAFETY: checked non-null just above; the plugin passes a pointer to its own variable.
            unsafe { *props = c.props.handle() };
        }
        kOfxStatOK
    })
}

impl Clip {
    pub(super) fn effect(&self) -> &Effect {
        // SAFETY: a clip never outlives its effect.
        unsafe { &*self.effect }
    }

    /// The frame this clip shows at `time` and the render scale in force.
    pub fn frame_at(&self, time: f64) -> Result<Option<Arc<Frame>>, String> {
        if let Some(out) = self.output.locked().clone() {
            return Ok(Some(out));
        }
        let source = self.source.locked().clone();
        let Some(source) = source else {
            return Ok(None);
        };
        let mut frame = source.frame(time)?;
        // The spec's default extraction: one field, each line doubled.
        let field = *self.effect().field.locked();
        if matches!(field, "OfxImageFieldLower" | "OfxImageFieldUpper") {
            frame = Arc::new(frame.field_doubled(field == "OfxImageFieldUpper"));
        }
        let scale = *self.effect().render_scale.locked();
        if scale == (1.0, 1.0) {
            return Ok(Some(frame));
        }
        let mut proxy = self.proxy.locked();
        if let Some((from, at, made)) = proxy.as_ref() {
            if Arc::ptr_eq(from, &frame) && *at == scale {
                return Ok(Some(made.clone()));
            }
        }
        let made = Arc::new(frame.scaled(scale));
        *proxy = Some((frame, scale, made.clone()));
        Ok(Some(made))
    }

    /// Canonical region of definition at `time` (the full-resolution bounds).
    pub fn rod(&self, time: f64) -> Option<RectI> {
        let source = self.source.locked().clone()?;
        if source.infinite() {
            return Some(INFINITE);
        }
        // Canonical x is pixels times the pixel aspect ratio.
        source.frame(time).ok().map(|f| {
            let b = f.bounds;
            let x = |v: i32| (v as f64 * f.par).round() as i32;
            RectI::new(x(b.x1), b.y1, x(b.x2), b.y2)
        })
    }
}

pub(super) unsafe extern "C" fn clip_get_image(
    clip: OfxImageClipHandle,
    time: OfxTime,
    _region: *const OfxRectD,
    image: *mut OfxPropertySetHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "clip_get_image", || {
        // SAFETY: the plugin passes a clip handle we gave it (see `clip_of`).
        let Some(c) = (unsafe { clip_of(clip) }) else {
            return kOfxStatErrBadHandle;
        };
        if image.is_null() {
            return kOfxStatErrBadHandle;
        }
        if super::misuse::no_image(&c.name) {
            return kOfxStatFailed;
        }
        let frame = match c.frame_at(time) {
            Ok(Some(f)) => f,
            Ok(None) => return kOfxStatFailed,
            Err(message) => {
                c.effect().messages.locked().push(Message {
                    kind: "OfxMessageError".into(),
                    id: "net.morphfx.harness.MissingFrame".into(),
                    text: message,
                });
                return kOfxStatFailed;
            }
        };
        let scale = *c.effect().render_scale.locked();
        let props = frame.image_props(scale, time);
        super::misuse::tamper_image(&c.name, &props);
        // SAFETY: out-pointer from the plugin. The boxed set (owning the frame) is
        // released by clipReleaseImage.
        unsafe { *image = Box::into_raw(Box::new(props)) as OfxPropertySetHandle };
        kOfxStatOK
    })
}

unsafe extern "C" fn clip_release_image(image: OfxPropertySetHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "clip_release_image", || {
        if image.is_null() {
            return kOfxStatErrBadHandle;
        }
        // SAFETY: image handles come only from Box::into_raw in clip_get_image
        // and are never freed (see below), so the set is live.
        let set = unsafe { &*(image as *const PropertySet) };
        if set.released.swap(true, Ordering::Relaxed) {
            super::checks::violation("an image released twice".into());
            return kOfxStatErrBadHandle;
        }
        // The pixels go now; the emptied set stays, so a later use is reported
        // (by the property suite) instead of reading freed memory.
        // SAFETY: as above; the plugin gave up the handle with this call, and
        // only this function (once per image, checked above) takes the box back.
        let mut set = unsafe { Box::from_raw(image as *mut PropertySet) };
        set.owner = None;
        set.clear();
        let mut released = RELEASED.locked();
        if released.len() == RELEASED_KEPT {
            // A long render stays flat in memory: the oldest shells go (a
            // plugin misusing an image does so within a frame or two).
            released.pop_front();
        }
        released.push_back(SendSet(set));
        kOfxStatOK
    })
}

/// Released images' emptied property sets (a few dozen bytes each), the
/// newest [`RELEASED_KEPT`].
static RELEASED: Mutex<std::collections::VecDeque<SendSet>> =
    Mutex::new(std::collections::VecDeque::new());
const RELEASED_KEPT: usize = 1 << 16;

struct SendSet(#[allow(dead_code)] Box<PropertySet>);

unsafe extern "C" fn clip_get_rod(
    clip: OfxImageClipHandle,
    time: OfxTime,
    bounds: *mut OfxRectD,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "clip_get_rod", || {
        // SAFETY: the plugin passes a clip handle we gave it (see `clip_of`).
        let Some(c) = (unsafe { clip_of(clip) }) else {
            return kOfxStatErrBadHandle;
        };
        let Some(r) = c.rod(time) else {
            return kOfxStatFailed;
        };
        if !bounds.is_null() {
            // SAFETY: checked non-null just above; the plugin passes a pointer to its own variable.
            unsafe {
                *bounds = OfxRectD {
                    x1: r.x1 as f64,
                    y1: r.y1 as f64,
                    x2: r.x2 as f64,
                    y2: r.y2 as f64,
                };
            }
        }
        kOfxStatOK
    })
}

/// A render the user interrupted may stop early: its picture is dropped.
unsafe extern "C" fn abort(_: OfxImageEffectHandle) -> c_int {
    super::guard::guard(0, "abort", || crate::interrupt::requested() as c_int)
}

unsafe extern "C" fn memory_alloc(
    _: OfxImageEffectHandle,
    _: usize,
    _: *mut OfxImageMemoryHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "memory_alloc", || {
        kOfxStatErrUnsupported
    })
}
unsafe extern "C" fn memory_free(_: OfxImageMemoryHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "memory_free", || kOfxStatErrUnsupported)
}
unsafe extern "C" fn memory_lock(_: OfxImageMemoryHandle, _: *mut *mut c_void) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "memory_lock", || kOfxStatErrUnsupported)
}
unsafe extern "C" fn memory_unlock(_: OfxImageMemoryHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "memory_unlock", || {
        kOfxStatErrUnsupported
    })
}

pub static SUITE: OfxImageEffectSuiteV1 = OfxImageEffectSuiteV1 {
    getPropertySet: Some(get_property_set),
    getParamSet: Some(get_param_set),
    clipDefine: Some(clip_define),
    clipGetHandle: Some(clip_get_handle),
    clipGetPropertySet: Some(clip_get_property_set),
    clipGetImage: Some(clip_get_image),
    clipReleaseImage: Some(clip_release_image),
    clipGetRegionOfDefinition: Some(clip_get_rod),
    abort: Some(abort),
    imageMemoryAlloc: Some(memory_alloc),
    imageMemoryFree: Some(memory_free),
    imageMemoryLock: Some(memory_lock),
    imageMemoryUnlock: Some(memory_unlock),
};

/// A message from the shim's C strings (null ones read as empty).
///
/// # Safety
/// Each pointer is null or a NUL-terminated string (the plugin's, or the
/// shim's formatted buffer).
unsafe fn message_of(kind: *const c_char, id: *const c_char, text: *const c_char) -> Message {
    let s = |p: *const c_char| {
        if p.is_null() {
            String::new()
        } else {
            // SAFETY: NUL-terminated, per this function's contract.
            unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
        }
    };
    Message {
        kind: s(kind),
        id: s(id),
        text: s(text),
    }
}

/// Messages posted with no effect handle (the message suite v1 allows it),
/// the first [`UNOWNED_KEPT`] until taken.
static UNOWNED: Mutex<Vec<Message>> = Mutex::new(Vec::new());
const UNOWNED_KEPT: usize = 256;

/// Takes the messages the plugin posted with no effect handle.
pub fn take_unowned_messages() -> Vec<Message> {
    std::mem::take(&mut *UNOWNED.locked())
}

/// # Safety
/// Called by the C shim with the plugin's handle (checked against live effects) and C strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mfx_message_text(
    handle: *mut c_void,
    kind: *const c_char,
    id: *const c_char,
    text: *const c_char,
) -> c_int {
    super::guard::guard(0, "mfx_message_text", || {
        // SAFETY: the shim passes C strings or nulls.
        let m = unsafe { message_of(kind, id, text) };
        match live_effect(handle) {
            Some(e) => e.messages.locked().push(m),
            None => {
                eprintln!("morphfx: plugin says ({}): {}", m.kind, m.text);
                let mut unowned = UNOWNED.locked();
                if unowned.len() < UNOWNED_KEPT {
                    unowned.push(m);
                }
            }
        }
        kOfxStatOK
    })
}

/// # Safety
/// Called by the C shim with the plugin's handle (checked against live effects) and C strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mfx_persistent_text(
    handle: *mut c_void,
    kind: *const c_char,
    id: *const c_char,
    text: *const c_char,
) -> c_int {
    super::guard::guard(0, "mfx_persistent_text", || {
        // The spec: the handle may NOT be null, and must be an instance.
        let Some(e) = live_effect(handle) else {
            return kOfxStatErrBadHandle;
        };
        // SAFETY: the shim passes C strings or nulls.
        let m = unsafe { message_of(kind, id, text) };
        *e.persistent.locked() = Some(m);
        kOfxStatOK
    })
}

unsafe extern "C" fn clear_persistent(handle: *mut c_void) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "clear_persistent", || {
        let Some(e) = live_effect(handle) else {
            return kOfxStatErrBadHandle;
        };
        *e.persistent.locked() = None;
        kOfxStatOK
    })
}

unsafe extern "C" {
    fn mfx_persistent_message(
        handle: *mut c_void,
        kind: *const c_char,
        id: *const c_char,
        format: *const c_char,
        ...
    ) -> OfxStatus;
    fn mfx_message(
        handle: *mut c_void,
        kind: *const c_char,
        id: *const c_char,
        format: *const c_char,
        ...
    ) -> OfxStatus;
}

pub static MESSAGE_SUITE: OfxMessageSuiteV1 = OfxMessageSuiteV1 {
    message: Some(mfx_message),
};

/// Version 2 extends version 1 in place, as the spec allows a host to answer both.
pub static MESSAGE_SUITE_V2: OfxMessageSuiteV2 = OfxMessageSuiteV2 {
    message: Some(mfx_message),
    setPersistentMessage: Some(mfx_persistent_message),
    clearPersistentMessage: Some(clear_persistent),
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_image_used_after_release_is_a_violation_not_a_crash() {
        let _one_at_a_time = super::super::VIOLATION_TESTS.locked();
        let set = PropertySet::new();
        set.set_int(kOfxImagePropRowBytes, &[256]);
        let h = Box::into_raw(Box::new(set)) as OfxPropertySetHandle;
        let (get, release) = (
            super::super::props::SUITE.propGetInt.unwrap(),
            SUITE.clipReleaseImage.unwrap(),
        );
        let mut rb = 0;
        // SAFETY: `h` is a live set made above; the out-pointer is ours.
        let status = unsafe { get(h, kOfxImagePropRowBytes.as_ptr(), 0, &mut rb) };
        assert_eq!(status, kOfxStatOK);
        assert_eq!(rb, 256);
        // SAFETY: as above; the host keeps released sets, so these calls are sound.
        unsafe {
            assert_eq!(release(h), kOfxStatOK);
            assert_ne!(
                get(h, kOfxImagePropRowBytes.as_ptr(), 0, &mut rb),
                kOfxStatOK
            );
            assert_eq!(release(h), kOfxStatErrBadHandle);
        }
        let seen = super::super::take_violations();
        assert!(
            seen.iter().any(|v| v.contains("after clipReleaseImage")),
            "{seen:?}"
        );
        assert!(
            seen.iter().any(|v| v.contains("released twice")),
            "{seen:?}"
        );
    }
}
