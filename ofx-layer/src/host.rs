//! The host's suites, fetched once in the load action and shared by all threads.

use std::ffi::CStr;
use std::sync::atomic::{AtomicBool, AtomicPtr, Ordering};
use std::sync::RwLock;

use openfx::sys::generic::core::*;
use openfx::sys::generic::property::*;
use openfx::sys::image_effect_v1::draw_suite::*;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::interact::*;
use openfx::sys::image_effect_v1::message::*;
use openfx::sys::image_effect_v1::param::*;
use openfx::sys::image_effect_v1::progress::*;

use super::planes::{self, PlaneSuiteV1};
use super::{Failure, Outcome};
use crate::sync::RwLocked;

#[derive(Clone, Copy)]
pub struct Suites {
    pub prop: &'static OfxPropertySuiteV1,
    pub effect: &'static OfxImageEffectSuiteV1,
    pub param: &'static OfxParameterSuiteV1,
    pub message: Option<&'static OfxMessageSuiteV1>,
    /// Persistent messages (render errors stay on the node until cleared).
    pub message_v2: Option<&'static OfxMessageSuiteV2>,
    /// Interacts: their properties and redraw requests (overlays).
    pub interact: Option<&'static OfxInteractSuiteV1>,
    /// OFX 1.5 drawing without OpenGL (overlays).
    pub draw: Option<&'static OfxDrawSuiteV1>,
    /// Progress of long work outside renders (tracking), with cancel.
    pub progress: Option<&'static OfxProgressSuiteV1>,
    /// The Foundry's plane suite: planes besides colour (multi-planar hosts).
    pub plane: Option<&'static PlaneSuiteV1>,
}

// SAFETY: the suites are immutable function tables the host keeps alive for as
// long as the binary is loaded; OFX allows calling them from any thread that
// the host calls us on (the suites we use are documented thread safe for
// render-time use, or we only use them on the threads the spec allows).
unsafe impl Send for Suites {}
// SAFETY: as above.
unsafe impl Sync for Suites {}

static SUITES: RwLock<Option<Suites>> = RwLock::new(None);

/// The host struct from `OfxSetHost` / `setHost`, kept until the load action.
static HOST: AtomicPtr<OfxHost> = AtomicPtr::new(std::ptr::null_mut());

/// Records the host. The spec lets a plugin fetch suites only from the load
/// action on, so nothing is fetched here.
pub fn set_host(host: *mut OfxHost) -> Outcome {
    if host.is_null() {
        return Err(Failure::Failed("OfxSetHost was given a null host".into()));
    }
    HOST.store(host, Ordering::Release);
    Ok(())
}

/// Fetches the suites (the load action). A host missing a required suite
/// fails the load with `kOfxStatErrMissingHostFeature` and says which.
pub fn load() -> Outcome {
    let host = HOST.load(Ordering::Acquire);
    if host.is_null() {
        return Err(Failure::Failed(
            "the host never called setHost before the load action".into(),
        ));
    }
    // SAFETY: non-null, and the host promises the struct outlives the binary's use of it.
    let host = unsafe { &*host };
    let fetch = host
        .fetchSuite
        .ok_or_else(|| Failure::Failed("host has no fetchSuite".into()))?;
    let get = |name: &CStr, version: i32| -> *const std::ffi::c_void {
        // SAFETY: fetchSuite is the host's own function, called as OFX specifies.
        unsafe { fetch(host.host, name.as_ptr(), version) }
    };
    let required = |name: &CStr, version: i32| -> Outcome<*const std::ffi::c_void> {
        let p = get(name, version);
        if p.is_null() {
            Err(Failure::Status(
                kOfxStatErrMissingHostFeature,
                format!(
                    "host does not provide suite {} v{version}",
                    name.to_string_lossy()
                ),
            ))
        } else {
            Ok(p)
        }
    };
    // The message suite first, so that a missing required suite is said
    // through it (with no effect handle, which its v1 allows).
    let message = get(kOfxMessageSuite, 1) as *const OfxMessageSuiteV1;
    MESSAGE.store(message as *mut OfxMessageSuiteV1, Ordering::Release);
    let missing = |f: Failure| {
        // A host that failed our load gets no use of suites fetched from a
        // host before it.
        *SUITES.write_locked() = None;
        f
    };
    let prop = required(kOfxPropertySuite, 1).map_err(missing)? as *const OfxPropertySuiteV1;
    let effect =
        required(kOfxImageEffectSuite, 1).map_err(missing)? as *const OfxImageEffectSuiteV1;
    let param = required(kOfxParameterSuite, 1).map_err(missing)? as *const OfxParameterSuiteV1;
    let message_v2 = get(kOfxMessageSuite, 2) as *const OfxMessageSuiteV2;
    let interact = get(kOfxInteractSuite, 1) as *const OfxInteractSuiteV1;
    let draw = get(kOfxDrawSuite, 1) as *const OfxDrawSuiteV1;
    let progress = get(kOfxProgressSuite, 1) as *const OfxProgressSuiteV1;
    let plane = get(planes::PLANE_SUITE, 1) as *const PlaneSuiteV1;
    // SAFETY: the host returned these pointers for the named suite versions;
    // they stay valid until the binary is unloaded.
    let suites = unsafe {
        Suites {
            prop: &*prop,
            effect: &*effect,
            param: &*param,
            message: message.as_ref(),
            message_v2: message_v2.as_ref(),
            interact: interact.as_ref(),
            draw: draw.as_ref(),
            progress: progress.as_ref(),
            plane: plane.as_ref(),
        }
    };
    switches();
    // A later load (a host that reloads us) replaces the suites.
    *SUITES.write_locked() = Some(suites);
    let planar = suites.prop.propGetInt.is_some_and(|get| {
        let mut v = 0;
        // SAFETY: the host descriptor's property set, which the host keeps
        // for as long as the binary is loaded; a NUL-terminated name and a
        // live out-pointer.
        let status = unsafe { get(host.host, planes::MULTI_PLANAR.as_ptr(), 0, &mut v) };
        status == kOfxStatOK && v == 1
    });
    MULTI_PLANAR.store(planar && suites.plane.is_some(), Ordering::Release);
    Ok(())
}

