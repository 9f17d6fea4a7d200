//! The host side of OpenFX: loads a bundle through its C ABI and drives the
//! action sequence a real host follows. All `unsafe` of the harness lives in
//! this module, each block with its safety argument.

pub mod allocator;
pub mod effect;
pub mod frame;
pub mod guard;
pub mod misuse;
pub mod overlay;
pub mod params;
pub mod props;
pub mod services;

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use morphfx::geom::RectI;
use openfx::sys::generic::core::*;
use openfx::sys::generic::property::*;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::memory::kOfxMemorySuite;
use openfx::sys::image_effect_v1::message::*;
use openfx::sys::image_effect_v1::multi_thread::kOfxMultiThreadSuite;
use openfx::sys::image_effect_v1::param::*;
use openfx::sys::image_effect_v1::progress::kOfxProgressSuite;
use openfx::sys::image_effect_v1::time_line::kOfxTimeLineSuite;

pub use effect::{take_unowned_messages, Effect, FrameSource, Message};
pub use frame::Frame;
use params::ParamValue;
use props::PropertySet;

/// Message id the plugin uses for the user's mistakes.
pub const BAD_INPUT_ID: &str = "net.morphfx.BadInput";

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ErrorKind {
    /// Exit status 2: the input is at fault, an output could not be
    /// written, or the run was interrupted (the message says which).
    BadInput,
    /// Exit status 1.
    Failed,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HostError {
    pub kind: ErrorKind,
    pub message: String,
}

impl HostError {
    pub fn bad(m: impl Into<String>) -> Self {
        HostError {
            kind: ErrorKind::BadInput,
            message: m.into(),
        }
    }
    pub fn failed(m: impl Into<String>) -> Self {
        HostError {
            kind: ErrorKind::Failed,
            message: m.into(),
        }
    }
}

impl std::fmt::Display for HostError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}
impl std::error::Error for HostError {}

/// What a host offers beyond the basics.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HostOptions {
    /// Overlay interacts (and the interact suite), as a host with a viewer.
    pub overlays: bool,
    /// The OFX 1.5 Draw suite, recording every call.
    pub draw_suite: bool,
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

/// What this host saw a plugin do against the spec, for tests to fail on.
static VIOLATIONS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Records a spec violation by the plugin (and says it on stderr).
pub fn violation(what: String) {
    eprintln!("morphfx: the plugin broke the OpenFX spec: {what}");
    VIOLATIONS
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(what);
}

/// Records a failure of this host itself (a callback that panicked): kept
/// with the violations, so tests fail on it, but not blamed on the plugin.
pub fn host_failure(what: String) {
    eprintln!("morphfx: host failure: {what}");
    VIOLATIONS
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(what);
}

/// Held by unit tests that read [`take_violations`], which is process-wide.
#[cfg(test)]
pub(crate) static VIOLATION_TESTS: Mutex<()> = Mutex::new(());

