//! The overlay's painter on OpenGL 1.1, for hosts without the Draw suite.
//!
//! GL is opened at run time, never linked: the library the host already
//! has loaded first, else the system's. The bundle then loads where there is
//! no libGL at all, and simply draws nothing there, or when no GL context is
//! current. On Linux a viewer's context may be GLX's (X11) or EGL's (Qt on
//! Wayland, or offscreen); libGL's entry points draw into either.

use std::ffi::{c_double, c_float, c_int, c_uint, c_void};
use std::sync::OnceLock;

use morphfx::geom::Vec2;
use morphfx::strokes;

use super::paint::{Painter, Stipple, LABEL_PX};

type GLenum = c_uint;

const GL_LINES: GLenum = 0x0001;
const GL_LINE_STRIP: GLenum = 0x0003;
const GL_LINE_SMOOTH: GLenum = 0x0B20;
const GL_LINE_STIPPLE: GLenum = 0x0B24;
const GL_BLEND: GLenum = 0x0BE2;
const GL_LINE_SMOOTH_HINT: GLenum = 0x0C52;
const GL_NICEST: GLenum = 0x1102;
const GL_SRC_ALPHA: GLenum = 0x0302;
const GL_ONE_MINUS_SRC_ALPHA: GLenum = 0x0303;
const GL_VIEWPORT: GLenum = 0x0BA2;
const GL_PROJECTION_MATRIX: GLenum = 0x0BA7;
const GL_CURRENT_BIT: GLenum = 0x0001;
const GL_LINE_BIT: GLenum = 0x0004;
const GL_ENABLE_BIT: GLenum = 0x2000;
const GL_COLOR_BUFFER_BIT: GLenum = 0x4000;
const GL_HINT_BIT: GLenum = 0x8000;

/// The GL 1.1 entry points the overlay uses, resolved once.
struct Gl {
    current_context: unsafe extern "system" fn() -> *mut c_void,
    push_attrib: unsafe extern "system" fn(GLenum),
    pop_attrib: unsafe extern "system" fn(),
    enable: unsafe extern "system" fn(GLenum),
    disable: unsafe extern "system" fn(GLenum),
    blend_func: unsafe extern "system" fn(GLenum, GLenum),
    hint: unsafe extern "system" fn(GLenum, GLenum),
    line_width: unsafe extern "system" fn(c_float),
    line_stipple: unsafe extern "system" fn(c_int, u16),
    color4f: unsafe extern "system" fn(c_float, c_float, c_float, c_float),
    begin: unsafe extern "system" fn(GLenum),
    end: unsafe extern "system" fn(),
    vertex2d: unsafe extern "system" fn(c_double, c_double),
    get_doublev: unsafe extern "system" fn(GLenum, *mut c_double),
    get_integerv: unsafe extern "system" fn(GLenum, *mut c_int),
    /// Keeps the library loaded for as long as the pointers above are used.
    _lib: libloading::Library,
}

type EglCurrent = unsafe extern "system" fn() -> *mut c_void;

#[cfg(target_os = "linux")]
const LIBRARY: &str = "libGL.so.1";
#[cfg(target_os = "macos")]
const LIBRARY: &str = "/System/Library/Frameworks/OpenGL.framework/OpenGL";
#[cfg(windows)]
const LIBRARY: &str = "opengl32.dll";

#[cfg(target_os = "linux")]
const CURRENT_CONTEXT: &[u8] = b"glXGetCurrentContext\0";
#[cfg(target_os = "macos")]
const CURRENT_CONTEXT: &[u8] = b"CGLGetCurrentContext\0";
#[cfg(windows)]
const CURRENT_CONTEXT: &[u8] = b"wglGetCurrentContext\0";

/// `name` when the process has it loaded already.
#[cfg(unix)]
fn loaded(name: &str) -> Option<libloading::Library> {
    use libloading::os::unix::{Library, RTLD_NOW};
    // SAFETY: RTLD_NOLOAD only finds a library already in the process; it
    // runs no initialisers.
    let lib = unsafe { Library::open(Some(name), RTLD_NOW | libc::RTLD_NOLOAD) };
    lib.ok().map(Into::into)
}

/// The library the host has loaded, else the system's; `None` without one.
fn open() -> Option<libloading::Library> {
    #[cfg(unix)]
    if let Some(lib) = loaded(LIBRARY) {
        return Some(lib);
    }
    // SAFETY: loading the system's GL runs its initialisers, which every
    // GL application runs; the host process is such an application.
    unsafe { libloading::Library::new(LIBRARY) }.ok()
}

/// EGL's `eglGetCurrentContext`, only from a libEGL the host has loaded:
/// a host that never loaded it has no EGL context to draw into.
#[cfg(target_os = "linux")]
fn open_egl() -> Option<(libloading::Library, EglCurrent)> {
    let lib = loaded("libEGL.so.1")?;
    // SAFETY: EGL 1.0's `EGLContext eglGetCurrentContext(void)`.
    let current: EglCurrent = *unsafe { lib.get(b"eglGetCurrentContext\0") }.ok()?;
    Some((lib, current))
}

/// Elsewhere the window system's own call finds every context.
#[cfg(not(target_os = "linux"))]
fn open_egl() -> Option<(libloading::Library, EglCurrent)> {
    None
}

