//! Defining params from [`ParamSpec`] tables and reading their values.

use std::collections::HashMap;
use std::ffi::{c_char, c_int, CStr, CString};

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::param::*;

use super::props::PropSet;
use super::spec::{Double, Id, IntValued, Kind, ParamSpec, Point, Text, TextMode};
use super::{check, host, Failure, Outcome};

fn cstr(s: &str) -> CString {
    CString::new(s).unwrap_or_default()
}

/// The range of line-point params (canonical px): twice the largest frame
/// the warps cover, either side of the origin.
pub const POINT_RANGE: (f64, f64) = (-131072.0, 131072.0);

/// An effect's param set: where params are defined (on a descriptor) and
/// their handles fetched (on an instance).
#[derive(Clone, Copy)]
pub struct ParamSet {
    set: OfxParamSetHandle,
    suite: &'static OfxParameterSuiteV1,
}

impl ParamSet {
    /// The param set behind a host's handle.
    ///
    /// # Safety
    /// `set` is null (refused) or the param set handle the host's
    /// getParamSet returned for an effect that is still alive while the
    /// value (and any [`Params`] bound from it) is used.
    pub unsafe fn from_raw(set: OfxParamSetHandle) -> Outcome<Self> {
        if set.is_null() {
            return Err(Failure::Status(
                kOfxStatErrBadHandle,
                "null param set".into(),
            ));
        }
        Ok(ParamSet {
            set,
            suite: host::suites()?.param,
        })
    }

    /// Defines every param of `specs` (describe-in-context).
    pub fn define_all(&self, specs: &[ParamSpec]) -> Outcome {
        for spec in specs {
            self.define(spec)?;
        }
        Ok(())
    }

    /// The params of `specs`, their handles and types fetched once (an
    /// instance keeps them for its life). A param the host cannot hand over
    /// is left out: reading it fails, and the reader falls back to its
    /// default. Each remembers the type the host made it with (the type it
    /// was defined with, where the host does not say), and every read and
    /// write checks it before handing the host a pointer.
    pub fn bind<'a>(&self, specs: impl IntoIterator<Item = &'a ParamSpec>) -> Params {
        let handles = specs
            .into_iter()
            .filter_map(|spec| {
                let handle = self.handle(spec.id()).ok()?;
                let kind = self
                    .host_type(handle)
                    .unwrap_or_else(|| ParamType::declared(spec.kind()));
                Some((spec.id().to_owned(), Param { handle, kind }))
            })
            .collect();
        Params {
            set: *self,
            handles,
            blocks_refused: Default::default(),
            blocks_open: Default::default(),
        }
    }

    /// The type the host says `handle`'s param has (`kOfxParamPropType`).
    fn host_type(&self, handle: OfxParamHandle) -> Option<ParamType> {
        let f = self.suite.paramGetPropertySet?;
        let mut props: OfxPropertySetHandle = std::ptr::null_mut();
        // SAFETY: a handle the host just gave for this set, and a live out-pointer.
        check(unsafe { f(handle, &mut props) }, "paramGetPropertySet").ok()?;
        // SAFETY: the host just returned the param's property set.
        let props = unsafe { PropSet::from_raw(props) }.ok()?;
        let name = props.get_string(kOfxParamPropType, 0).ok()?;
        Some(ParamType::named(&name))
    }

    fn handle(&self, id: &str) -> Outcome<OfxParamHandle> {
        let get = need(self.suite.paramGetHandle, "paramGetHandle")?;
        let name = cstr(id);
        let mut h: OfxParamHandle = std::ptr::null_mut();
        // SAFETY: set is the instance's param set; name NUL-terminated; out-pointer live.
        let status = unsafe { get(self.set, name.as_ptr(), &mut h, std::ptr::null_mut()) };
        check(status, &format!("param {id}"))?;
        if h.is_null() {
            return Err(Failure::Status(
                kOfxStatErrBadHandle,
                format!("param {id}: null handle"),
            ));
        }
        Ok(h)
    }

    fn define(&self, spec: &ParamSpec) -> Outcome {
        define(self.set, self.suite, spec)
    }
}

