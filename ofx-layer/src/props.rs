//! Safe access to OFX property sets.

use std::ffi::{c_char, c_void, CStr, CString};

use openfx::sys::generic::core::*;
use openfx::sys::generic::property::*;

use super::{check, host, Failure, Outcome};

#[derive(Clone, Copy)]
pub struct PropSet {
    handle: OfxPropertySetHandle,
    suite: &'static OfxPropertySuiteV1,
}

fn name_of(name: &CStr) -> String {
    name.to_string_lossy().into_owned()
}

fn cstring(v: &str) -> CString {
    // Interior NULs cannot cross the C ABI: cut the string there.
    CString::new(v.split('\0').next().unwrap_or_default()).unwrap_or_default()
}

macro_rules! call {
    ($self:ident, $f:ident, $name:expr, $($arg:expr),*) => {{
        let missing = || Failure::Failed(concat!("host has no ", stringify!($f)).into());
        let f = $self.suite.$f.ok_or_else(missing)?;
        // SAFETY: `handle` came from the host for this action and is non-null
        // (checked in `new`); names are NUL-terminated; out-pointers point at
        // live locals of the right type.
        let status = unsafe { f($self.handle, $name.as_ptr(), $($arg),*) };
        check(status, &format!("{} of {}", stringify!($f), name_of($name)))
    }};
}

impl PropSet {
    /// The property set behind a host's handle.
    ///
    /// # Safety
    /// `handle` is null (refused) or a property set handle the host gave us
    /// (an action's arguments, or a suite call's answer), valid for as long
    /// as the returned value is used.
    pub unsafe fn from_raw(handle: OfxPropertySetHandle) -> Outcome<Self> {
        if handle.is_null() {
            return Err(Failure::Status(
                kOfxStatErrBadHandle,
                "null property set".into(),
            ));
        }
        Ok(PropSet {
            handle,
            suite: host::suites()?.prop,
        })
    }

    pub(super) fn handle(&self) -> OfxPropertySetHandle {
        self.handle
    }

    pub fn set_string(&self, name: &CStr, index: i32, value: &str) -> Outcome {
        let v = cstring(value);
        // The host copies string values on set (OFX property suite).
        call!(self, propSetString, name, index, v.as_ptr())
    }
    pub fn set_strings(&self, name: &CStr, values: &[&str]) -> Outcome {
        for (i, v) in values.iter().enumerate() {
            self.set_string(name, i as i32, v)?;
        }
        Ok(())
    }
    pub fn set_int(&self, name: &CStr, index: i32, value: i32) -> Outcome {
        call!(self, propSetInt, name, index, value)
    }
    pub fn set_double(&self, name: &CStr, index: i32, value: f64) -> Outcome {
        call!(self, propSetDouble, name, index, value)
    }
    pub fn set_doubles(&self, name: &CStr, values: &[f64]) -> Outcome {
        for (i, v) in values.iter().enumerate() {
            self.set_double(name, i as i32, *v)?;
        }
        Ok(())
    }
    pub fn set_pointer(&self, name: &CStr, index: i32, value: *mut c_void) -> Outcome {
        call!(self, propSetPointer, name, index, value)
    }

    pub fn get_int(&self, name: &CStr, index: i32) -> Outcome<i32> {
        let mut v = 0;
        call!(self, propGetInt, name, index, &mut v)?;
        Ok(v)
    }
    pub fn get_ints<const N: usize>(&self, name: &CStr) -> Outcome<[i32; N]> {
        let mut out = [0; N];
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.get_int(name, i as i32)?;
        }
        Ok(out)
    }
    pub fn get_double(&self, name: &CStr, index: i32) -> Outcome<f64> {
        let mut v = 0.0;
        call!(self, propGetDouble, name, index, &mut v)?;
        Ok(v)
    }
    pub fn get_doubles<const N: usize>(&self, name: &CStr) -> Outcome<[f64; N]> {
        let mut out = [0.0; N];
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.get_double(name, i as i32)?;
        }
        Ok(out)
    }
    pub fn get_pointer(&self, name: &CStr, index: i32) -> Outcome<*mut c_void> {
        let mut v: *mut c_void = std::ptr::null_mut();
        call!(self, propGetPointer, name, index, &mut v)?;
        Ok(v)
    }
    /// Every value of a string property.
    pub fn get_strings(&self, name: &CStr) -> Outcome<Vec<String>> {
        let mut n = 0;
        call!(self, propGetDimension, name, &mut n)?;
        (0..n).map(|i| self.get_string(name, i)).collect()
    }
    pub fn get_string(&self, name: &CStr, index: i32) -> Outcome<String> {
        let mut v: *mut c_char = std::ptr::null_mut();
        call!(self, propGetString, name, index, &mut v)?;
        if v.is_null() {
            return Ok(String::new());
        }
        // SAFETY: the host returned a NUL-terminated string it owns and keeps
        // valid at least until the next call on this property set; we copy it now.
        Ok(unsafe { CStr::from_ptr(v) }.to_string_lossy().into_owned())
    }
}
