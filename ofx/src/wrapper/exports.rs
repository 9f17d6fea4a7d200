//! The three symbols a host looks up, written by hand: `OfxSetHost` must return
//! an `OfxStatus` (the `openfx` crate's export macro gets this wrong).

use std::ffi::{c_int, CString};
use std::sync::OnceLock;

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;

use super::dispatch::dispatch;
use super::{cpu, host};
use crate::nodes::{NodeKind, PLUGIN_VERSION};

/// Strings the host may read for as long as the binary is loaded.
struct Statics {
    /// Owns the identifier strings the plugin structs point into.
    _ids: Vec<CString>,
    plugins: Vec<OfxPlugin>,
}

// SAFETY: the plugin structs hold pointers to the `ids` CStrings and to
// immutable statics only; nothing is ever written after initialisation.
unsafe impl Send for Statics {}
// SAFETY: as above.
unsafe impl Sync for Statics {}

static STATICS: OnceLock<Statics> = OnceLock::new();

entry_point!(morph_main, NodeKind::Morph, dispatch);
entry_point!(warp_main, NodeKind::Warp, dispatch);

unsafe extern "C" fn set_host_v1(host: *mut OfxHost) {
    let _ = std::panic::catch_unwind(|| host::set_host(host));
}

fn statics() -> &'static Statics {
    STATICS.get_or_init(|| {
        let ids: Vec<CString> = NodeKind::ALL
            .iter()
            .map(|k| CString::new(k.info().id).expect("ids have no NUL"))
            .collect();
        let plugins = NodeKind::ALL
            .iter()
            .zip(&ids)
            .map(|(kind, id)| OfxPlugin {
                pluginApi: kOfxImageEffectPluginApi.as_ptr(),
                apiVersion: 1,
                pluginIdentifier: id.as_ptr(),
                pluginVersionMajor: PLUGIN_VERSION.0,
                pluginVersionMinor: PLUGIN_VERSION.1,
                setHost: Some(set_host_v1),
                mainEntry: Some(match kind {
                    NodeKind::Morph => morph_main,
                    NodeKind::Warp => warp_main,
                }),
            })
            .collect();
        Statics { _ids: ids, plugins }
    })
}

/// # Safety
/// Called by OFX hosts with a valid host struct (or null, refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn OfxSetHost(host: *const OfxHost) -> OfxStatus {
    if let Some(fast) = cpu::fast_build() {
        // SAFETY: the fast build's own OfxSetHost, given the host's argument.
        return unsafe { (fast.set_host)(host) };
    }
    match std::panic::catch_unwind(|| host::set_host(host as *mut OfxHost)) {
        Ok(Ok(())) => kOfxStatOK,
        Ok(Err(f)) => f.status(),
        Err(_) => kOfxStatFailed,
    }
}

#[unsafe(no_mangle)]
pub extern "C" fn OfxGetNumberOfPlugins() -> c_int {
    if let Some(fast) = cpu::fast_build() {
        // SAFETY: the fast build's own export, which takes no arguments.
        return unsafe { (fast.count)() };
    }
    std::panic::catch_unwind(|| statics().plugins.len() as c_int).unwrap_or(0)
}

#[unsafe(no_mangle)]
pub extern "C" fn OfxGetPlugin(nth: c_int) -> *mut OfxPlugin {
    if let Some(fast) = cpu::fast_build() {
        // SAFETY: the fast build's own export; its plugin structs live as long
        // as it stays loaded, which is for good.
        return unsafe { (fast.get)(nth) };
    }
    std::panic::catch_unwind(|| {
        let plugins = &statics().plugins;
        match usize::try_from(nth).ok().and_then(|i| plugins.get(i)) {
            // The host only reads through this pointer.
            Some(p) => p as *const OfxPlugin as *mut OfxPlugin,
            None => std::ptr::null_mut(),
        }
    })
    .unwrap_or(std::ptr::null_mut())
}
