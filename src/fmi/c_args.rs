//! C arguments as Rust values: arrays as slices (NULL refused where the length is not 0)
//! and strings as `&str`.

use std::ffi::{c_char, CStr};

use super::status::{Failure, Outcome};

/// A slice from a C array, refusing NULL with a non-zero length.
#[inline]
pub unsafe fn slice<'a, T>(data: *const T, len: usize, what: &str) -> Outcome<&'a [T]> {
    if len == 0 {
        Ok(&[])
    } else if data.is_null() {
        Err(null_array(what, len))
    } else {
        Ok(std::slice::from_raw_parts(data, len))
    }
}

#[inline]
pub unsafe fn slice_mut<'a, T>(data: *mut T, len: usize, what: &str) -> Outcome<&'a mut [T]> {
    if len == 0 {
        Ok(&mut [])
    } else if data.is_null() {
        Err(null_array(what, len))
    } else {
        Ok(std::slice::from_raw_parts_mut(data, len))
    }
}

/// A slice from a C array for a fast path: `None` for NULL with a non-zero length.
#[inline(always)]
pub unsafe fn array<'a, T>(data: *const T, len: usize) -> Option<&'a [T]> {
    match len {
        0 => Some(&[]),
        _ if data.is_null() => None,
        _ => Some(std::slice::from_raw_parts(data, len)),
    }
}

#[inline(always)]
pub unsafe fn array_mut<'a, T>(data: *mut T, len: usize) -> Option<&'a mut [T]> {
    match len {
        0 => Some(&mut []),
        _ if data.is_null() => None,
        _ => Some(std::slice::from_raw_parts_mut(data, len)),
    }
}

#[cold]
#[inline(never)]
fn null_array(what: &str, len: usize) -> Failure {
    Failure::error(format!("{what} is NULL but its length is {len}"))
}

/// The UTF-8 text of a C string; `None` for NULL or invalid UTF-8.
pub unsafe fn c_str<'a>(text: *const c_char) -> Option<&'a str> {
    if text.is_null() {
        None
    } else {
        CStr::from_ptr(text).to_str().ok()
    }
}
