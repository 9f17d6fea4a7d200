//! A loaded bundle: the host struct and its suites, the plugins' load and
//! describe actions, and every call into a plugin's main entry.

use std::ffi::{c_char, c_int, c_void, CStr};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use openfx::sys::generic::core::*;
use openfx::sys::generic::property::*;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::memory::kOfxMemorySuite;
use openfx::sys::image_effect_v1::message::*;
use openfx::sys::image_effect_v1::multi_thread::kOfxMultiThreadSuite;
use openfx::sys::image_effect_v1::param::*;
use openfx::sys::image_effect_v1::progress::kOfxProgressSuite;
use openfx::sys::image_effect_v1::time_line::kOfxTimeLineSuite;

use super::checks::violation;
use super::effect::{Effect, Message};
use super::props::PropertySet;
use super::{effect, guard, interact_suites, misuse, params, planes, props, services};
use crate::error::{HostError, BAD_INPUT_ID};
use crate::sync::Locked;

/// What a host offers beyond the basics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HostOptions {
    /// Overlay interacts (and the interact suite), as a host with a viewer.
    pub overlays: bool,
    /// The OFX 1.5 Draw suite, recording every call.
    pub draw_suite: bool,
    /// The multi-plane extension, as Natron offers it (`planes`).
    pub multi_plane: bool,
}

/// Whether the loaded host whose property set is `host` has int property
/// `name` set to 1.
fn offers(host: OfxPropertySetHandle, name: &CStr) -> bool {
    // SAFETY: `host` is one of our host property sets (fetchSuite checked
    // it is in LOADED_HOSTS, which holds only live hosts' sets).
    let props = unsafe { &*(host as *const PropertySet) };
    props.ints(name).first() == Some(&1)
}

/// Host structs (by their property set) whose plugins have been sent the
/// load action: before it, the spec lets a plugin fetch no suite.
static LOADED_HOSTS: Mutex<Vec<usize>> = Mutex::new(Vec::new());

unsafe extern "C" fn fetch_suite(
    host: OfxPropertySetHandle,
    name: *const c_char,
    version: c_int,
) -> *const c_void {
    guard::guard(std::ptr::null(), "fetch_suite", || {
        if name.is_null() {
            return std::ptr::null();
        }
        // SAFETY: suite names are NUL-terminated C strings.
        let name = unsafe { CStr::from_ptr(name) };
        if misuse::withholds(name) {
            return std::ptr::null();
        }
        let loaded = LOADED_HOSTS.locked().contains(&(host as usize));
        if !loaded {
            violation(format!(
                "fetchSuite({}, {version}) before the load action",
                name.to_string_lossy()
            ));
            return std::ptr::null();
        }
        match (name, version) {
            (n, 1) if n == kOfxPropertySuite => &props::SUITE as *const _ as *const c_void,
            (n, 1) if n == kOfxImageEffectSuite => &effect::SUITE as *const _ as *const c_void,
            (n, 1) if n == kOfxParameterSuite => &params::SUITE as *const _ as *const c_void,
            (n, 1) if n == kOfxMessageSuite => &effect::MESSAGE_SUITE as *const _ as *const c_void,
            (n, 2) if n == kOfxMessageSuite => {
                &effect::MESSAGE_SUITE_V2 as *const _ as *const c_void
            }
            (n, 1) if n == kOfxMemorySuite => &services::MEMORY_SUITE as *const _ as *const c_void,
            (n, 1) if n == kOfxMultiThreadSuite => {
                &services::MULTI_THREAD_SUITE as *const _ as *const c_void
            }
            (n, 1) if n == kOfxProgressSuite => {
                &services::PROGRESS_SUITE_V1 as *const _ as *const c_void
            }
            (n, 2) if n == kOfxProgressSuite => {
                &services::PROGRESS_SUITE_V2 as *const _ as *const c_void
            }
            (n, 1) if n == kOfxTimeLineSuite => {
                &services::TIME_LINE_SUITE as *const _ as *const c_void
            }
            (n, 1)
                if n == interact_suites::kOfxInteractSuite
                    && offers(host, kOfxImageEffectPropSupportsOverlays) =>
            {
                &interact_suites::INTERACT_SUITE as *const _ as *const c_void
            }
            (n, 1)
                if n == interact_suites::kOfxDrawSuite
                    && offers(host, interact_suites::DRAW_SUITE_PROP) =>
            {
                &interact_suites::DRAW_SUITE as *const _ as *const c_void
            }
            (n, 1) if n == planes::PLANE_SUITE && offers(host, planes::MULTI_PLANAR) => {
                &planes::SUITE as *const _ as *const c_void
            }
            // Anything else (OpenGL render, dialogs, ...) this host does not provide: a
            // null answer is how OFX says so.
            _ => std::ptr::null(),
        }
    })
}