fn load() -> Option<Gl> {
    let lib = open()?;
    macro_rules! sym {
        ($name:literal) => {
            // SAFETY: the symbol is the GL 1.1 (or GLX/CGL/WGL) function of
            // that name, whose signature the field it is stored in states.
            *unsafe { lib.get(concat!($name, "\0").as_bytes()) }.ok()?
        };
    }
    Some(Gl {
        // SAFETY: as in `sym!`.
        current_context: *unsafe { lib.get(CURRENT_CONTEXT) }.ok()?,
        push_attrib: sym!("glPushAttrib"),
        pop_attrib: sym!("glPopAttrib"),
        enable: sym!("glEnable"),
        disable: sym!("glDisable"),
        blend_func: sym!("glBlendFunc"),
        hint: sym!("glHint"),
        line_width: sym!("glLineWidth"),
        line_stipple: sym!("glLineStipple"),
        color4f: sym!("glColor4f"),
        begin: sym!("glBegin"),
        end: sym!("glEnd"),
        vertex2d: sym!("glVertex2d"),
        get_doublev: sym!("glGetDoublev"),
        get_integerv: sym!("glGetIntegerv"),
        _lib: lib,
    })
}

fn gl() -> Option<&'static Gl> {
    static GL: OnceLock<Option<Gl>> = OnceLock::new();
    GL.get_or_init(load).as_ref()
}

/// EGL, once the host has loaded it (looked for again until then: a host
/// may load it only when it opens its first viewer).
fn egl() -> Option<EglCurrent> {
    static EGL: OnceLock<(libloading::Library, EglCurrent)> = OnceLock::new();
    if let Some((_, current)) = EGL.get() {
        return Some(*current);
    }
    let found = open_egl()?;
    Some(EGL.get_or_init(|| found).1)
}

impl Gl {
    /// Whether the calling thread has a GL context current.
    fn has_context(&self) -> bool {
        // SAFETY: both ask their window system for the calling thread's
        // context; safe with or without one.
        unsafe {
            !(self.current_context)().is_null() || egl().is_some_and(|current| !current().is_null())
        }
    }
}

/// Draws with OpenGL 1.1 into the host's current context; restores the GL
/// state it changes when dropped.
pub struct GlPainter {
    gl: &'static Gl,
    pixel: (f64, f64),
}

impl GlPainter {
    /// A painter, when GL is there and a context is current (a draw action
    /// with GL has one); `None` otherwise.
    pub fn new(host_pixel: (f64, f64)) -> Option<GlPainter> {
        let gl = gl()?;
        if !gl.has_context() {
            return None;
        }
        // SAFETY: a context is current on this thread (checked above), and
        // these calls only save and set state that Drop restores.
        unsafe {
            (gl.push_attrib)(
                GL_CURRENT_BIT | GL_LINE_BIT | GL_ENABLE_BIT | GL_COLOR_BUFFER_BIT | GL_HINT_BIT,
            );
            (gl.enable)(GL_BLEND);
            (gl.blend_func)(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
            (gl.enable)(GL_LINE_SMOOTH);
            (gl.hint)(GL_LINE_SMOOTH_HINT, GL_NICEST);
        }
        let pixel = measured_pixel(gl).unwrap_or(host_pixel);
        Some(GlPainter { gl, pixel })
    }

    /// Canonical units per screen pixel, from the projection when it gives one.
    pub fn pixel(&self) -> (f64, f64) {
        self.pixel
    }

    fn primitive(&mut self, mode: GLenum, points: &[Vec2]) {
        // SAFETY: a context is current for the painter's life (`new`).
        unsafe {
            (self.gl.begin)(mode);
            for p in points {
                (self.gl.vertex2d)(p.x, p.y);
            }
            (self.gl.end)();
        }
    }
}

/// The projection's canonical units per viewport pixel: the overlay's
/// projection maps canonical coordinates to the viewport (OFX, Overlay
/// Interacts), so `2 / (m00 · width)` and `2 / (m11 · height)`.
fn measured_pixel(gl: &Gl) -> Option<(f64, f64)> {
    let mut m = [0.0f64; 16];
    let mut v = [0 as c_int; 4];
    // SAFETY: a context is current (the caller checked); GL writes 16
    // doubles and 4 ints into buffers of that size.
    unsafe {
        (gl.get_doublev)(GL_PROJECTION_MATRIX, m.as_mut_ptr());
        (gl.get_integerv)(GL_VIEWPORT, v.as_mut_ptr());
    }
    let px = 2.0 / (m[0] * v[2] as f64);
    let py = 2.0 / (m[5] * v[3] as f64);
    (px.is_finite() && py.is_finite() && px > 0.0 && py > 0.0).then_some((px, py))
}

impl Drop for GlPainter {
    fn drop(&mut self) {
        // SAFETY: pops the attributes `new` pushed, in the same context.
        unsafe { (self.gl.pop_attrib)() };
    }
}

impl Painter for GlPainter {
    fn colour(&mut self, [r, g, b, a]: [f32; 4]) {
        // SAFETY: a context is current for the painter's life.
        unsafe { (self.gl.color4f)(r, g, b, a) };
    }

    fn width(&mut self, px: f32) {
        // SAFETY: as above.
        unsafe { (self.gl.line_width)(px) };
    }

    fn stipple(&mut self, stipple: Stipple) {
        // SAFETY: as above.
        unsafe {
            match stipple {
                Stipple::Solid => (self.gl.disable)(GL_LINE_STIPPLE),
                Stipple::Dash => {
                    (self.gl.enable)(GL_LINE_STIPPLE);
                    (self.gl.line_stipple)(2, 0x0F0F);
                }
            }
        }
    }

    fn lines(&mut self, points: &[Vec2]) {
        self.primitive(GL_LINES, points);
    }

    fn strip(&mut self, points: &[Vec2]) {
        self.primitive(GL_LINE_STRIP, points);
    }

    fn text(&mut self, at: Vec2, text: &str) {
        // GL 1.1 has no text: the stroke font, a label's height in pixels.
        let (px, py) = self.pixel;
        for stroke in strokes::text(text, at, LABEL_PX * py, px / py) {
            self.primitive(GL_LINE_STRIP, &stroke);
        }
    }
}