/// The spec violations seen so far in this process (taken).
pub fn take_violations() -> Vec<String> {
    std::mem::take(&mut *VIOLATIONS.lock().unwrap_or_else(|e| e.into_inner()))
}

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
        let loaded = LOADED_HOSTS
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .contains(&(host as usize));
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
                if n == overlay::kOfxInteractSuite
                    && offers(host, kOfxImageEffectPropSupportsOverlays) =>
            {
                &overlay::INTERACT_SUITE as *const _ as *const c_void
            }
            (n, 1) if n == overlay::kOfxDrawSuite && offers(host, overlay::DRAW_SUITE_PROP) => {
                &overlay::DRAW_SUITE as *const _ as *const c_void
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
    plugin: *const OfxPlugin,
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
fn accept(st: OfxStatus, what: &str, effect: &Effect) -> Result<(), HostError> {
    if st == kOfxStatOK || st == kOfxStatReplyDefault {
        Ok(())
    } else {
        Err(failure(st, what, Some(effect)))
    }
}

/// A new instance of `descriptor` in `context`: its params and clips copied
/// from the descriptor, the clips unconnected until a job connects them.
fn instance_effect(descriptor: &Effect, context: &str) -> Box<Effect> {
    let effect = Effect::new();
    for (k, v) in [
        (kOfxPropType, "OfxTypeImageEffectInstance"),
        (kOfxImageEffectPropContext, context),
    ] {
        effect.props.set_str(k, v);
    }
    effect
        .props
        .set_double(kOfxImageEffectPropFrameRate, &[24.0]);
    effect
        .props
        .set_double(kOfxImageEffectPropProjectPixelAspectRatio, &[1.0]);
    effect
        .props
        .set_ptr(kOfxPropInstanceData, std::ptr::null_mut());
    let desc_params = params::ParamSet::instance_of(&descriptor.params);
    *effect
        .params
        .params
        .lock()
        .unwrap_or_else(|e| e.into_inner()) =
        std::mem::take(&mut *desc_params.params.lock().unwrap_or_else(|e| e.into_inner()));
    for name in descriptor.clip_names() {
        let desc_clip = descriptor.clip(&name).expect("listed");
        let clip = effect.add_clip(&name, desc_clip.props.clone_values());
        clip.props.set_int(kOfxImageClipPropConnected, &[0]);
        clip.props
            .set_str(kOfxImageClipPropFieldOrder, "OfxImageFieldNone");
        clip.props.set_double(kOfxImagePropPixelAspectRatio, &[1.0]);
        clip.props.set_double(kOfxImageEffectPropFrameRate, &[24.0]);
    }
    effect
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
    host_props.set_int(overlay::DRAW_SUITE_PROP, &[options.draw_suite as i32]);
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

    fn call(
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

    /// Loads, describes and instantiates plugin `id` in `context`.
    pub fn instance(&self, id: &str, context: &str) -> Result<Instance<'_>, HostError> {
        let info = self.plugins.iter().find(|p| p.id == id).ok_or_else(|| {
            HostError::bad(format!(
                "bundle {} has no plugin {id}",
                self.binary.display()
            ))
        })?;
        let plugin = info.plugin;
        self.send_load(plugin)?;
        let descriptor = self.describe(plugin, id, context)?;
        let effect = instance_effect(&descriptor, context);
        let st = self.call(
            plugin,
            kOfxActionCreateInstance,
            effect.handle() as *const c_void,
            None,
            None,
        );
        accept(st, "createInstance", &effect)?;
        Ok(Instance {
            bundle: self,
            plugin,
            _descriptor: descriptor,
            effect,
        })
    }

    /// Describe, then describe in `context`: the plugin's descriptor.
    fn describe(
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
    fn send_load(&self, plugin: *const OfxPlugin) -> Result<(), HostError> {
        let mut loaded = self.loaded.lock().unwrap_or_else(|e| e.into_inner());
        if loaded.contains(&(plugin as usize)) {
            return Ok(());
        }
        LOADED_HOSTS
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(self.host.host as usize);
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
        let loaded = std::mem::take(&mut *self.loaded.lock().unwrap_or_else(|e| e.into_inner()));
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
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .retain(|h| *h != self.host.host as usize);
    }
}

fn failure(status: OfxStatus, what: &str, effect: Option<&Effect>) -> HostError {
    let mut messages = effect.map(|e| e.take_messages()).unwrap_or_default();
    // Render-time errors arrive as the persistent message (message suite v2).
    if let Some(m) = effect.and_then(|e| {
        e.persistent
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }) {
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

/// One plugin instance with its clips and params.
pub struct Instance<'b> {
    bundle: &'b Bundle,
    plugin: *const OfxPlugin,
    _descriptor: Box<Effect>,
    pub effect: Box<Effect>,
}

/// How the output image is laid out (for testing host variety).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputSpec {
    pub depth: &'static str,
    pub channels: usize,
    pub top_down: bool,
    pub render_scale: (f64, f64),
    /// Split the window into this many bands rendered concurrently.
    pub tiles: usize,
    /// Ask isIdentity first and copy the source it names, as hosts do
    /// (off: always render, to compare the plugin's own pixels).
    pub identity: bool,
    /// This host renders the sequence in frame order on this instance
    /// (kOfxImageEffectPropSequentialRenderStatus = 1).
    pub sequential: bool,
    /// Host misuse: send this render window, whatever the output image
    /// covers (`None`: the image's bounds, in tiles).
    pub window: Option<RectI>,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            depth: "OfxBitDepthFloat",
            channels: 4,
            top_down: false,
            render_scale: (1.0, 1.0),
            tiles: 1,
            identity: true,
            sequential: false,
            window: None,
        }
    }
}

