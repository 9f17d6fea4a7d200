//! Property sets and the property suite: open sets (the plugin may set any
//! property on a descriptor), strings kept alive until overwritten.

use std::any::Any;
use std::collections::HashMap;
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::sync::Mutex;

use openfx::sys::generic::core::*;
use openfx::sys::generic::property::*;

use crate::sync::Locked;

#[derive(Debug, Clone)]
pub enum Value {
    S(Vec<CString>),
    I(Vec<i32>),
    D(Vec<f64>),
    P(Vec<usize>),
}

#[derive(Default)]
pub struct PropertySet {
    values: Mutex<HashMap<String, Value>>,
    /// Keeps whatever the set describes alive (an image's pixels).
    pub owner: Option<Box<dyn Any + Send + Sync>>,
    /// An image's set after `clipReleaseImage`: kept (emptied) so that a
    /// plugin still using it is reported, not undefined behaviour.
    pub released: std::sync::atomic::AtomicBool,
}

impl PropertySet {
    pub fn new() -> Self {
        Self::default()
    }
    fn map(&self) -> std::sync::MutexGuard<'_, HashMap<String, Value>> {
        self.values.locked()
    }
    pub fn set(&self, name: &CStr, v: Value) {
        self.map().insert(name.to_string_lossy().into_owned(), v);
    }
    pub fn set_str(&self, name: &CStr, v: &str) {
        self.set(name, Value::S(vec![CString::new(v).unwrap_or_default()]));
    }
    pub fn set_strs(&self, name: &CStr, v: &[&str]) {
        self.set(
            name,
            Value::S(
                v.iter()
                    .map(|s| CString::new(*s).unwrap_or_default())
                    .collect(),
            ),
        );
    }
    pub fn set_int(&self, name: &CStr, v: &[i32]) {
        self.set(name, Value::I(v.to_vec()));
    }
    pub fn set_double(&self, name: &CStr, v: &[f64]) {
        self.set(name, Value::D(v.to_vec()));
    }
    pub fn set_ptr(&self, name: &CStr, v: *mut c_void) {
        self.set(name, Value::P(vec![v as usize]));
    }
    pub fn get(&self, name: &str) -> Option<Value> {
        self.map().get(name).cloned()
    }
    pub fn str(&self, name: &CStr) -> Option<String> {
        match self.get(&name.to_string_lossy())? {
            Value::S(v) => v.first().map(|s| s.to_string_lossy().into_owned()),
            _ => None,
        }
    }
    pub fn strs(&self, name: &CStr) -> Vec<String> {
        match self.get(&name.to_string_lossy()) {
            Some(Value::S(v)) => v.iter().map(|s| s.to_string_lossy().into_owned()).collect(),
            _ => Vec::new(),
        }
    }
    pub fn ints(&self, name: &CStr) -> Vec<i32> {
        match self.get(&name.to_string_lossy()) {
            Some(Value::I(v)) => v,
            _ => Vec::new(),
        }
    }
    pub fn doubles(&self, name: &CStr) -> Vec<f64> {
        match self.get(&name.to_string_lossy()) {
            Some(Value::D(v)) => v,
            Some(Value::I(v)) => v.into_iter().map(f64::from).collect(),
            _ => Vec::new(),
        }
    }
    /// Copies every value (not the owner).
    pub fn clone_values(&self) -> PropertySet {
        PropertySet {
            values: Mutex::new(self.map().clone()),
            ..PropertySet::default()
        }
    }
    /// Forgets every value, and the memory that held them.
    pub fn clear(&self) {
        *self.map() = HashMap::new();
    }
    pub fn handle(&self) -> OfxPropertySetHandle {
        self as *const PropertySet as OfxPropertySetHandle
    }
}

/// # Safety
/// `h` must be null or a handle this host made from a live `PropertySet`.
unsafe fn set_of<'a>(h: OfxPropertySetHandle) -> Option<&'a PropertySet> {
    // SAFETY: per the contract above; every property set handle we hand out
    // points at a PropertySet that outlives the plugin's use of it (released
    // images' sets are kept).
    let set = unsafe { (h as *const PropertySet).as_ref() }?;
    if set.released.load(std::sync::atomic::Ordering::Relaxed) {
        super::checks::violation(
            "an image's properties read or written after clipReleaseImage".into(),
        );
        return None;
    }
    Some(set)
}

