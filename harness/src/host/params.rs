//! Params with real per-param storage and keyframes (linear for doubles,
//! stepped for the rest), and the parameter suite.

use std::ffi::{c_char, c_int, c_uint, CStr, CString};
use std::sync::Mutex;

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::param::*;

use super::props::PropertySet;
use crate::sync::Locked;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    Double(usize),
    Int(usize),
    Str,
    /// Groups, pages, buttons: no value.
    None,
}

#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParamValue {
    pub d: [f64; 4],
    pub i: [i32; 4],
    pub s: CString,
}

pub struct Param {
    pub name: String,
    pub kind: String,
    pub props: PropertySet,
    state: Mutex<(ParamValue, Vec<(f64, ParamValue)>)>,
    /// Calls of the variadic value functions (get and set, at a time or
    /// not) the plugin made on this param.
    pub value_calls: std::sync::atomic::AtomicUsize,
}

impl Param {
    pub fn shape(&self) -> Shape {
        match self.kind.as_str() {
            "OfxParamTypeDouble" => Shape::Double(1),
            "OfxParamTypeDouble2D" => Shape::Double(2),
            "OfxParamTypeDouble3D" => Shape::Double(3),
            "OfxParamTypeRGB" => Shape::Double(3),
            "OfxParamTypeRGBA" => Shape::Double(4),
            "OfxParamTypeInteger" | "OfxParamTypeBoolean" | "OfxParamTypeChoice" => Shape::Int(1),
            "OfxParamTypeInteger2D" => Shape::Int(2),
            "OfxParamTypeInteger3D" => Shape::Int(3),
            "OfxParamTypeString" | "OfxParamTypeStrChoice" => Shape::Str,
            _ => Shape::None,
        }
    }

    /// A param of an instance, valued at its descriptor's default (of the
    /// type a test armed this host to make it with instead, if any).
    pub fn instance_of(desc: &Param) -> Param {
        let props = desc.props.clone_values();
        let mut p = Param {
            name: desc.name.clone(),
            kind: desc.kind.clone(),
            props,
            state: Mutex::new(Default::default()),
            value_calls: Default::default(),
        };
        if let Some(kind) = super::misuse::param_type(&desc.name) {
            p.kind = kind.to_owned();
            p.props.set_str(kOfxParamPropType, kind);
        }
        p.set(p.default_value());
        p
    }

    /// The value its descriptor declares as default.
    fn default_value(&self) -> ParamValue {
        let props = &self.props;
        let mut v = ParamValue::default();
        match self.shape() {
            Shape::Double(n) => {
                for (k, d) in props
                    .doubles(kOfxParamPropDefault)
                    .into_iter()
                    .take(n)
                    .enumerate()
                {
                    v.d[k] = d;
                }
            }
            Shape::Int(n) => {
                for (k, i) in props
                    .ints(kOfxParamPropDefault)
                    .into_iter()
                    .take(n)
                    .enumerate()
                {
                    v.i[k] = i;
                }
            }
            Shape::Str => {
                v.s = CString::new(props.str(kOfxParamPropDefault).unwrap_or_default())
                    .unwrap_or_default()
            }
            Shape::None => {}
        }
        v
    }

    /// Back to its default, unkeyed: as a fresh instance has it.
    pub fn reset(&self) {
        self.set(self.default_value());
    }

    fn state(&self) -> std::sync::MutexGuard<'_, (ParamValue, Vec<(f64, ParamValue)>)> {
        self.state.locked()
    }

    pub fn value_at(&self, time: f64) -> ParamValue {
        let st = self.state();
        let (value, keys) = &*st;
        if keys.is_empty() {
            return value.clone();
        }
        if time <= keys[0].0 {
            return keys[0].1.clone();
        }
        let last = keys.len() - 1;
        if time >= keys[last].0 {
            return keys[last].1.clone();
        }
        let hi = keys.iter().position(|k| k.0 > time).unwrap_or(last);
        let (t0, v0) = &keys[hi - 1];
        let (t1, v1) = &keys[hi];
        let w = (time - t0) / (t1 - t0);
        let mut out = v0.clone();
        if let Shape::Double(n) = self.shape() {
            for k in 0..n {
                out.d[k] = v0.d[k] + (v1.d[k] - v0.d[k]) * w;
            }
        }
        out
    }

    pub fn set(&self, v: ParamValue) {
        let mut st = self.state();
        st.0 = v;
        st.1.clear();
    }

    /// Keys `v` at `time` (replacing a key already there).
    pub fn set_key(&self, time: f64, v: ParamValue) {
        let mut st = self.state();
        let keys = &mut st.1;
        keys.retain(|k| k.0 != time);
        keys.push((time, v));
        keys.sort_by(|a, b| a.0.total_cmp(&b.0));
    }

    pub fn num_keys(&self) -> usize {
        self.state().1.len()
    }

    /// The times of its keys, in order.
    pub fn key_times(&self) -> Vec<f64> {
        self.state().1.iter().map(|k| k.0).collect()
    }
}