fn define(param_set: OfxParamSetHandle, suite: &OfxParameterSuiteV1, spec: &ParamSpec) -> Outcome {
    let define = need(suite.paramDefine, "paramDefine")?;
    let kind: &CStr = match spec.kind() {
        Kind::Double { .. } => kOfxParamTypeDouble,
        Kind::Int { .. } => kOfxParamTypeInteger,
        Kind::Bool { .. } => kOfxParamTypeBoolean,
        Kind::Choice { .. } => kOfxParamTypeChoice,
        Kind::Point { .. } => kOfxParamTypeDouble2D,
        Kind::Text { .. } => kOfxParamTypeString,
        Kind::Group { .. } => kOfxParamTypeGroup,
        Kind::Button => kOfxParamTypePushButton,
        Kind::HostDriven { .. } => kOfxParamTypeDouble,
    };
    let name = cstr(spec.id());
    let mut props: OfxPropertySetHandle = std::ptr::null_mut();
    // SAFETY: param_set came from the host's getParamSet for this descriptor;
    // type and name are NUL-terminated; `props` is a live out-pointer.
    let status = unsafe { define(param_set, kind.as_ptr(), name.as_ptr(), &mut props) };
    check(status, &format!("defining param {}", spec.id()))?;
    // SAFETY: the host just returned the new param's properties.
    let p = unsafe { PropSet::from_raw(props)? };
    if let &Kind::HostDriven { default } = spec.kind() {
        p.set_double(kOfxParamPropDefault, 0, default)?;
        let _ = p.set_double(kOfxParamPropMin, 0, 0.0);
        let _ = p.set_double(kOfxParamPropMax, 0, 1.0);
        let _ = p.set_double(kOfxParamPropDisplayMin, 0, 0.0);
        let _ = p.set_double(kOfxParamPropDisplayMax, 0, 1.0);
        return Ok(());
    }
    set_common(&p, spec)?;
    set_kind(&p, spec.kind())
}

/// Label, hint, script name, parent and animation: what every visible param has.
fn set_common(p: &PropSet, spec: &ParamSpec) -> Outcome {
    p.set_string(kOfxPropLabel, 0, spec.label())?;
    // Optional properties: a minimal host may not know them; defining still succeeds.
    let _ = p.set_string(kOfxParamPropHint, 0, spec.hint());
    let _ = p.set_string(kOfxParamPropScriptName, 0, spec.id());
    if let Some(g) = &spec.group() {
        let _ = p.set_string(kOfxParamPropParent, 0, g);
    }
    if !matches!(spec.kind(), Kind::Group { .. }) {
        let _ = p.set_int(kOfxParamPropAnimates, 0, spec.animates() as i32);
    }
    Ok(())
}