static MULTI_PLANAR: AtomicBool = AtomicBool::new(false);

/// The host says it is multi-planar and has the plane suite: effects may
/// read and make planes besides colour.
pub fn multi_planar() -> bool {
    MULTI_PLANAR.load(Ordering::Acquire)
}

/// The message suite of the last load, kept apart from [`SUITES`] so that a
/// load failing for want of another suite can still say why.
static MESSAGE: AtomicPtr<OfxMessageSuiteV1> = AtomicPtr::new(std::ptr::null_mut());

/// Says `text` as an error with no effect to attach it to (an action sent
/// with a null handle, a failed load): through the host's message suite,
/// whose v1 takes a null handle, else on stderr.
pub fn unowned_error(id: &CStr, text: &str) {
    let suite = MESSAGE.load(Ordering::Acquire);
    // SAFETY: null, or the suite the host returned for this name and
    // version in our load action, valid while the binary is loaded.
    let message = unsafe { suite.as_ref() }.and_then(|s| s.message);
    let format = super::printf_literal(text);
    let status = match message {
        // SAFETY: the host's message function: a null handle (allowed by
        // the v1 suite), a message type and id, and a format with no
        // conversion (every `%` doubled), so no variadic argument is read.
        Some(f) => unsafe {
            f(
                std::ptr::null_mut(),
                kOfxMessageError.as_ptr(),
                id.as_ptr(),
                format.as_ptr(),
            )
        },
        None => kOfxStatErrMissingHostFeature,
    };
    if status != kOfxStatOK {
        use std::io::Write;
        let _ = writeln!(std::io::stderr(), "MorphFX: {text}");
    }
}

/// The plugin's environment switches, read once (at the load action):
/// hosts call actions from many threads, and reading the environment on
/// each races with a host that changes its own.
#[derive(Debug, Default)]
pub struct Switches {
    /// `MORPHFX_FORCE_PANIC=<action>`: that action panics (tests prove no
    /// unwind crosses the C ABI).
    pub force_panic: Option<String>,
    /// `MORPHFX_VERBOSE`: solvers say what they did on stderr.
    pub verbose: bool,
}

pub fn switches() -> &'static Switches {
    static SWITCHES: std::sync::OnceLock<Switches> = std::sync::OnceLock::new();
    SWITCHES.get_or_init(|| Switches {
        force_panic: std::env::var("MORPHFX_FORCE_PANIC").ok(),
        verbose: std::env::var_os("MORPHFX_VERBOSE").is_some(),
    })
}

pub fn suites() -> Outcome<Suites> {
    SUITES
        .read_locked()
        .ok_or_else(|| Failure::Failed("the host never sent the load action".into()))
}

/// `MORPHFX_VERBOSE` is set: solvers say what they did on stderr.
pub fn verbose() -> bool {
    switches().verbose
}