pub struct PluginInfo {
    pub id: String,
    pub version: (u32, u32),
    /// The binary whose code answers this plugin's actions (a bundle may hand
    /// over to another build of itself, e.g. one for the CPU it runs on).
    pub served_by: Option<PathBuf>,
    pub(super) plugin: *const OfxPlugin,
}

/// The shared object that holds `address`, from the dynamic loader.
fn object_holding(address: *const c_void) -> Option<PathBuf> {
    let mut info = libc::Dl_info {
        dli_fname: std::ptr::null(),
        dli_fbase: std::ptr::null_mut(),
        dli_sname: std::ptr::null(),
        dli_saddr: std::ptr::null_mut(),
    };
    // SAFETY: dladdr only reads the loader's tables; `info` is a live local.
    if unsafe { libc::dladdr(address, &mut info) } == 0 || info.dli_fname.is_null() {
        return None;
    }
    // SAFETY: dli_fname is a NUL-terminated path owned by the loader.
    let name = unsafe { CStr::from_ptr(info.dli_fname) };
    Some(PathBuf::from(name.to_string_lossy().into_owned()))
}

/// The executable or shared library this code is linked into: `morphfx`
/// itself, or the Python module, which links the harness and the plugin
/// and so is an OpenFX binary of its own.
pub fn this_binary() -> Option<PathBuf> {
    object_holding(this_binary as *const c_void)
}

/// A loaded bundle and its plugins.
pub struct Bundle {
    pub binary: PathBuf,
    pub plugins: Vec<PluginInfo>,
    /// Plugins sent the load action (once each; unload when the bundle goes).
    loaded: Mutex<Vec<usize>>,
    host: Box<OfxHost>,
    _host_props: Box<PropertySet>,
    _lib: libloading::Library,
}

/// OK and "reply default" are both success for an action.
pub(super) fn accept(st: OfxStatus, what: &str, effect: &Effect) -> Result<(), HostError> {
    if st == kOfxStatOK || st == kOfxStatReplyDefault {
        Ok(())
    } else {
        Err(failure(st, what, Some(effect)))
    }
}

/// The error of an action that answered `status`: the plugin's last error
/// message (its persistent one included), bad input where it says so.
pub(super) fn failure(status: OfxStatus, what: &str, effect: Option<&Effect>) -> HostError {
    let mut messages = effect.map(|e| e.take_messages()).unwrap_or_default();
    // Render-time errors arrive as the persistent message (message suite v2).
    if let Some(m) = effect.and_then(|e| e.persistent.locked().clone()) {
        messages.push(m);
    }
    let errors: Vec<&Message> = messages
        .iter()
        .filter(|m| m.kind == kOfxMessageError.to_string_lossy())
        .collect();
    match errors.last() {
        Some(m) if m.id == BAD_INPUT_ID || m.id.starts_with("net.morphfx.harness") => {
            HostError::bad(m.text.clone())
        }
        Some(m) => HostError::failed(format!("{what}: {}", m.text)),
        None => HostError::failed(format!("{what} failed with OFX status {status}")),
    }
}

/// What our host says it is and supports (the host descriptor's properties).
fn host_properties(options: HostOptions) -> Box<PropertySet> {
    let host_props = Box::new(PropertySet::new());
    host_props.set_str(kOfxPropName, "net.morphfx.harness");
    host_props.set_str(kOfxPropLabel, "morphfx harness");
    host_props.set_int(kOfxImageEffectHostPropIsBackground, &[1]);
    host_props.set_int(
        kOfxImageEffectPropSupportsOverlays,
        &[options.overlays as i32],
    );
    host_props.set_int(
        interact_suites::DRAW_SUITE_PROP,
        &[options.draw_suite as i32],
    );
    host_props.set_int(planes::MULTI_PLANAR, &[options.multi_plane as i32]);
    host_props.set_int(kOfxImageEffectPropSupportsMultiResolution, &[1]);
    host_props.set_int(kOfxImageEffectPropSupportsTiles, &[1]);
    host_props.set_int(kOfxImageEffectPropTemporalClipAccess, &[1]);
    host_props.set_strs(
        kOfxImageEffectPropSupportedComponents,
        &[
            "OfxImageComponentRGBA",
            "OfxImageComponentRGB",
            "OfxImageComponentAlpha",
        ],
    );
    host_props.set_strs(
        kOfxImageEffectPropSupportedContexts,
        &[
            "OfxImageEffectContextGeneral",
            "OfxImageEffectContextFilter",
            "OfxImageEffectContextTransition",
        ],
    );
    host_props.set_strs(
        kOfxImageEffectPropSupportedPixelDepths,
        &["OfxBitDepthByte", "OfxBitDepthShort", "OfxBitDepthFloat"],
    );
    host_props.set_int(kOfxImageEffectPropSupportsMultipleClipDepths, &[0]);
    host_props.set_int(kOfxImageEffectPropSupportsMultipleClipPARs, &[0]);
    host_props.set_int(kOfxParamHostPropSupportsStringAnimation, &[0]);
    host_props.set_int(kOfxParamHostPropMaxParameters, &[-1]);
    host_props
}