#[derive(Default)]
pub struct ParamSet {
    pub props: PropertySet,
    pub params: Mutex<Vec<Box<Param>>>,
}

impl ParamSet {
    pub fn find(&self, name: &str) -> Option<*const Param> {
        let params = self.params.locked();
        params
            .iter()
            .find(|p| p.name == name)
            .map(|p| &**p as *const Param)
    }
    /// The instance's copy of a descriptor's params.
    pub fn instance_of(desc: &ParamSet) -> ParamSet {
        let params = desc.params.locked();
        ParamSet {
            props: desc.props.clone_values(),
            params: Mutex::new(
                params
                    .iter()
                    .map(|p| Box::new(Param::instance_of(p)))
                    .collect(),
            ),
        }
    }
    pub fn names(&self) -> Vec<(String, String)> {
        let params = self.params.locked();
        params
            .iter()
            .map(|p| (p.name.clone(), p.kind.clone()))
            .collect()
    }
    /// The param called `name`; lives as long as this set.
    pub fn get(&self, name: &str) -> Option<&Param> {
        // SAFETY: params are boxed and never removed, so the pointer lives as long as `self`.
        self.find(name).map(|p| unsafe { &*p })
    }
}

/// # Safety
/// `h` must be null or a param handle this host made.
unsafe fn param_of<'a>(h: OfxParamHandle) -> Option<&'a Param> {
    // SAFETY: param handles point at boxed Params owned by a live ParamSet.
    unsafe { (h as *const Param).as_ref() }
}

unsafe extern "C" fn param_define(
    set: OfxParamSetHandle,
    kind: *const c_char,
    name: *const c_char,
    props: *mut OfxPropertySetHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "param_define", || {
        // SAFETY: set handles point at live ParamSets; strings are NUL-terminated.
        let Some(set) = (unsafe { (set as *const ParamSet).as_ref() }) else {
            return kOfxStatErrBadHandle;
        };
        if kind.is_null() || name.is_null() {
            return kOfxStatErrBadHandle;
        }
        // SAFETY: both checked non-null just above; OFX strings are NUL-terminated.
        let (kind, name) = unsafe { (CStr::from_ptr(kind), CStr::from_ptr(name)) };
        let name = name.to_string_lossy().into_owned();
        let mut params = set.params.locked();
        if params.iter().any(|p| p.name == name) {
            return kOfxStatErrExists;
        }
        let p = Box::new(Param {
            name: name.clone(),
            kind: kind.to_string_lossy().into_owned(),
            props: PropertySet::new(),
            state: Mutex::new(Default::default()),
            value_calls: Default::default(),
        });
        p.props.set_str(kOfxParamPropType, &p.kind);
        p.props.set_str(kOfxPropName, &name);
        if !props.is_null() {
            // SAFETY: non-null out-pointer from the plugin.
            unsafe { *props = p.props.handle() };
        }
        params.push(p);
        kOfxStatOK
    })
}