fn name_of(p: *const c_char) -> Option<String> {
    if p.is_null() {
        return None;
    }
    // SAFETY: OFX property names are NUL-terminated C strings.
    Some(unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

macro_rules! setter {
    ($fn:ident, $t:ty, $variant:ident, $conv:expr) => {
        unsafe extern "C" fn $fn(
            h: OfxPropertySetHandle,
            name: *const c_char,
            index: c_int,
            value: $t,
        ) -> OfxStatus {
            super::guard::guard(kOfxStatErrUnknown, stringify!($fn), || {
                // SAFETY: handles we hand out are live PropertySets.
                let (Some(set), Some(name)) = (unsafe { set_of(h) }, name_of(name)) else {
                    return kOfxStatErrBadHandle;
                };
                if index < 0 {
                    return kOfxStatErrBadIndex;
                }
                let conv: fn($t) -> _ = $conv;
                let v = conv(value);
                let mut map = set.map();
                let entry = map
                    .entry(name)
                    .or_insert_with(|| Value::$variant(Vec::new()));
                let Value::$variant(vec) = entry else {
                    *entry = Value::$variant(Vec::new());
                    let Value::$variant(vec) = entry else {
                        unreachable!()
                    };
                    vec.resize_with(index as usize + 1, Default::default);
                    vec[index as usize] = v;
                    return kOfxStatOK;
                };
                if vec.len() <= index as usize {
                    vec.resize_with(index as usize + 1, Default::default);
                }
                vec[index as usize] = v;
                kOfxStatOK
            })
        }
    };
}

setter!(set_string, *const c_char, S, |v| if v.is_null() {
    CString::default()
} else {
    // SAFETY: the plugin passes a NUL-terminated string; we copy it.
    unsafe { CStr::from_ptr(v) }.to_owned()
});
setter!(set_int, c_int, I, |v| v);
setter!(set_double, f64, D, |v| v);
setter!(set_pointer, *mut c_void, P, |v| v as usize);

unsafe extern "C" fn get_any(
    h: OfxPropertySetHandle,
    name: *const c_char,
    index: c_int,
    out: *mut c_void,
    kind: u8,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_any", || {
        // SAFETY: handles we hand out are live PropertySets.
        let (Some(set), Some(name)) = (unsafe { set_of(h) }, name_of(name)) else {
            return kOfxStatErrBadHandle;
        };
        if out.is_null() || index < 0 {
            return kOfxStatErrBadIndex;
        }
        let map = set.map();
        let Some(v) = map.get(&name) else {
            return kOfxStatErrUnknown;
        };
        let i = index as usize;
        // SAFETY: (all arms) `out` points at the plugin's variable of the type the
        // called getter names; string pointers stay valid until the property is set again.
        unsafe {
            match (kind, v) {
                (b's', Value::S(v)) if i < v.len() => *(out as *mut *const c_char) = v[i].as_ptr(),
                (b'i', Value::I(v)) if i < v.len() => *(out as *mut c_int) = v[i],
                (b'd', Value::D(v)) if i < v.len() => *(out as *mut f64) = v[i],
                (b'd', Value::I(v)) if i < v.len() => *(out as *mut f64) = v[i] as f64,
                (b'p', Value::P(v)) if i < v.len() => {
                    *(out as *mut *mut c_void) = v[i] as *mut c_void
                }
                (_, Value::S(v)) if i >= v.len() => return kOfxStatErrBadIndex,
                (_, Value::I(v)) if i >= v.len() => return kOfxStatErrBadIndex,
                (_, Value::D(v)) if i >= v.len() => return kOfxStatErrBadIndex,
                (_, Value::P(v)) if i >= v.len() => return kOfxStatErrBadIndex,
                _ => return kOfxStatErrValue,
            }
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn get_string(
    h: OfxPropertySetHandle,
    n: *const c_char,
    i: c_int,
    out: *mut *mut c_char,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_string", || {
        // SAFETY: the plugin's own arguments, forwarded; `get_any` checks
        // the handle, the name and the out-pointer before use.
        unsafe { get_any(h, n, i, out as *mut c_void, b's') }
    })
}
unsafe extern "C" fn get_int(
    h: OfxPropertySetHandle,
    n: *const c_char,
    i: c_int,
    out: *mut c_int,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_int", || {
        // SAFETY: the plugin's own arguments, forwarded; `get_any` checks
        // the handle, the name and the out-pointer before use.
        unsafe { get_any(h, n, i, out as *mut c_void, b'i') }
    })
}
unsafe extern "C" fn get_double(
    h: OfxPropertySetHandle,
    n: *const c_char,
    i: c_int,
    out: *mut f64,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_double", || {
        // SAFETY: the plugin's own arguments, forwarded; `get_any` checks
        // the handle, the name and the out-pointer before use.
        unsafe { get_any(h, n, i, out as *mut c_void, b'd') }
    })
}
unsafe extern "C" fn get_pointer(
    h: OfxPropertySetHandle,
    n: *const c_char,
    i: c_int,
    out: *mut *mut c_void,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_pointer", || {
        // SAFETY: the plugin's own arguments, forwarded; `get_any` checks
        // the handle, the name and the out-pointer before use.
        unsafe { get_any(h, n, i, out as *mut c_void, b'p') }
    })
}