/// Hands the bundle our host and lists its plugins.
///
/// # Safety
/// `lib` must be an OFX bundle (its `OfxSetHost`, `OfxGetNumberOfPlugins` and
/// `OfxGetPlugin` have the OFX signatures), and `lib` and `host` must outlive
/// every plugin pointer returned.
unsafe fn plugins_of(
    lib: &libloading::Library,
    host: &OfxHost,
    binary: &Path,
) -> Result<Vec<PluginInfo>, HostError> {
    // SAFETY: the caller vouches for the symbols' signatures and lifetimes.
    unsafe {
        if let Ok(set_host) =
            lib.get::<unsafe extern "C" fn(*const OfxHost) -> OfxStatus>(b"OfxSetHost\0")
        {
            let st = set_host(host);
            if st != kOfxStatOK {
                return Err(HostError::failed(format!(
                    "OfxSetHost failed with status {st}"
                )));
            }
        }
        let count = lib
            .get::<unsafe extern "C" fn() -> c_int>(b"OfxGetNumberOfPlugins\0")
            .map_err(|e| HostError::bad(format!("{}: not an OFX bundle: {e}", binary.display())))?;
        let get = lib
            .get::<unsafe extern "C" fn(c_int) -> *mut OfxPlugin>(b"OfxGetPlugin\0")
            .map_err(|e| HostError::bad(format!("{}: not an OFX bundle: {e}", binary.display())))?;
        let mut plugins = Vec::new();
        for i in 0..count() {
            let p = get(i);
            let Some(plugin) = p.as_ref() else { continue };
            if let Some(set_host) = plugin.setHost {
                set_host(host as *const OfxHost as *mut OfxHost);
            }
            plugins.push(PluginInfo {
                served_by: plugin
                    .mainEntry
                    .and_then(|f| object_holding(f as *const c_void)),
                id: CStr::from_ptr(plugin.pluginIdentifier)
                    .to_string_lossy()
                    .into_owned(),
                version: (plugin.pluginVersionMajor, plugin.pluginVersionMinor),
                plugin: p,
            });
        }
        Ok(plugins)
    }
}

/// The binary inside a bundle folder, or the path itself if it is a file.
pub fn bundle_binary(path: &Path) -> PathBuf {
    if path.is_dir() {
        let stem = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("")
            .trim_end_matches(".bundle");
        path.join("Contents/Linux-x86-64").join(stem)
    } else {
        path.to_path_buf()
    }
}

impl Bundle {
    pub fn load(path: &Path) -> Result<Bundle, HostError> {
        Bundle::load_with(path, HostOptions::default())
    }

    /// Loads the bundle into a host with `options`.
    pub fn load_with(path: &Path, options: HostOptions) -> Result<Bundle, HostError> {
        let binary = bundle_binary(path);
        if !binary.is_file() {
            return Err(HostError::bad(format!(
                "plugin bundle {}: no binary at {}",
                path.display(),
                binary.display()
            )));
        }
        // SAFETY: loading a shared library runs its initialisers; an OFX bundle
        // is such a library by contract, and we load only the path we were given.
        let lib = unsafe { libloading::Library::new(&binary) }
            .map_err(|e| HostError::bad(format!("plugin bundle {}: {e}", binary.display())))?;
        let host_props = host_properties(options);
        let host = Box::new(OfxHost {
            host: host_props.handle(),
            fetchSuite: Some(fetch_suite),
        });

        // SAFETY: `lib` is the OFX bundle just loaded, and the Bundle keeps
        // it and `host` alive for as long as anything it returned is used.
        let plugins = unsafe { plugins_of(&lib, &host, &binary)? };
        Ok(Bundle {
            binary,
            plugins,
            loaded: Mutex::new(Vec::new()),
            host,
            _host_props: host_props,
            _lib: lib,
        })
    }