unsafe extern "C" fn param_get_handle(
    set: OfxParamSetHandle,
    name: *const c_char,
    param: *mut OfxParamHandle,
    props: *mut OfxPropertySetHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "param_get_handle", || {
        // SAFETY: set handles point at live ParamSets; name NUL-terminated.
        let Some(set) = (unsafe { (set as *const ParamSet).as_ref() }) else {
            return kOfxStatErrBadHandle;
        };
        if name.is_null() {
            return kOfxStatErrBadHandle;
        }
        // SAFETY: checked non-null just above; OFX strings are NUL-terminated.
        let name = unsafe { CStr::from_ptr(name) }.to_string_lossy();
        let Some(p) = set.find(&name) else {
            return kOfxStatErrUnknown;
        };
        // SAFETY: out-pointers are the plugin's; `p` is a live boxed Param.
        unsafe {
            if !param.is_null() {
                *param = p as OfxParamHandle;
            }
            if !props.is_null() {
                *props = (*p).props.handle();
            }
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn param_set_props(
    set: OfxParamSetHandle,
    props: *mut OfxPropertySetHandle,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "param_set_props", || {
        // SAFETY: set handles point at live ParamSets.
        let Some(set) = (unsafe { (set as *const ParamSet).as_ref() }) else {
            return kOfxStatErrBadHandle;
        };
        if !props.is_null() {
            // SAFETY: checked non-null just above; the plugin passes a pointer to its own variable.
            unsafe { *props = set.props.handle() };
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn param_props(h: OfxParamHandle, props: *mut OfxPropertySetHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "param_props", || {
        // SAFETY: see `param_of`.
        let Some(p) = (unsafe { param_of(h) }) else {
            return kOfxStatErrBadHandle;
        };
        if !props.is_null() {
            // SAFETY: checked non-null just above; the plugin passes a pointer to its own variable.
            unsafe { *props = p.props.handle() };
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn num_keys(h: OfxParamHandle, n: *mut c_uint) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "num_keys", || {
        // SAFETY: see `param_of`.
        let Some(p) = (unsafe { param_of(h) }) else {
            return kOfxStatErrBadHandle;
        };
        if !n.is_null() {
            // SAFETY: checked non-null just above; the plugin passes a pointer to its own variable.
            unsafe { *n = p.num_keys() as c_uint };
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn key_time(h: OfxParamHandle, nth: c_uint, time: *mut OfxTime) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "key_time", || {
        // SAFETY: see `param_of`.
        let Some(p) = (unsafe { param_of(h) }) else {
            return kOfxStatErrBadHandle;
        };
        match p.key_times().get(nth as usize) {
            None => kOfxStatErrBadIndex,
            Some(_) if time.is_null() => kOfxStatErrBadIndex,
            Some(t) => {
                // SAFETY: checked non-null; the plugin's own variable.
                unsafe { *time = *t };
                kOfxStatOK
            }
        }
    })
}
unsafe extern "C" fn unsupported_key_index(
    _: OfxParamHandle,
    _: OfxTime,
    _: c_int,
    _: *mut c_int,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "unsupported_key_index", || {
        kOfxStatErrUnsupported
    })
}
unsafe extern "C" fn unsupported_delete_key(_: OfxParamHandle, _: OfxTime) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "unsupported_delete_key", || {
        kOfxStatErrUnsupported
    })
}
unsafe extern "C" fn delete_all_keys(h: OfxParamHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "delete_all_keys", || {
        // SAFETY: see `param_of`.
        let Some(p) = (unsafe { param_of(h) }) else {
            return kOfxStatErrBadHandle;
        };
        let v = p.value_at(0.0);
        p.set(v);
        kOfxStatOK
    })
}
unsafe extern "C" fn unsupported_copy(
    _: OfxParamHandle,
    _: OfxParamHandle,
    _: OfxTime,
    _: *const OfxRangeD,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "unsupported_copy", || {
        kOfxStatErrUnsupported
    })
}
thread_local! {
    /// The plugin's param writes and edit blocks on this thread, in order
    /// (instanceChanged and interacts run on the thread that calls them):
    /// open blocks, and the log a test reads back.
    static EDITS: std::cell::RefCell<(u32, Vec<String>)> =
        const { std::cell::RefCell::new((0, Vec::new())) };
}

thread_local! {
    /// The action the host is calling on this thread, innermost last.
    static ACTIONS: std::cell::RefCell<Vec<String>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Marks this thread as inside `action` until dropped: the spec lets a
/// plugin set param values only from the instance-changed action and
/// interacts' events, so a write anywhere else is a violation.
pub struct Inside;

impl Inside {
    pub fn action(action: &CStr) -> Inside {
        ACTIONS.with(|a| a.borrow_mut().push(action.to_string_lossy().into_owned()));
        Inside
    }
}

impl Drop for Inside {
    fn drop(&mut self) {
        ACTIONS.with(|a| a.borrow_mut().pop());
    }
}

/// Reports a param write made outside the instance-changed action (a
/// render, a thread of the plugin's own, another action).
fn check_write_allowed(param: &str) {
    let action = ACTIONS.with(|a| a.borrow().last().cloned());
    // Interacts edit params too (a drag in the viewer), from their pen and
    // key actions.
    let allowed = matches!(
        action.as_deref(),
        Some(
            "OfxActionInstanceChanged"
                | "OfxInteractActionPenDown"
                | "OfxInteractActionPenMotion"
                | "OfxInteractActionPenUp"
                | "OfxInteractActionKeyDown"
                | "OfxInteractActionKeyRepeat"
        )
    );
    if !allowed {
        super::checks::violation(format!(
            "param {param} written in {} (only the instance-changed action may set values)",
            action.as_deref().unwrap_or("a thread outside any action")
        ));
    }
}

/// What the plugin wrote on this thread since the last call: `begin NAME`,
/// `set PARAM` or `set PARAM@TIME`, `end`.
pub fn take_edit_log() -> Vec<String> {
    EDITS.with(|e| std::mem::take(&mut e.borrow_mut().1))
}

fn log_edit(entry: String) {
    EDITS.with(|e| e.borrow_mut().1.push(entry));
}

unsafe extern "C" fn edit(_: OfxParamSetHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "edit", || {
        let open = EDITS.with(|e| {
            let mut e = e.borrow_mut();
            let open = e.0 > 0;
            e.0 = e.0.saturating_sub(1);
            open
        });
        if !open {
            super::checks::violation("paramEditEnd without a paramEditBegin".into());
            return kOfxStatFailed;
        }
        log_edit("end".into());
        kOfxStatOK
    })
}
unsafe extern "C" fn edit_begin(_: OfxParamSetHandle, name: *const c_char) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "edit_begin", || {
        let name = if name.is_null() {
            String::new()
        } else {
            // SAFETY: a NUL-terminated name from the plugin.
            unsafe { CStr::from_ptr(name) }
                .to_string_lossy()
                .into_owned()
        };
        EDITS.with(|e| e.borrow_mut().0 += 1);
        log_edit(format!("begin {name}"));
        kOfxStatOK
    })
}

// The C shim (varargs.c) unpacks variadic arguments through these.

/// # Safety
/// Called by the C shim with a param handle from the plugin and live out-pointers.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mfx_param_shape(
    h: OfxParamHandle,
    kind: *mut c_int,
    dim: *mut c_int,
) -> c_int {
    super::guard::guard(0, "mfx_param_shape", || {
        // SAFETY: see `param_of`; out-pointers are the shim's locals.
        let Some(p) = (unsafe { param_of(h) }) else {
            return kOfxStatErrBadHandle;
        };
        // Every variadic value call asks the shape first.
        p.value_calls
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let (k, d) = match p.shape() {
            Shape::Double(n) => (0, n),
            Shape::Int(n) => (1, n),
            Shape::Str => (2, 1),
            Shape::None => return kOfxStatErrValue,
        };
        // SAFETY: the C shim passes pointers to its own locals (see varargs.c).
        unsafe {
            *kind = k;
            *dim = d as c_int;
        }
        kOfxStatOK
    })
}

/// # Safety
/// As `mfx_param_shape`; `d` and `iv` have room for 4 values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mfx_param_get(
    h: OfxParamHandle,
    time: f64,
    at_time: c_int,
    d: *mut f64,
    iv: *mut c_int,
    s: *mut *const c_char,
) -> c_int {
    super::guard::guard(0, "mfx_param_get", || {
        // SAFETY: see `param_of`.
        let Some(p) = (unsafe { param_of(h) }) else {
            return kOfxStatErrBadHandle;
        };
        if super::misuse::params_unreadable() {
            return kOfxStatErrUnknown;
        }
        let v = p.value_at(if at_time != 0 { time } else { 0.0 });
        // SAFETY: the shim's arrays hold 4 values; the string pointer stays valid
        // because the param keeps an equal CString until it is set again — we
        // return the stored one, not the copy.
        unsafe {
            for k in 0..4 {
                *d.add(k) = v.d[k];
                *iv.add(k) = v.i[k];
            }
            let st = p.state();
            let stored =
                st.1.iter()
                    .find(|(_, kv)| kv.s == v.s)
                    .map(|(_, kv)| &kv.s)
                    .unwrap_or(&st.0.s);
            *s = stored.as_ptr();
        }
        kOfxStatOK
    })
}