impl Instance<'_> {
    fn param(&self, name: &str) -> Result<&params::Param, HostError> {
        self.effect
            .params
            .get(name)
            .ok_or_else(|| HostError::bad(format!("the plugin has no param {name}")))
    }

    /// The plugin's descriptor properties (what describe set).
    pub fn descriptor_props(&self) -> &PropertySet {
        &self._descriptor.props
    }

    pub fn param_names(&self) -> Vec<(String, String)> {
        self.effect.params.names()
    }

    pub fn param_props(&self, name: &str) -> Option<&PropertySet> {
        self.effect.params.get(name).map(|p| &p.props)
    }

    pub fn set_double(
        &self,
        name: &str,
        values: &[f64],
        time: Option<f64>,
    ) -> Result<(), HostError> {
        let p = self.param(name)?;
        let mut v = ParamValue::default();
        v.d[..values.len()].copy_from_slice(values);
        match time {
            Some(t) => p.set_key(t, v),
            None => p.set(v),
        }
        Ok(())
    }

    /// Tells the plugin to drop what it caches (`kOfxActionPurgeCaches`).
    pub fn purge_caches(&self) -> Result<(), HostError> {
        self.act(kOfxActionPurgeCaches, None, None).map(|_| ())
    }

    /// The messages the plugin posted since the last call (message suite).
    pub fn take_messages(&self) -> Vec<Message> {
        self.effect.take_messages()
    }

    /// The times of a param's keys, in order.
    pub fn key_times(&self, name: &str) -> Result<Vec<f64>, HostError> {
        Ok(self.param(name)?.key_times())
    }

    /// The values of a double-valued param at `time` (keys interpolated).
    pub fn doubles_at(&self, name: &str, time: f64) -> Result<Vec<f64>, HostError> {
        let p = self.param(name)?;
        let n = match p.shape() {
            params::Shape::Double(n) => n,
            _ => return Err(HostError::bad(format!("{name} is not a double param"))),
        };
        Ok(p.value_at(time).d[..n].to_vec())
    }

    /// The user will press cancel on the plugin's progress bar once it
    /// reaches `at` (`None`: never).
    pub fn cancel_progress_at(&self, at: Option<f64>) {
        *self
            .effect
            .cancel_at
            .lock()
            .unwrap_or_else(|e| e.into_inner()) = at;
    }

    /// Every progress the plugin reported so far, and whether a progress
    /// task is still open.
    pub fn progress_log(&self) -> (Vec<f64>, bool) {
        let log = self
            .effect
            .progress_log
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone();
        let open = self
            .effect
            .progress
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .is_some();
        (log, open)
    }

    /// Tells the plugin the user changed (or pressed) param `name` at `time`.
    pub fn instance_changed(&self, name: &str, time: f64) -> Result<(), HostError> {
        *self
            .effect
            .render_scale
            .lock()
            .unwrap_or_else(|e| e.into_inner()) = (1.0, 1.0);
        let name = CString::new(name).map_err(|_| HostError::bad("NUL in a param name"))?;
        let a = PropertySet::new();
        a.set_str(kOfxPropType, "OfxTypeParameter");
        a.set_str(kOfxPropName, &name.to_string_lossy());
        a.set_str(kOfxPropChangeReason, "OfxChangeUserEdited");
        a.set_double(kOfxPropTime, &[time]);
        a.set_double(kOfxImageEffectPropRenderScale, &[1.0, 1.0]);
        self.act(kOfxActionBeginInstanceChanged, Some(&a), None)?;
        let result = self.act(kOfxActionInstanceChanged, Some(&a), None);
        self.act(kOfxActionEndInstanceChanged, Some(&a), None)?;
        result.map(|_| ())
    }

    pub fn set_int(&self, name: &str, value: i32) -> Result<(), HostError> {
        let p = self.param(name)?;
        let mut v = ParamValue::default();
        v.i[0] = value;
        p.set(v);
        Ok(())
    }

    pub fn set_string(&self, name: &str, value: &str) -> Result<(), HostError> {
        let p = self.param(name)?;
        p.set(ParamValue {
            s: CString::new(value).map_err(|_| HostError::bad(format!("{name}: NUL in text")))?,
            ..Default::default()
        });
        Ok(())
    }

    /// Sets `name`'s option by its label (choice params).
    pub fn set_choice(&self, name: &str, option: &str) -> Result<(), HostError> {
        let p = self.param(name)?;
        let options = p.props.strs(kOfxParamPropChoiceOption);
        let i = options
            .iter()
            .position(|o| o == option || o.split(' ').next() == Some(option))
            .ok_or_else(|| {
                HostError::bad(format!(
                    "{name}: unknown option \"{option}\" (one of {})",
                    options.join(", ")
                ))
            })?;
        self.set_int(name, i as i32)
    }

    pub fn connect(&self, clip: &str, source: Arc<dyn FrameSource>) -> Result<(), HostError> {
        let c = self
            .effect
            .clip(clip)
            .ok_or_else(|| HostError::bad(format!("the plugin has no clip {clip}")))?;
        if let Some((first, last)) = source.range() {
            c.props
                .set_double(kOfxImageEffectPropFrameRange, &[first, last]);
        }
        *c.source.lock().unwrap_or_else(|e| e.into_inner()) = Some(source);
        c.props.set_int(kOfxImageClipPropConnected, &[1]);
        Ok(())
    }

    /// Anamorphic footage: pixels `par` canonical units wide, for the project
    /// and every clip (connect frames with the same `par`).
    pub fn set_pixel_aspect(&self, par: f64) {
        self.effect
            .props
            .set_double(kOfxImageEffectPropProjectPixelAspectRatio, &[par]);
        let clips = self.effect.clips.lock().unwrap_or_else(|e| e.into_inner());
        for clip in clips.iter() {
            clip.props.set_double(kOfxImagePropPixelAspectRatio, &[par]);
        }
    }

    fn pixel_aspect(&self) -> f64 {
        let par = self
            .effect
            .props
            .doubles(kOfxImageEffectPropProjectPixelAspectRatio);
        par.first().copied().filter(|p| *p > 0.0).unwrap_or(1.0)
    }

    /// The project's images (size at offset), canonical, rounded out.
    fn project_rect(&self) -> RectI {
        let p = &self.effect.props;
        let (size, offset) = (
            p.doubles(kOfxImageEffectPropProjectSize),
            p.doubles(kOfxImageEffectPropProjectOffset),
        );
        let (w, h) = (
            size.first().copied().unwrap_or(0.0),
            size.get(1).copied().unwrap_or(0.0),
        );
        let (x, y) = (
            offset.first().copied().unwrap_or(0.0),
            offset.get(1).copied().unwrap_or(0.0),
        );
        RectI::new(
            x.floor() as i32,
            y.floor() as i32,
            (x + w).ceil() as i32,
            (y + h).ceil() as i32,
        )
    }

    pub fn set_project(&self, width: f64, height: f64) {
        self.set_letterboxed_project((width, height), (0.0, 0.0), (width, height));
    }

    /// A project whose images fill `size` at `offset` inside an `extent`
    /// rooted at 0,0 (a letterboxed format: the spec's project properties).
    pub fn set_letterboxed_project(
        &self,
        extent: (f64, f64),
        offset: (f64, f64),
        size: (f64, f64),
    ) {
        let p = &self.effect.props;
        p.set_double(kOfxImageEffectPropProjectExtent, &[extent.0, extent.1]);
        p.set_double(kOfxImageEffectPropProjectOffset, &[offset.0, offset.1]);
        p.set_double(kOfxImageEffectPropProjectSize, &[size.0, size.1]);
    }

    fn act(
        &self,
        action: &CStr,
        in_args: Option<&PropertySet>,
        out_args: Option<&PropertySet>,
    ) -> Result<OfxStatus, HostError> {
        let st = self.bundle.call(
            self.plugin,
            action,
            self.effect.handle() as *const c_void,
            in_args,
            out_args,
        );
        if st == kOfxStatOK || st == kOfxStatReplyDefault {
            Ok(st)
        } else {
            Err(failure(st, &action.to_string_lossy(), Some(&self.effect)))
        }
    }

    /// How many calls of the variadic value functions (get or set) the
    /// plugin made on param `name` so far.
    pub fn value_calls(&self, name: &str) -> usize {
        self.effect.params.get(name).map_or(0, |p| {
            p.value_calls.load(std::sync::atomic::Ordering::Relaxed)
        })
    }

    /// Sends `action` as a misbehaving host might (tests of the plugin's
    /// answers): with no effect handle when `null_handle`, and the
    /// arguments as given. The plugin's status, as it answered, and the
    /// messages it posted on the instance (its persistent one taken too).
    pub fn send_raw(
        &self,
        action: &CStr,
        null_handle: bool,
        in_args: Option<&PropertySet>,
        out_args: Option<&PropertySet>,
    ) -> (OfxStatus, Vec<Message>) {
        let handle = if null_handle {
            std::ptr::null()
        } else {
            self.effect.handle() as *const c_void
        };
        self.effect.take_messages();
        let status = self
            .bundle
            .call(self.plugin, action, handle, in_args, out_args);
        let mut messages = self.effect.take_messages();
        messages.extend(
            self.effect
                .persistent
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .take(),
        );
        (status, messages)
    }

    fn sequence_args(first: f64, last: f64) -> PropertySet {
        let a = PropertySet::new();
        a.set_double(kOfxImageEffectPropFrameRange, &[first, last]);
        a.set_double(kOfxImageEffectPropFrameStep, &[1.0]);
        a.set_int(kOfxPropIsInteractive, &[0]);
        a.set_double(kOfxImageEffectPropRenderScale, &[1.0, 1.0]);
        a
    }

    pub fn begin_sequence(&self, first: f64, last: f64) -> Result<(), HostError> {
        *self
            .effect
            .timeline
            .lock()
            .unwrap_or_else(|e| e.into_inner()) = (first, first, last);
        let a = Self::sequence_args(first, last);
        self.act(kOfxImageEffectActionBeginSequenceRender, Some(&a), None)
            .map(|_| ())
    }

    pub fn end_sequence(&self, first: f64, last: f64) -> Result<(), HostError> {
        let a = Self::sequence_args(first, last);
        self.act(kOfxImageEffectActionEndSequenceRender, Some(&a), None)
            .map(|_| ())
    }

    /// The plugin's clip preferences (`kOfxImageEffectActionGetClipPreferences`),
    /// as hosts ask after connecting clips: the out-args it set.
    pub fn clip_preferences(&self) -> Result<PropertySet, HostError> {
        let out = PropertySet::new();
        out.set_int(kOfxImageEffectFrameVarying, &[0]);
        out.set_str(
            kOfxImageEffectPropPreMultiplication,
            "OfxImagePreMultiplied",
        );
        self.act(kOfxImageEffectActionGetClipPreferences, None, Some(&out))?;
        Ok(out)
    }

    /// The output's region of definition at `time` (canonical): the
    /// plugin's, or where it replies default, the host's default.
    pub fn region_of_definition(&self, time: f64, scale: (f64, f64)) -> Result<RectI, HostError> {
        let a = PropertySet::new();
        a.set_double(kOfxPropTime, &[time]);
        a.set_double(kOfxImageEffectPropRenderScale, &[scale.0, scale.1]);
        let out = PropertySet::new();
        // The spec: the host sets the out-arg to the default first.
        let d = self.default_region(time);
        out.set_double(
            kOfxImageEffectPropRegionOfDefinition,
            &[d.x1 as f64, d.y1 as f64, d.x2 as f64, d.y2 as f64],
        );
        self.act(
            kOfxImageEffectActionGetRegionOfDefinition,
            Some(&a),
            Some(&out),
        )?;
        let r = out.doubles(kOfxImageEffectPropRegionOfDefinition);
        if r.len() != 4 {
            return Err(HostError::failed("the plugin gave no region of definition"));
        }
        Ok(RectI::new(
            r[0].floor() as i32,
            r[1].floor() as i32,
            r[2].ceil() as i32,
            r[3].ceil() as i32,
        ))
    }

    /// The spec's default region of definition, as for the filter,
    /// transition and general contexts: the union of the (non-optional)
    /// input clips' regions; this host gives an unconnected clip none, and
    /// with none at all the default is the project's.
    fn default_region(&self, time: f64) -> RectI {
        let clips = self.effect.clips.lock().unwrap_or_else(|e| e.into_inner());
        clips
            .iter()
            .filter(|c| c.name != "Output")
            .filter(|c| c.props.ints(kOfxImageClipPropOptional).first() != Some(&1))
            .filter_map(|c| c.rod(time))
            .reduce(|u, r| {
                RectI::new(
                    u.x1.min(r.x1),
                    u.y1.min(r.y1),
                    u.x2.max(r.x2),
                    u.y2.max(r.y2),
                )
            })
            .unwrap_or_else(|| self.project_rect())
    }

    /// Asks the plugin whether the output at `time` is one of its sources
    /// unchanged (`kOfxImageEffectActionIsIdentity`), as hosts do before
    /// rendering: `Some((clip, time))` when it is.
    pub fn identity(
        &self,
        time: f64,
        window: RectI,
        scale: (f64, f64),
    ) -> Result<Option<(String, f64)>, HostError> {
        let a = PropertySet::new();
        a.set_double(kOfxPropTime, &[time]);
        a.set_str(kOfxImageEffectPropFieldToRender, "OfxImageFieldNone");
        a.set_int(
            kOfxImageEffectPropRenderWindow,
            &[window.x1, window.y1, window.x2, window.y2],
        );
        a.set_double(kOfxImageEffectPropRenderScale, &[scale.0, scale.1]);
        let out = PropertySet::new();
        out.set_str(kOfxPropName, "");
        out.set_double(kOfxPropTime, &[time]);
        if self.act(kOfxImageEffectActionIsIdentity, Some(&a), Some(&out))? != kOfxStatOK {
            return Ok(None);
        }
        let name = out
            .strs(kOfxPropName)
            .into_iter()
            .next()
            .unwrap_or_default();
        let at = out.doubles(kOfxPropTime).first().copied().unwrap_or(time);
        if self.effect.clip(&name).is_none() || name == "Output" {
            return Err(HostError::failed(format!(
                "isIdentity named clip \"{name}\", which is not one of the plugin's source clips"
            )));
        }
        Ok(Some((name, at)))
    }

    /// Renders the frame at `time` into a new buffer laid out as `spec`,
    /// or copies the source the plugin names as identical.
    /// Interlaced footage, `order` (`OfxImageFieldLower` or `Upper`) first:
    /// renders then go field by field as the plugin asks.
    pub fn set_field_order(&self, order: &'static str) {
        *self
            .effect
            .field_order
            .lock()
            .unwrap_or_else(|e| e.into_inner()) = Some(order);
        let clips = self.effect.clips.lock().unwrap_or_else(|e| e.into_inner());
        for clip in clips.iter() {
            clip.props.set_str(kOfxImageClipPropFieldOrder, order);
        }
    }

    /// Renders frame `time`. Interlaced footage goes as the spec says: with
    /// `FieldRenderTwiceAlways` (the default), once per field, the first at
    /// `time` and the second at `time + 0.5`, each from single-field sources
    /// with lines doubled, the output interleaving the two; otherwise once,
    /// both fields at a time (this host animates nothing it renders).
    pub fn render(&self, time: f64, spec: OutputSpec) -> Result<Arc<Frame>, HostError> {
        let order = *self
            .effect
            .field_order
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        let Some(first) = order else {
            return self.render_field(time, spec, "OfxImageFieldNone");
        };
        let twice = self
            .descriptor_props()
            .ints(kOfxImageEffectPluginPropFieldRenderTwiceAlways)
            .first()
            .is_none_or(|v| *v != 0);
        if !twice {
            return self.render_field(time, spec, "OfxImageFieldBoth");
        }
        let second = if first == "OfxImageFieldLower" {
            "OfxImageFieldUpper"
        } else {
            "OfxImageFieldLower"
        };
        let a = self.render_field(time, spec, first)?.to_image();
        let b = self.render_field(time + 0.5, spec, second)?.to_image();
        *self.effect.field.lock().unwrap_or_else(|e| e.into_inner()) = "OfxImageFieldNone";
        let upper_first = first == "OfxImageFieldUpper";
        let both = morphfx::image::Image::from_fn(a.bounds, a.channels, |i, j, c| {
            let upper = j.rem_euclid(2) == 1;
            if upper == upper_first {
                a.pixel(i, j)[c]
            } else {
                b.pixel(i, j)[c]
            }
        });
        let mut out = Frame::from_image(&both, spec.depth, spec.top_down);
        out.par = self.pixel_aspect();
        Ok(Arc::new(out))
    }

    fn render_field(
        &self,
        time: f64,
        spec: OutputSpec,
        field: &'static str,
    ) -> Result<Arc<Frame>, HostError> {
        self.set_render_state(time, spec.render_scale, field);
        let bounds = self.output_bounds(time, spec.render_scale)?;
        if spec.identity {
            if let Some((clip, at)) = self.identity(time, bounds, spec.render_scale)? {
                return Ok(self.pass_through(&clip, at, bounds, spec));
            }
        }
        let mut out = Frame::blank(bounds, spec.channels, spec.depth, spec.top_down);
        out.par = self.pixel_aspect();
        let out = Arc::new(out);
        let out_clip = self
            .effect
            .clip("Output")
            .ok_or_else(|| HostError::failed("the plugin has no Output clip"))?;
        *out_clip.output.lock().unwrap_or_else(|e| e.into_inner()) = Some(out.clone());
        out_clip
            .props
            .set_str(kOfxImageEffectPropPixelDepth, spec.depth);
        let result = self.render_tiles(time, spec, field, bounds);
        *out_clip.output.lock().unwrap_or_else(|e| e.into_inner()) = None;
        result?;
        Ok(out)
    }

    /// What the plugin may ask the host during a render: the field, the
    /// time on the timeline and the render scale.
    fn set_render_state(&self, time: f64, scale: (f64, f64), field: &'static str) {
        *self.effect.field.lock().unwrap_or_else(|e| e.into_inner()) = field;
        self.effect.take_messages();
        self.effect
            .timeline
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .0 = time;
        *self
            .effect
            .render_scale
            .lock()
            .unwrap_or_else(|e| e.into_inner()) = scale;
    }

    /// The pixels to render: the region of definition at `scale` (the
    /// project where it is infinite, as a viewer shows it).
    fn output_bounds(&self, time: f64, scale: (f64, f64)) -> Result<RectI, HostError> {
        let rod = self.region_of_definition(time, scale)?;
        let rod = if rod.x1 <= i32::MIN / 2 || rod.x2 >= i32::MAX / 2 {
            rod.intersect(&self.project_rect())
        } else {
            rod
        };
        // Pixels: canonical x divided by the pixel aspect ratio.
        let par = self.pixel_aspect();
        let (sx, sy) = scale;
        Ok(RectI::new(
            (rod.x1 as f64 * sx / par).floor() as i32,
            (rod.y1 as f64 * sy).floor() as i32,
            (rod.x2 as f64 * sx / par).ceil() as i32,
            (rod.y2 as f64 * sy).ceil() as i32,
        ))
    }

    /// An identity render: the clip's frame at `at`, as the host copies it.
    fn pass_through(&self, clip: &str, at: f64, bounds: RectI, spec: OutputSpec) -> Arc<Frame> {
        let source = self
            .effect
            .clip(clip)
            .and_then(|c| c.frame_at(at).ok().flatten());
        let image = match source {
            Some(f) => frame::with_channels(&f.to_image(), spec.channels),
            None => morphfx::image::Image::new(bounds, spec.channels),
        };
        Arc::new(Frame::from_image(&image, spec.depth, spec.top_down))
    }

    /// The render action over `spec.tiles` horizontal bands of `bounds`,
    /// each on its own thread as a multi-threaded host would.
    fn render_tiles(
        &self,
        time: f64,
        spec: OutputSpec,
        field: &'static str,
        bounds: RectI,
    ) -> Result<(), HostError> {
        let tiles = spec.tiles.max(1) as i32;
        let band = (bounds.height() as i32 + tiles - 1) / tiles;
        let windows: Vec<RectI> = (0..tiles)
            .map(|k| {
                RectI::new(
                    bounds.x1,
                    bounds.y1 + k * band,
                    bounds.x2,
                    (bounds.y1 + (k + 1) * band).min(bounds.y2),
                )
            })
            .filter(|w| !w.is_empty())
            .collect();
        let (sx, sy) = spec.render_scale;
        let render_one = |w: RectI| {
            let a = PropertySet::new();
            a.set_double(kOfxPropTime, &[time]);
            a.set_str(kOfxImageEffectPropFieldToRender, field);
            a.set_int(kOfxImageEffectPropRenderWindow, &[w.x1, w.y1, w.x2, w.y2]);
            a.set_double(kOfxImageEffectPropRenderScale, &[sx, sy]);
            a.set_int(
                kOfxImageEffectPropSequentialRenderStatus,
                &[spec.sequential as i32],
            );
            a.set_int(kOfxImageEffectPropInteractiveRenderStatus, &[0]);
            self.act(kOfxImageEffectActionRender, Some(&a), None)
                .map(|_| ())
        };
        if let Some(w) = spec.window {
            return render_one(w);
        }
        if windows.len() == 1 {
            return render_one(windows[0]);
        }
        std::thread::scope(|s| {
            let handles: Vec<_> = windows
                .iter()
                .map(|w| s.spawn(move || render_one(*w)))
                .collect();
            handles.into_iter().try_for_each(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(HostError::failed("render thread panicked")))
            })
        })
    }
}

impl Drop for Instance<'_> {
    fn drop(&mut self) {
        let _ = self.bundle.call(
            self.plugin,
            kOfxActionDestroyInstance,
            self.effect.handle() as *const c_void,
            None,
            None,
        );
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
// SAFETY: an instance's host state is behind its own locks, and the plugin
// declares its renders fully thread safe.
unsafe impl Sync for Instance<'_> {}
