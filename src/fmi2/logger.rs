//! The importer's logger callback, with the five log categories of our model
//! descriptions. Messages are always passed as the argument of a `"%s"` format, so a
//! `%` in a message can never be read as a conversion.

use std::ffi::{c_char, CStr, CString};

use fmi_sys::fmi2::{fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status};

use super::status::Status;

/// Log categories, in `LogCategories` order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Category {
    Events,
    StatusWarning,
    StatusError,
    StatusFatal,
    All,
}

impl Category {
    pub const ALL: [Category; 5] = [
        Category::Events,
        Category::StatusWarning,
        Category::StatusError,
        Category::StatusFatal,
        Category::All,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Category::Events => "logEvents",
            Category::StatusWarning => "logStatusWarning",
            Category::StatusError => "logStatusError",
            Category::StatusFatal => "logStatusFatal",
            Category::All => "logAll",
        }
    }

    pub fn description(self) -> &'static str {
        match self {
            Category::Events => {
                "Life-cycle events: instantiation, initialization, reset, termination"
            }
            Category::StatusWarning => "Calls that return fmi2Warning or fmi2Discard",
            Category::StatusError => "Calls that return fmi2Error (always logged)",
            Category::StatusFatal => "Calls that return fmi2Fatal (always logged)",
            Category::All => "Every call into the FMU",
        }
    }

    pub fn from_name(name: &str) -> Option<Category> {
        Category::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The category a message with this status belongs to.
    pub fn for_status(status: Status) -> Category {
        match status {
            Status::Ok => Category::Events,
            Status::Warning | Status::Discard => Category::StatusWarning,
            Status::Error => Category::StatusError,
            Status::Fatal => Category::StatusFatal,
        }
    }
}

pub struct Logger {
    callback: fmi2CallbackLogger,
    environment: fmi2ComponentEnvironment,
    instance_name: CString,
    enabled: [bool; 5],
}

impl Logger {
    pub fn new(
        callback: fmi2CallbackLogger,
        environment: fmi2ComponentEnvironment,
        instance_name: &str,
        logging_on: bool,
    ) -> Self {
        Logger {
            callback,
            environment,
            instance_name: to_c_string(instance_name),
            enabled: [logging_on; 5],
        }
    }

    /// `fmi2SetDebugLogging`: with no categories the switch applies to all of them.
    pub fn set(&mut self, on: bool, categories: &[Category]) {
        if categories.is_empty() {
            self.enabled = [on; 5];
        }
        for &c in categories {
            self.enabled[c as usize] = on;
        }
    }

    pub fn is_enabled(&self, category: Category) -> bool {
        self.enabled[category as usize] || self.enabled[Category::All as usize]
    }

    /// Sends a message; errors and fatal errors always, the rest when their category is on.
    pub fn log(&self, status: Status, category: Category, message: &str) {
        let always = matches!(status, Status::Error | Status::Fatal);
        if !always && !self.is_enabled(category) {
            return;
        }
        let Some(callback) = self.callback else {
            return;
        };
        let category = to_c_string(category.name());
        let message = to_c_string(message);
        let format: &CStr = c"%s";
        // SAFETY: the importer guaranteed the callback and its environment stay valid for
        // the instance's lifetime; every string is NUL-terminated and outlives the call,
        // and the variadic argument matches the "%s" conversion.
        unsafe {
            callback(
                self.environment,
                self.instance_name.as_ptr(),
                status as fmi2Status,
                category.as_ptr(),
                format.as_ptr(),
                message.as_ptr() as *const c_char,
            );
        }
    }
}

/// A C string of `text`, with any interior NUL replaced so nothing is cut off silently.
pub fn to_c_string(text: &str) -> CString {
    CString::new(text.replace('\0', "\u{2400}")).expect("interior NULs were replaced")
}