/// # Safety
/// As `mfx_param_get`; `s` is null or NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn mfx_param_set(
    h: OfxParamHandle,
    time: f64,
    at_time: c_int,
    d: *const f64,
    iv: *const c_int,
    s: *const c_char,
) -> c_int {
    super::guard::guard(0, "mfx_param_set", || {
        // SAFETY: see `param_of`; arrays hold 4 values.
        let Some(p) = (unsafe { param_of(h) }) else {
            return kOfxStatErrBadHandle;
        };
        let mut v = ParamValue::default();
        // SAFETY: the caller's `d` and `iv` point at four values each.
        unsafe {
            for k in 0..4 {
                v.d[k] = *d.add(k);
                v.i[k] = *iv.add(k);
            }
            if !s.is_null() {
                v.s = CStr::from_ptr(s).to_owned();
            }
        }
        check_write_allowed(&p.name);
        if at_time != 0 {
            log_edit(format!("set {}@{time}", p.name));
            p.set_key(time, v);
        } else {
            log_edit(format!("set {}", p.name));
            p.set(v);
        }
        kOfxStatOK
    })
}

unsafe extern "C" {
    fn mfx_paramGetValue(h: OfxParamHandle, ...) -> OfxStatus;
    fn mfx_paramGetValueAtTime(h: OfxParamHandle, time: OfxTime, ...) -> OfxStatus;
    fn mfx_paramSetValue(h: OfxParamHandle, ...) -> OfxStatus;
    fn mfx_paramSetValueAtTime(h: OfxParamHandle, time: OfxTime, ...) -> OfxStatus;
    fn mfx_paramGetDerivative(h: OfxParamHandle, time: OfxTime, ...) -> OfxStatus;
    fn mfx_paramGetIntegral(h: OfxParamHandle, t1: OfxTime, t2: OfxTime, ...) -> OfxStatus;
}

