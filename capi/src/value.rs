//! Values across the boundary: `situ_value` (a typed value, in and out),
//! `situ_arg` (a value for a field by name), C strings in and out.

use crate::error::{situ_status, Failure};
use situ_api::{Arg, FieldValue};
use std::ffi::{c_char, CStr, CString};

/// The type of a `situ_value` (one of the `SITU_*` type constants).
pub type situ_type = u32;
/// A number (`f64` in the rules); an integer is taken for it too.
pub const SITU_F64: situ_type = 0;
/// An integer (`i64` in the rules).
pub const SITU_I64: situ_type = 1;
/// A boolean.
pub const SITU_BOOL: situ_type = 2;
/// A symbol of an enumeration, by name.
pub const SITU_SYMBOL: situ_type = 3;

/// A typed value: `kind` says which member holds it. Build one with
/// `situ_f64`, `situ_i64`, `situ_bool` or `situ_symbol`.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct situ_value {
    pub kind: situ_type,
    pub f64: f64,
    pub i64: i64,
    pub boolean: bool,
    /// A NUL-terminated UTF-8 name. In a value situ returns, owned by the
    /// handle it came from.
    pub symbol: *const c_char,
}

/// A value for an event's field, by the field's name.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct situ_arg {
    pub field: *const c_char,
    pub value: situ_value,
}

const EMPTY: situ_value = situ_value { kind: SITU_F64, f64: 0.0, i64: 0, boolean: false, symbol: std::ptr::null() };

/// A number.
#[no_mangle]
pub extern "C" fn situ_f64(x: f64) -> situ_value {
    situ_value { kind: SITU_F64, f64: x, ..EMPTY }
}

/// An integer.
#[no_mangle]
pub extern "C" fn situ_i64(x: i64) -> situ_value {
    situ_value { kind: SITU_I64, i64: x, ..EMPTY }
}

/// A boolean.
#[no_mangle]
pub extern "C" fn situ_bool(x: bool) -> situ_value {
    situ_value { kind: SITU_BOOL, boolean: x, ..EMPTY }
}

/// A symbol by name (the string is read when the value is used, not
/// copied: keep it alive until then).
#[no_mangle]
pub extern "C" fn situ_symbol(name: *const c_char) -> situ_value {
    situ_value { kind: SITU_SYMBOL, symbol: name, ..EMPTY }
}

/// A C string as UTF-8; `what` names it in the error.
pub(crate) unsafe fn text<'a>(s: *const c_char, what: &str) -> Result<&'a str, Failure> {
    if s.is_null() {
        return Err(Failure::new(situ_status::SITU_ERR_NULL, format!("{what} is null")));
    }
    CStr::from_ptr(s)
        .to_str()
        .map_err(|e| Failure::new(situ_status::SITU_ERR_UTF8, format!("{what} is not UTF-8: {e}")))
}

/// A caller's array of `count` elements (null only when `count` is 0).
pub(crate) unsafe fn slice<'a, T>(p: *const T, count: usize, what: &str) -> Result<&'a [T], Failure> {
    if count == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Failure::new(situ_status::SITU_ERR_NULL, format!("{what} is null with a count of {count}")));
    }
    Ok(std::slice::from_raw_parts(p, count))
}

/// A place to write to, checked for null.
pub(crate) unsafe fn place<'a, T>(p: *mut T, what: &str) -> Result<&'a mut T, Failure> {
    p.as_mut().ok_or_else(|| Failure::new(situ_status::SITU_ERR_NULL, format!("{what} is null")))
}

/// A caller's value as the board's argument.
pub(crate) unsafe fn arg<'a>(v: &'a situ_value, field: &str) -> Result<Arg<'a>, Failure> {
    Ok(match v.kind {
        SITU_F64 => Arg::F64(v.f64),
        SITU_I64 => Arg::I64(v.i64),
        SITU_BOOL => Arg::Bool(v.boolean),
        SITU_SYMBOL => Arg::Symbol(text(v.symbol, &format!("the symbol for {field}"))?),
        other => {
            return Err(Failure::new(
                situ_status::SITU_ERR_ARGUMENT,
                format!(
                "the value for {field} has type {other}, which is none of SITU_F64, SITU_I64, SITU_BOOL, SITU_SYMBOL"
            ),
            ))
        }
    })
}

/// A string for C; a NUL inside (which no name of the rules has) becomes a space.
pub(crate) fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', " ")).unwrap_or_default()
}

/// A fact's value for C; a symbol's name is `symbol`, owned by the caller.
pub(crate) fn out_value(v: &FieldValue, symbol: *const c_char) -> situ_value {
    match v {
        FieldValue::F64(x) => situ_f64(*x),
        FieldValue::I64(x) => situ_i64(*x),
        FieldValue::Bool(x) => situ_bool(*x),
        FieldValue::Symbol(_) => situ_symbol(symbol),
    }
}