/// The properties of the param's type: default, range, options, mode.
fn set_kind(p: &PropSet, kind: &Kind) -> Outcome {
    match kind {
        Kind::Double {
            default,
            min,
            max,
            display,
        } => {
            p.set_double(kOfxParamPropDefault, 0, *default)?;
            let _ = p.set_double(kOfxParamPropMin, 0, *min);
            let _ = p.set_double(kOfxParamPropMax, 0, *max);
            // Both range and display range set: Resolve otherwise clamps to (-1, 1).
            let _ = p.set_double(kOfxParamPropDisplayMin, 0, display.0);
            let _ = p.set_double(kOfxParamPropDisplayMax, 0, display.1);
            let _ = p.set_string(
                kOfxParamPropDoubleType,
                0,
                &kOfxParamDoubleTypePlain.to_string_lossy(),
            );
        }
        Kind::Int { default, min, max } => {
            p.set_int(kOfxParamPropDefault, 0, *default)?;
            let _ = p.set_int(kOfxParamPropMin, 0, *min);
            let _ = p.set_int(kOfxParamPropMax, 0, *max);
            let _ = p.set_int(kOfxParamPropDisplayMin, 0, *min);
            let _ = p.set_int(kOfxParamPropDisplayMax, 0, *max);
        }
        Kind::Bool { default } => p.set_int(kOfxParamPropDefault, 0, *default as i32)?,
        Kind::Choice { options, default } => {
            p.set_strings(kOfxParamPropChoiceOption, options)?;
            p.set_int(kOfxParamPropDefault, 0, *default as i32)?;
        }
        Kind::Point { default } => {
            p.set_doubles(kOfxParamPropDefault, &[default.0, default.1])?;
            // No host handle (kOfxParamPropUseHostOverlayHandle left 0): the
            // nodes' own overlay draws and drags every position, and a host
            // that also drew its crosshair and the param's script name at
            // each of 64 x 4 ends (Natron does) would bury the lines and
            // catch the pen. Nuke draws host handles beside a plugin's
            // overlay only for params that set the property, so it agrees.
            // A real range and display range: hosts that find none clamp
            // (Resolve to -1..1). Positions may lie outside the frame
            // (overscan), so the range is wide; sliders show a 4K frame.
            let (lo, hi) = POINT_RANGE;
            let _ = p.set_doubles(kOfxParamPropMin, &[lo, lo]);
            let _ = p.set_doubles(kOfxParamPropMax, &[hi, hi]);
            let _ = p.set_doubles(kOfxParamPropDisplayMin, &[0.0, 0.0]);
            let _ = p.set_doubles(kOfxParamPropDisplayMax, &[4096.0, 4096.0]);
            let _ = p.set_string(
                kOfxParamPropDoubleType,
                0,
                &kOfxParamDoubleTypeXYAbsolute.to_string_lossy(),
            );
            // Defaults and values in canonical pixels, not normalised (OFX 1.2+).
            let _ = p.set_string(
                kOfxParamPropDefaultCoordinateSystem,
                0,
                &kOfxParamCoordinatesCanonical.to_string_lossy(),
            );
        }
        Kind::Text { default, mode } => {
            p.set_string(kOfxParamPropDefault, 0, default)?;
            let mode: &CStr = match mode {
                TextMode::SingleLine => kOfxParamStringIsSingleLine,
                TextMode::MultiLine => kOfxParamStringIsMultiLine,
                TextMode::FilePath => kOfxParamStringIsFilePath,
            };
            let _ = p.set_string(kOfxParamPropStringMode, 0, &mode.to_string_lossy());
            if mode == kOfxParamStringIsFilePath {
                let _ = p.set_int(kOfxParamPropStringFilePathExists, 0, 1);
            }
        }
        Kind::Group { open } => {
            let _ = p.set_int(kOfxParamPropGroupOpen, 0, *open as i32);
        }
        Kind::Button | Kind::HostDriven { .. } => {}
    }
    Ok(())
}

/// A suite function the host may leave out, or the error that says so.
fn need<F>(f: Option<F>, name: &str) -> Outcome<F> {
    f.ok_or_else(|| Failure::Failed(format!("host has no {name}")))
}

/// An OFX param type, as far as reading and writing values goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamType {
    Double,
    Double2D,
    Integer,
    Boolean,
    Choice,
    String,
    /// Any other type (groups, buttons, pages, 3D, colours, ...).
    Other,
}

impl ParamType {
    /// The type named by a `kOfxParamPropType` value.
    pub fn named(name: &str) -> ParamType {
        let is = |t: &CStr| t.to_bytes() == name.as_bytes();
        if is(kOfxParamTypeDouble) {
            ParamType::Double
        } else if is(kOfxParamTypeDouble2D) {
            ParamType::Double2D
        } else if is(kOfxParamTypeInteger) {
            ParamType::Integer
        } else if is(kOfxParamTypeBoolean) {
            ParamType::Boolean
        } else if is(kOfxParamTypeChoice) {
            ParamType::Choice
        } else if is(kOfxParamTypeString) {
            ParamType::String
        } else {
            ParamType::Other
        }
    }

