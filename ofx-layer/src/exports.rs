//! The three symbols a host looks up, made for a list of node types by
//! [`export!`](crate::export): `OfxSetHost` (which must return an
//! `OfxStatus`, which the `openfx` crate's export macro gets wrong),
//! `OfxGetNumberOfPlugins` and `OfxGetPlugin`. Each hands over to the fast
//! build where the CPU runs it (see `cpu.rs`).

use std::ffi::c_int;

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;

use super::plugin::ImageEffect;
use super::{cpu, dispatch, host};

/// The plugin structs of a bundle, for as long as the binary is loaded.
pub struct Plugins(pub &'static [OfxPlugin]);

// SAFETY: the plugin structs hold pointers to `'static` C strings and
// functions only, and nothing writes to them.
unsafe impl Sync for Plugins {}

/// Node type `E`'s plugin struct.
pub const fn plugin<E: ImageEffect>() -> OfxPlugin {
    OfxPlugin {
        pluginApi: kOfxImageEffectPluginApi.as_ptr(),
        apiVersion: 1,
        pluginIdentifier: E::ID.as_ptr(),
        pluginVersionMajor: E::VERSION.0,
        pluginVersionMinor: E::VERSION.1,
        setHost: Some(set_host_v1),
        mainEntry: Some(dispatch::main_entry::<E>),
    }
}

unsafe extern "C" fn set_host_v1(host: *mut OfxHost) {
    let _ = std::panic::catch_unwind(|| host::set_host(host));
}

/// `OfxSetHost`.
///
/// # Safety
/// Called by OFX hosts with a valid host struct (or null, refused).
pub unsafe fn set_host(host: *const OfxHost) -> OfxStatus {
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

/// `OfxGetNumberOfPlugins`.
pub fn count(plugins: &Plugins) -> c_int {
    if let Some(fast) = cpu::fast_build() {
        // SAFETY: the fast build's own export, which takes no arguments.
        return unsafe { (fast.count)() };
    }
    plugins.0.len() as c_int
}

/// `OfxGetPlugin`.
pub fn get(plugins: &Plugins, nth: c_int) -> *mut OfxPlugin {
    if let Some(fast) = cpu::fast_build() {
        // SAFETY: the fast build's own export; its plugin structs live as long
        // as it stays loaded, which is for good.
        return unsafe { (fast.get)(nth) };
    }
    match usize::try_from(nth).ok().and_then(|i| plugins.0.get(i)) {
        // The host only reads through this pointer.
        Some(p) => p as *const OfxPlugin as *mut OfxPlugin,
        None => std::ptr::null_mut(),
    }
}

/// Exports the bundle's node types, in the order hosts list them: the
/// plugin structs and the three symbols a host looks up. The composition
/// root names its nodes once, here.
#[macro_export]
macro_rules! export {
    ($($node:ty),+ $(,)?) => {
        static PLUGINS: $crate::exports::Plugins =
            $crate::exports::Plugins(&[$($crate::exports::plugin::<$node>()),+]);

        /// # Safety
        /// Called by OFX hosts with a valid host struct (or null, refused).
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn OfxSetHost(
            host: *const $crate::sys::generic::core::OfxHost,
        ) -> $crate::sys::generic::core::OfxStatus {
            // SAFETY: this function's own contract.
            unsafe { $crate::exports::set_host(host) }
        }

        #[unsafe(no_mangle)]
        pub extern "C" fn OfxGetNumberOfPlugins() -> std::ffi::c_int {
            std::panic::catch_unwind(|| $crate::exports::count(&PLUGINS)).unwrap_or(0)
        }

        #[unsafe(no_mangle)]
        pub extern "C" fn OfxGetPlugin(
            nth: std::ffi::c_int,
        ) -> *mut $crate::sys::generic::core::OfxPlugin {
            std::panic::catch_unwind(|| $crate::exports::get(&PLUGINS, nth))
                .unwrap_or(std::ptr::null_mut())
        }
    };
}