pub static SUITE: OfxParameterSuiteV1 = OfxParameterSuiteV1 {
    paramDefine: Some(param_define),
    paramGetHandle: Some(param_get_handle),
    paramSetGetPropertySet: Some(param_set_props),
    paramGetPropertySet: Some(param_props),
    paramGetValue: Some(mfx_paramGetValue),
    paramGetValueAtTime: Some(mfx_paramGetValueAtTime),
    paramGetDerivative: Some(mfx_paramGetDerivative),
    paramGetIntegral: Some(mfx_paramGetIntegral),
    paramSetValue: Some(mfx_paramSetValue),
    paramSetValueAtTime: Some(mfx_paramSetValueAtTime),
    paramGetNumKeys: Some(num_keys),
    paramGetKeyTime: Some(key_time),
    paramGetKeyIndex: Some(unsupported_key_index),
    paramDeleteKey: Some(unsupported_delete_key),
    paramDeleteAllKeys: Some(delete_all_keys),
    paramCopy: Some(unsupported_copy),
    paramEditBegin: Some(edit_begin),
    paramEditEnd: Some(edit),
};

#[cfg(test)]
mod tests {
    use super::*;

    fn write(param: &Param) {
        let (d, i) = ([0.5f64; 4], [0 as c_int; 4]);
        // SAFETY: the handle is a live Param; the arrays hold 4 values.
        let st = unsafe {
            mfx_param_set(
                param as *const Param as OfxParamHandle,
                0.0,
                0,
                d.as_ptr(),
                i.as_ptr(),
                std::ptr::null(),
            )
        };
        assert_eq!(st, kOfxStatOK);
    }

    fn reported(name: &str) -> bool {
        super::super::take_violations()
            .iter()
            .any(|v| v.contains(&format!("param {name} ")))
    }

    #[test]
    fn param_writes_outside_instance_changed_are_violations() {
        let _one_at_a_time = super::super::VIOLATION_TESTS.locked();
        let param = Param {
            name: "written_param".into(),
            kind: "OfxParamTypeDouble".into(),
            props: PropertySet::new(),
            state: Mutex::new(Default::default()),
            value_calls: Default::default(),
        };
        {
            let _in = Inside::action(c"OfxActionInstanceChanged");
            write(&param);
        }
        assert!(!reported("written_param"), "allowed in instance changed");
        {
            let _in = Inside::action(c"OfxImageEffectActionRender");
            write(&param);
        }
        assert!(reported("written_param"), "a write during a render");
        write(&param);
        assert!(reported("written_param"), "a write outside any action");
    }
}