    /// The type a param of `kind` is defined with.
    fn declared(kind: &Kind) -> ParamType {
        match kind {
            Kind::Double { .. } | Kind::HostDriven { .. } => ParamType::Double,
            Kind::Point { .. } => ParamType::Double2D,
            Kind::Int { .. } => ParamType::Integer,
            Kind::Bool { .. } => ParamType::Boolean,
            Kind::Choice { .. } => ParamType::Choice,
            Kind::Text { .. } => ParamType::String,
            Kind::Group { .. } | Kind::Button => ParamType::Other,
        }
    }
}

/// What the host's variadic value functions are handed for a param: the
/// pointers (or values) an accessor passes are right only for these types.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Values {
    /// One `double` (or `double*`): Double params.
    OneDouble,
    /// Two `double`s (or `double*`s): Double2D params.
    TwoDoubles,
    /// One `int` (or `int*`): Integer, Boolean and Choice params.
    OneInt,
    /// One `char*` (or `char**`): String params.
    OneString,
}

impl Values {
    /// Whether a param of type `t` takes these values.
    pub fn fit(self, t: ParamType) -> bool {
        matches!(
            (self, t),
            (Values::OneDouble, ParamType::Double)
                | (Values::TwoDoubles, ParamType::Double2D)
                | (
                    Values::OneInt,
                    ParamType::Integer | ParamType::Boolean | ParamType::Choice
                )
                | (Values::OneString, ParamType::String)
        )
    }
}

/// A param's handle and the type it was made with.
#[derive(Clone, Copy)]
struct Param {
    handle: OfxParamHandle,
    kind: ParamType,
}

/// One instance's params, their handles fetched once.
pub struct Params {
    set: ParamSet,
    handles: HashMap<String, Param>,
    /// The host answered `paramEditBegin` with an error (the OpenFX
    /// reference host's example does): edits go on without undo blocks.
    blocks_refused: std::sync::atomic::AtomicBool,
    /// Edit blocks opened and not yet closed.
    blocks_open: std::sync::atomic::AtomicUsize,
}

// SAFETY: param handles are the host's, valid for the instance's life
// (`ParamSet::from_raw`'s contract); OFX lets render threads read param
// values through them concurrently, and writes (instanceChanged only) are
// the host's to serialise. The map itself is never changed after `bind`.
unsafe impl Send for Params {}
// SAFETY: as above.
unsafe impl Sync for Params {}

impl Params {
    /// Params bound to no host (what a node computes without one, as its
    /// tests do): every read and write fails as for a param the host never
    /// made.
    pub fn unbound() -> Params {
        // SAFETY: every field of the suite is an `Option` of a function
        // pointer, for which all-zero bytes are `None`.
        static NO_SUITE: OfxParameterSuiteV1 = unsafe { std::mem::zeroed() };
        Params {
            set: ParamSet {
                set: std::ptr::null_mut(),
                suite: &NO_SUITE,
            },
            handles: HashMap::new(),
            blocks_refused: Default::default(),
            blocks_open: Default::default(),
        }
    }

    /// Whether the host made param `id` (a minimal host may not make every
    /// kind the plugin defines).
    pub fn has<K>(&self, id: &Id<K>) -> bool {
        let id = id.name();
        self.handles.contains_key(id)
    }

    fn param(&self, id: &str) -> Outcome<Param> {
        self.handles.get(id).copied().ok_or_else(|| {
            Failure::Status(
                kOfxStatErrUnknown,
                format!("param {id}: the host has no such param"),
            )
        })
    }

    /// The handle of any param (keys, properties: no values passed).
    fn handle(&self, id: &str) -> Outcome<OfxParamHandle> {
        self.param(id).map(|p| p.handle)
    }

    /// The handle of a param that takes `values`; a param of another type
    /// is an error naming it, and the host is never called with pointers
    /// its type does not take.
    fn typed(&self, id: &str, values: Values) -> Outcome<OfxParamHandle> {
        let p = self.param(id)?;
        if values.fit(p.kind) {
            Ok(p.handle)
        } else {
            Err(Failure::Failed(format!(
                "param {id} is a {:?} param in this host, which does not take {values:?}",
                p.kind
            )))
        }
    }

