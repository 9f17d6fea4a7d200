//! Which build of the plugin runs on this CPU.
//!
//! The bundle holds two builds of the same code: `MorphFX.ofx`, compiled for
//! baseline x86-64 (SSE2), and beside it `MorphFX-x86-64-v3.so`, compiled for
//! x86-64-v3 (AVX2 + FMA), whose kernels are twice as fast. A host loads
//! `MorphFX.ofx`, and must be able to on any x86-64 CPU: its exports and this
//! check are baseline code. When the CPU has AVX2 and FMA, the baseline build
//! hands every entry point to the v3 build (the host then holds the v3 build's
//! plugin structs, so every later call goes straight there); otherwise it
//! runs itself. Whole builds rather than per-function target features keep
//! every kernel (and every inlined `wide` vector op) compiled for one CPU,
//! bit for bit what the benchmarks measure, with no `unsafe` in the core.

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::sync::OnceLock;

use openfx::sys::generic::core::*;

/// Name of the fast build, next to the baseline binary.
pub const FAST_BUILD: &str = "MorphFX-x86-64-v3.so";

/// `MORPHFX_CPU=baseline` runs the baseline build whatever the CPU offers:
/// how tests see what a host on a CPU without AVX2 sees. Read once.
pub const CPU_VARIABLE: &str = "MORPHFX_CPU";

/// The fast build's three exports.
pub struct FastBuild {
    pub set_host: unsafe extern "C" fn(*const OfxHost) -> OfxStatus,
    pub count: unsafe extern "C" fn() -> c_int,
    pub get: unsafe extern "C" fn(c_int) -> *mut OfxPlugin,
}

/// Whether this binary itself was compiled for AVX2 + FMA.
const THIS_IS_FAST: bool = cfg!(all(target_feature = "avx2", target_feature = "fma"));

/// Which build this binary is, as the plugin's description ends: the one
/// a host's calls reach (the baseline build hands them all to the v3 one
/// when it can), so a user or a benchmark can tell which code ran.
pub fn this_build() -> &'static str {
    if THIS_IS_FAST {
        "x86-64-v3 build with AVX2 and FMA"
    } else {
        "baseline x86-64 build"
    }
}

/// Whether this CPU can run the fast build (baseline code: the detection is
/// real here, not folded to a constant as it would be in the v3 build).
fn cpu_has_v3() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// The fast build to delegate to, loaded on first use; `None` to run here.
pub fn fast_build() -> Option<&'static FastBuild> {
    static FAST: OnceLock<Option<FastBuild>> = OnceLock::new();
    FAST.get_or_init(|| {
        if THIS_IS_FAST
            || std::env::var(CPU_VARIABLE).is_ok_and(|v| v == "baseline")
            || !cpu_has_v3()
        {
            return None;
        }
        let path = own_path()?.with_file_name(FAST_BUILD);
        if !path.is_file() {
            return None;
        }
        // SAFETY: the file is our own v3 build, next to this binary; loading
        // it runs only Rust's static initialisers, and this CPU runs its code
        // (checked above).
        let fast = unsafe { load(&path) };
        if fast.is_none() {
            // Never a panic here: stderr may be closed inside a host.
            use std::io::Write;
            let _ = writeln!(
                std::io::stderr(),
                "MorphFX: could not load {}; running the baseline build",
                path.display()
            );
        }
        fast
    })
    .as_ref()
}

/// This binary's path, from the dynamic loader.
fn own_path() -> Option<std::path::PathBuf> {
    let mut info = libc::Dl_info {
        dli_fname: std::ptr::null(),
        dli_fbase: std::ptr::null_mut(),
        dli_sname: std::ptr::null(),
        dli_saddr: std::ptr::null_mut(),
    };
    let here = fast_build as *const c_void;
    // SAFETY: dladdr only reads the loader's tables; `info` is a live local.
    if unsafe { libc::dladdr(here, &mut info) } == 0 || info.dli_fname.is_null() {
        return None;
    }
    // SAFETY: dli_fname is a NUL-terminated path owned by the loader.
    let name = unsafe { CStr::from_ptr(info.dli_fname) };
    use std::os::unix::ffi::OsStrExt;
    Some(std::path::Path::new(std::ffi::OsStr::from_bytes(name.to_bytes())).to_path_buf())
}

/// Opens `path` for good (never closed: the host keeps pointers into it) and
/// resolves the three OFX exports.
///
/// # Safety
/// `path` must be a build of this crate for a CPU that this one can run.
unsafe fn load(path: &std::path::Path) -> Option<FastBuild> {
    use std::os::unix::ffi::OsStrExt;
    let c_path = CString::new(path.as_os_str().as_bytes()).ok()?;
    // SAFETY: a NUL-terminated path; RTLD_LOCAL keeps its symbols from
    // shadowing the host's or ours.
    let lib = unsafe { libc::dlopen(c_path.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
    if lib.is_null() {
        return None;
    }
    let sym = |name: &CStr| -> Option<*mut c_void> {
        // SAFETY: `lib` is a live handle from dlopen; the name is NUL-terminated.
        let p = unsafe { libc::dlsym(lib, name.as_ptr() as *const c_char) };
        (!p.is_null()).then_some(p)
    };
    let (set_host, count, get) = (
        sym(c"OfxSetHost")?,
        sym(c"OfxGetNumberOfPlugins")?,
        sym(c"OfxGetPlugin")?,
    );
    // SAFETY: these are our own exports (exports.rs), with these signatures.
    unsafe {
        Some(FastBuild {
            set_host: std::mem::transmute::<
                *mut c_void,
                unsafe extern "C" fn(*const OfxHost) -> OfxStatus,
            >(set_host),
            count: std::mem::transmute::<*mut c_void, unsafe extern "C" fn() -> c_int>(count),
            get: std::mem::transmute::<*mut c_void, unsafe extern "C" fn(c_int) -> *mut OfxPlugin>(
                get,
            ),
        })
    }
}