    pub(super) fn call(
        &self,
        plugin: *const OfxPlugin,
        action: &CStr,
        handle: *const c_void,
        in_args: Option<&PropertySet>,
        out_args: Option<&PropertySet>,
    ) -> OfxStatus {
        let h = |p: Option<&PropertySet>| p.map_or(std::ptr::null_mut(), |p| p.handle());
        let _inside = params::Inside::action(action);
        // SAFETY: `plugin` came from this bundle's OfxGetPlugin and the library
        // is loaded; handles are live objects of this host.
        unsafe {
            match (*plugin).mainEntry {
                Some(main) => main(action.as_ptr(), handle, h(in_args), h(out_args)),
                None => kOfxStatErrMissingHostFeature,
            }
        }
    }

    /// Describe, then describe in `context`: the plugin's descriptor.
    pub(super) fn describe(
        &self,
        plugin: *const OfxPlugin,
        id: &str,
        context: &str,
    ) -> Result<Box<Effect>, HostError> {
        let descriptor = Effect::new();
        descriptor
            .props
            .set_str(kOfxPropType, "OfxTypeImageEffectHost");
        let handle = descriptor.handle() as *const c_void;
        let st = self.call(plugin, kOfxActionDescribe, handle, None, None);
        accept(st, "describe", &descriptor)?;
        let contexts = descriptor.props.strs(kOfxImageEffectPropSupportedContexts);
        if !contexts.iter().any(|c| c == context) {
            return Err(HostError::bad(format!(
                "plugin {id} does not support context {context} (it offers {})",
                contexts.join(", ")
            )));
        }
        let in_args = PropertySet::new();
        in_args.set_str(kOfxImageEffectPropContext, context);
        let action = kOfxImageEffectActionDescribeInContext;
        let st = self.call(plugin, action, handle, Some(&in_args), None);
        accept(st, "describeInContext", &descriptor)?;
        Ok(descriptor)
    }

    pub fn host(&self) -> &OfxHost {
        &self.host
    }

    /// Sends the load action to `plugin` once (the spec: before describe,
    /// and never twice without an unload). Suites may be fetched from then on.
    pub(super) fn send_load(&self, plugin: *const OfxPlugin) -> Result<(), HostError> {
        let mut loaded = self.loaded.locked();
        if loaded.contains(&(plugin as usize)) {
            return Ok(());
        }
        LOADED_HOSTS.locked().push(self.host.host as usize);
        let st = self.call(plugin, kOfxActionLoad, std::ptr::null(), None, None);
        if st != kOfxStatOK && st != kOfxStatReplyDefault {
            return Err(HostError::failed(format!(
                "the plugin failed its load action (OFX status {st})"
            )));
        }
        loaded.push(plugin as usize);
        Ok(())
    }
}

impl Drop for Bundle {
    fn drop(&mut self) {
        let loaded = std::mem::take(&mut *self.loaded.locked());
        for plugin in loaded {
            let _ = self.call(
                plugin as *const OfxPlugin,
                kOfxActionUnload,
                std::ptr::null(),
                None,
                None,
            );
        }
        LOADED_HOSTS
            .locked()
            .retain(|h| *h != self.host.host as usize);
    }
}

// SAFETY: plugin pointers are immutable statics of the loaded library; the
// host struct and its property set are only read after loading. OFX renders
// may be called from any thread for a plugin that declares itself thread safe.
unsafe impl Send for PluginInfo {}
// SAFETY: as above.
unsafe impl Sync for PluginInfo {}
// SAFETY: as above: a bundle is its library and its plugins' info.
unsafe impl Send for Bundle {}
// SAFETY: as above.
unsafe impl Sync for Bundle {}

#[cfg(test)]
mod tests {
    /// Linked into a test executable, the code is that executable's.
    #[test]
    fn this_binary_is_the_one_the_code_is_linked_into() {
        let found = super::this_binary().expect("the loader knows its executable");
        let exe = std::env::current_exe().unwrap();
        assert_eq!(
            std::fs::canonicalize(found).unwrap(),
            std::fs::canonicalize(exe).unwrap()
        );
    }
}