    fn get_at(
        &self,
        id: &str,
        values: Values,
    ) -> Outcome<(
        OfxParamHandle,
        unsafe extern "C" fn(OfxParamHandle, OfxTime, ...) -> OfxStatus,
    )> {
        let h = self.typed(id, values)?;
        let f = need(self.set.suite.paramGetValueAtTime, "paramGetValueAtTime")?;
        Ok((h, f))
    }

    pub fn double(&self, id: &Id<Double>, time: f64) -> Outcome<f64> {
        let id = id.name();
        let (h, f) = self.get_at(id, Values::OneDouble)?;
        let mut v = 0.0f64;
        // SAFETY: `h` is a Double param (checked by `typed`), which takes
        // one `double*` vararg (OFX param suite).
        let status = unsafe { f(h, time, &mut v as *mut f64) };
        check(status, &format!("reading {id}"))?;
        Ok(v)
    }

    /// Integer, boolean and choice params all take one `int*`.
    pub fn int<K: IntValued>(&self, id: &Id<K>, time: f64) -> Outcome<i32> {
        let id = id.name();
        let (h, f) = self.get_at(id, Values::OneInt)?;
        let mut v: c_int = 0;
        // SAFETY: `h` is an Integer, Boolean or Choice param (checked by
        // `typed`), which take one `int*` vararg.
        let status = unsafe { f(h, time, &mut v as *mut c_int) };
        check(status, &format!("reading {id}"))?;
        Ok(v)
    }

    pub fn point(&self, id: &Id<Point>, time: f64) -> Outcome<(f64, f64)> {
        let id = id.name();
        let (h, f) = self.get_at(id, Values::TwoDoubles)?;
        let (mut x, mut y) = (0.0f64, 0.0f64);
        // SAFETY: `h` is a Double2D param (checked by `typed`), which
        // takes two `double*` varargs.
        let status = unsafe { f(h, time, &mut x as *mut f64, &mut y as *mut f64) };
        check(status, &format!("reading {id}"))?;
        Ok((x, y))
    }

    /// Keys a Double2D param at `time` (the host adds or moves the key).
    pub fn set_point_at(&self, id: &Id<Point>, time: f64, (x, y): (f64, f64)) -> Outcome {
        let id = id.name();
        let h = self.typed(id, Values::TwoDoubles)?;
        let f = need(self.set.suite.paramSetValueAtTime, "paramSetValueAtTime")?;
        // SAFETY: `h` is a Double2D param (checked by `typed`), which
        // takes two `double` varargs after the time.
        check(unsafe { f(h, time, x, y) }, &format!("setting {id}"))
    }

    /// Sets a Double2D param's value (a param without keys).
    pub fn set_point(&self, id: &Id<Point>, (x, y): (f64, f64)) -> Outcome {
        let id = id.name();
        let h = self.typed(id, Values::TwoDoubles)?;
        let f = need(self.set.suite.paramSetValue, "paramSetValue")?;
        // SAFETY: `h` is a Double2D param (checked by `typed`), which
        // takes two `double` varargs.
        check(unsafe { f(h, x, y) }, &format!("setting {id}"))
    }

    /// Sets an Integer, Boolean or Choice param's value.
    pub fn set_int<K: IntValued>(&self, id: &Id<K>, v: i32) -> Outcome {
        let id = id.name();
        let h = self.typed(id, Values::OneInt)?;
        let f = need(self.set.suite.paramSetValue, "paramSetValue")?;
        // SAFETY: `h` is an Integer, Boolean or Choice param (checked by
        // `typed`), which take one `int` vararg.
        check(unsafe { f(h, v as c_int) }, &format!("setting {id}"))
    }

    /// Sets a String param's value. A string with a NUL in it cannot cross
    /// the C ABI and is refused.
    pub fn set_string(&self, id: &Id<Text>, v: &str) -> Outcome {
        let id = id.name();
        let h = self.typed(id, Values::OneString)?;
        let f = need(self.set.suite.paramSetValue, "paramSetValue")?;
        let v = CString::new(v)
            .map_err(|_| Failure::BadInput(format!("setting {id}: the text holds a NUL")))?;
        // SAFETY: `h` is a String param (checked by `typed`), which takes
        // one `char*` vararg; the host copies the NUL-terminated string,
        // which lives until the call returns.
        check(unsafe { f(h, v.as_ptr()) }, &format!("setting {id}"))
    }