unsafe extern "C" fn get_dimension(
    h: OfxPropertySetHandle,
    name: *const c_char,
    count: *mut c_int,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_dimension", || {
        // SAFETY: handles we hand out are live PropertySets.
        let (Some(set), Some(name)) = (unsafe { set_of(h) }, name_of(name)) else {
            return kOfxStatErrBadHandle;
        };
        let n = match set.map().get(&name) {
            Some(Value::S(v)) => v.len(),
            Some(Value::I(v)) => v.len(),
            Some(Value::D(v)) => v.len(),
            Some(Value::P(v)) => v.len(),
            None => return kOfxStatErrUnknown,
        };
        if !count.is_null() {
            // SAFETY: non-null out-pointer from the plugin.
            unsafe { *count = n as c_int };
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn reset(h: OfxPropertySetHandle, name: *const c_char) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "reset", || {
        // SAFETY: handles we hand out are live PropertySets.
        let (Some(set), Some(name)) = (unsafe { set_of(h) }, name_of(name)) else {
            return kOfxStatErrBadHandle;
        };
        set.map().remove(&name);
        kOfxStatOK
    })
}

macro_rules! multi {
    ($fn:ident, $one:ident, $t:ty) => {
        unsafe extern "C" fn $fn(
            h: OfxPropertySetHandle,
            name: *const c_char,
            count: c_int,
            values: $t,
        ) -> OfxStatus {
            super::guard::guard(kOfxStatErrUnknown, stringify!($fn), || {
                for k in 0..count.max(0) {
                    // SAFETY: the plugin passes an array of `count` values.
                    let st = unsafe { $one(h, name, k, *values.add(k as usize)) };
                    if st != kOfxStatOK {
                        return st;
                    }
                }
                kOfxStatOK
            })
        }
    };
}
multi!(set_string_n, set_string, *const *const c_char);
multi!(set_int_n, set_int, *const c_int);
multi!(set_double_n, set_double, *const f64);
multi!(set_pointer_n, set_pointer, *const *mut c_void);

macro_rules! multi_get {
    ($fn:ident, $one:ident, $t:ty) => {
        unsafe extern "C" fn $fn(
            h: OfxPropertySetHandle,
            name: *const c_char,
            count: c_int,
            values: $t,
        ) -> OfxStatus {
            super::guard::guard(kOfxStatErrUnknown, stringify!($fn), || {
                for k in 0..count.max(0) {
                    // SAFETY: the plugin passes room for `count` values.
                    let st = unsafe { $one(h, name, k, values.add(k as usize)) };
                    if st != kOfxStatOK {
                        return st;
                    }
                }
                kOfxStatOK
            })
        }
    };
}
multi_get!(get_string_n, get_string, *mut *mut c_char);
multi_get!(get_int_n, get_int, *mut c_int);
multi_get!(get_double_n, get_double, *mut f64);
multi_get!(get_pointer_n, get_pointer, *mut *mut c_void);

pub static SUITE: OfxPropertySuiteV1 = OfxPropertySuiteV1 {
    propSetPointer: Some(set_pointer),
    propSetString: Some(set_string),
    propSetDouble: Some(set_double),
    propSetInt: Some(set_int),
    propSetPointerN: Some(set_pointer_n),
    propSetStringN: Some(set_string_n),
    propSetDoubleN: Some(set_double_n),
    propSetIntN: Some(set_int_n),
    propGetPointer: Some(get_pointer),
    propGetString: Some(get_string),
    propGetDouble: Some(get_double),
    propGetInt: Some(get_int),
    propGetPointerN: Some(get_pointer_n),
    propGetStringN: Some(get_string_n),
    propGetDoubleN: Some(get_double_n),
    propGetIntN: Some(get_int_n),
    propReset: Some(reset),
    propGetDimension: Some(get_dimension),
};
