//! Status codes and the error type every instance operation returns.

use fmi2_bindings::{
    fmi2Status, fmi2Status_fmi2Discard, fmi2Status_fmi2Error, fmi2Status_fmi2Fatal,
    fmi2Status_fmi2OK, fmi2Status_fmi2Warning,
};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum Status {
    Ok = fmi2Status_fmi2OK,
    Warning = fmi2Status_fmi2Warning,
    Discard = fmi2Status_fmi2Discard,
    Error = fmi2Status_fmi2Error,
    Fatal = fmi2Status_fmi2Fatal,
}

impl Status {
    pub fn code(self) -> fmi2Status {
        self as fmi2Status
    }
}

/// Why a call did not return `fmi2OK`; the message is logged with the function's name.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    pub status: Status,
    pub message: String,
}

impl Failure {
    pub fn error(message: impl Into<String>) -> Self {
        Failure {
            status: Status::Error,
            message: message.into(),
        }
    }

    pub fn discard(message: impl Into<String>) -> Self {
        Failure {
            status: Status::Discard,
            message: message.into(),
        }
    }
}

pub type Outcome<T = ()> = Result<T, Failure>;