    /// Moves a point the user is editing: keyed at `time` when the param
    /// already animates (other keys stay), set outright when it has none,
    /// or when the host cannot count keys (the OpenFX reference host
    /// library answers `kOfxStatErrMissingHostFeature`).
    pub fn move_point(&self, id: &Id<Point>, time: f64, p: (f64, f64)) -> Outcome {
        if self.num_keys(id).is_ok_and(|n| n > 0) {
            self.set_point_at(id, time, p)
        } else {
            self.set_point(id, p)
        }
    }

    /// How many keys the param has.
    pub fn num_keys<K>(&self, id: &Id<K>) -> Outcome<u32> {
        let id = id.name();
        let f = need(self.set.suite.paramGetNumKeys, "paramGetNumKeys")?;
        let h = self.handle(id)?;
        let mut n: std::ffi::c_uint = 0;
        // SAFETY: the param's handle and a live out-pointer.
        check(unsafe { f(h, &mut n) }, &format!("counting keys of {id}"))?;
        Ok(n)
    }

    /// The times of the param's keys, in order.
    pub fn key_times<K>(&self, id: &Id<K>) -> Outcome<Vec<f64>> {
        let n = self.num_keys(id)?;
        let id = id.name();
        let f = need(self.set.suite.paramGetKeyTime, "paramGetKeyTime")?;
        let h = self.handle(id)?;
        (0..n)
            .map(|k| {
                let mut t = 0.0;
                // SAFETY: the param's handle, a key index below its count
                // and a live out-pointer.
                check(unsafe { f(h, k, &mut t) }, &format!("key {k} of {id}"))?;
                Ok(t)
            })
            .collect()
    }

    /// Removes every key of the param (its value stays what it was).
    pub fn delete_all_keys<K>(&self, id: &Id<K>) -> Outcome {
        let id = id.name();
        let f = need(self.set.suite.paramDeleteAllKeys, "paramDeleteAllKeys")?;
        let h = self.handle(id)?;
        // SAFETY: the param's handle.
        check(unsafe { f(h) }, &format!("deleting keys of {id}"))
    }

    /// Hides or shows the param in the host's UI (`kOfxParamPropSecret`).
    pub fn set_secret<K>(&self, id: &Id<K>, secret: bool) -> Outcome {
        let id = id.name();
        let f = need(self.set.suite.paramGetPropertySet, "paramGetPropertySet")?;
        let h = self.handle(id)?;
        let mut props: OfxPropertySetHandle = std::ptr::null_mut();
        // SAFETY: the param's handle and a live out-pointer.
        check(unsafe { f(h, &mut props) }, &format!("properties of {id}"))?;
        // SAFETY: the host just returned the param's property set, which
        // lives as long as the param.
        let p = unsafe { PropSet::from_raw(props)? };
        p.set_int(kOfxParamPropSecret, 0, secret as i32)
    }

    /// Opens an edit block that a later [`Params::end_edit`] closes: an
    /// overlay drag spans several actions and is still one undo step.
    /// Opens an edit block, the host's one undo step, where it has them.
    /// Undo blocks are a convenience: where the host has none, or refuses
    /// to open one (the OpenFX reference host's example answers
    /// `paramEditBegin` with an error), the edit goes on without, and the
    /// refusal is said once.
    pub fn begin_edit(&self, name: &str) -> Outcome {
        self.open_block(name);
        Ok(())
    }

    /// Opens a block if the host has them and has not refused one; true
    /// when a block is open.
    fn open_block(&self, name: &str) -> bool {
        use std::sync::atomic::Ordering;
        let (Some(begin), Some(_)) = (self.set.suite.paramEditBegin, self.set.suite.paramEditEnd)
        else {
            return false;
        };
        if self.blocks_refused.load(Ordering::Acquire) {
            return false;
        }
        let label = cstr(name);
        // SAFETY: the instance's param set and a NUL-terminated label.
        let status = unsafe { begin(self.set.set, label.as_ptr()) };
        if status == kOfxStatOK {
            self.blocks_open.fetch_add(1, Ordering::AcqRel);
            return true;
        }
        if !self.blocks_refused.swap(true, Ordering::AcqRel) {
            eprintln!(
                "MorphFX: the host answered paramEditBegin with {}; edits are \
                    made without undo blocks",
                super::status_name(status)
            );
        }
        false
    }

    /// Closes the block [`Params::begin_edit`] opened (nothing where none
    /// opened).
    pub fn end_edit(&self) -> Outcome {
        use std::sync::atomic::Ordering;
        let Some(end) = self.set.suite.paramEditEnd else {
            return Ok(());
        };
        let open = self
            .blocks_open
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |n| n.checked_sub(1));
        if open.is_err() {
            return Ok(()); // none opened: the host refused it, or has none
        }
        // SAFETY: the instance's param set.
        check(unsafe { end(self.set.set) }, "paramEditEnd")
    }

    /// Runs `writes` inside one edit block (`paramEditBegin`/`paramEditEnd`):
    /// the host makes it one undo step. The block is closed whatever
    /// `writes` returns. Without a block (see [`Params::begin_edit`]) the
    /// writes are made all the same.
    pub fn edit_block<R>(&self, name: &str, writes: impl FnOnce() -> Outcome<R>) -> Outcome<R> {
        if !self.open_block(name) {
            return writes();
        }
        let result = writes();
        let closed = self.end_edit();
        let value = result?;
        closed.map(|()| value)
    }

    pub fn string(&self, id: &Id<Text>, time: f64) -> Outcome<String> {
        let id = id.name();
        let (h, f) = self.get_at(id, Values::OneString)?;
        let mut v: *const c_char = std::ptr::null();
        // SAFETY: `h` is a String param (checked by `typed`), which takes
        // one `char**` vararg; the host owns the result.
        let status = unsafe { f(h, time, &mut v as *mut *const c_char) };
        check(status, &format!("reading {id}"))?;
        if v.is_null() {
            return Ok(String::new());
        }
        // SAFETY: NUL-terminated host string, valid until the next param call; copied now.
        Ok(unsafe { CStr::from_ptr(v) }.to_string_lossy().into_owned())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TYPES: [ParamType; 7] = [
        ParamType::Double,
        ParamType::Double2D,
        ParamType::Integer,
        ParamType::Boolean,
        ParamType::Choice,
        ParamType::String,
        ParamType::Other,
    ];

    #[test]
    fn each_accessor_takes_exactly_the_types_the_param_suite_gives_its_values() {
        use ParamType::*;
        let takes =
            |v: Values| -> Vec<ParamType> { TYPES.into_iter().filter(|t| v.fit(*t)).collect() };
        // The OFX param suite: "double" for Double, two for Double2D, "int"
        // for Integer, Boolean and Choice, "char*" for String.
        assert_eq!(takes(Values::OneDouble), [Double]);
        assert_eq!(takes(Values::TwoDoubles), [Double2D]);
        assert_eq!(takes(Values::OneInt), [Integer, Boolean, Choice]);
        assert_eq!(takes(Values::OneString), [String]);
    }

    #[test]
    fn host_type_names_are_read_as_the_spec_spells_them() {
        for (name, t) in [
            (kOfxParamTypeDouble, ParamType::Double),
            (kOfxParamTypeDouble2D, ParamType::Double2D),
            (kOfxParamTypeInteger, ParamType::Integer),
            (kOfxParamTypeBoolean, ParamType::Boolean),
            (kOfxParamTypeChoice, ParamType::Choice),
            (kOfxParamTypeString, ParamType::String),
            (kOfxParamTypeDouble3D, ParamType::Other),
            (kOfxParamTypeInteger2D, ParamType::Other),
            (kOfxParamTypePushButton, ParamType::Other),
        ] {
            assert_eq!(ParamType::named(&name.to_string_lossy()), t, "{name:?}");
        }
        assert_eq!(ParamType::named(""), ParamType::Other);
    }
}
