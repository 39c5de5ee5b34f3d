//! The importer's logger callback, with the five log categories of our model
//! descriptions: FMI 2.0's (variadic, with the instance name; messages are always passed as
//! the argument of a `"%s"` format, so a `%` in a message can never be read as a
//! conversion) or FMI 3.0's (the message as it is, no format arguments).

use std::cell::RefCell;
use std::ffi::{c_char, CStr, CString};

use fmi2_bindings::{fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status, fmi2String};
use fmi3_bindings::{fmi3InstanceEnvironment, fmi3LogMessageCallback, fmi3Status, fmi3String};

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

    /// The name as a C string.
    pub fn name_c(self) -> &'static CStr {
        match self {
            Category::Events => c"logEvents",
            Category::StatusWarning => c"logStatusWarning",
            Category::StatusError => c"logStatusError",
            Category::StatusFatal => c"logStatusFatal",
            Category::All => c"logAll",
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

/// The importer's callback of either standard.
#[derive(Clone, Copy)]
pub enum Callback {
    Fmi2(
        unsafe extern "C" fn(
            fmi2ComponentEnvironment,
            fmi2String,
            fmi2Status,
            fmi2String,
            fmi2String,
            ...
        ),
    ),
    Fmi3(unsafe extern "C" fn(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String)),
}

impl Callback {
    pub fn fmi2(callback: fmi2CallbackLogger) -> Option<Callback> {
        callback.map(Callback::Fmi2)
    }

    pub fn fmi3(callback: fmi3LogMessageCallback) -> Option<Callback> {
        callback.map(Callback::Fmi3)
    }
}

/// Where an instance's messages go. Messages are queued while the instance is locked and
/// sent once the lock is released ([`Logger::take`] then [`Outbox::send`]): an importer's
/// logger may call back into the same instance, which must not deadlock.
pub struct Logger {
    callback: Option<Callback>,
    /// The importer's `componentEnvironment` (FMI 2.0) or `instanceEnvironment` (FMI 3.0).
    environment: *mut std::ffi::c_void,
    instance_name: CString,
    enabled: [bool; 5],
    pending: RefCell<Vec<Message>>,
}

// SAFETY: `Logger` is not `Send` by itself only because of the importer's environment
// pointer (and the `RefCell` makes it `!Sync`, which is fine: it is only ever used through
// `&mut Instance` behind the instance's mutex). We never dereference that pointer; we only
// hand it back to the importer's own logger callback, as both standards require. They let
// an importer call an instance from any thread as long as calls on one instance do not
// overlap, and the instance mutex serialises them, so moving the logger (inside its
// instance) to another thread cannot create a data race on our side.
unsafe impl Send for Logger {}

struct Message {
    status: Status,
    category: Category,
    text: CString,
}

/// Messages taken out of a [`Logger`], ready to be sent without holding the instance.
pub struct Outbox {
    callback: Callback,
    environment: *mut std::ffi::c_void,
    instance_name: CString,
    messages: Vec<Message>,
}

impl Logger {
    pub fn new(
        callback: Option<Callback>,
        environment: *mut std::ffi::c_void,
        instance_name: &str,
        logging_on: bool,
    ) -> Self {
        Logger {
            callback,
            environment,
            instance_name: to_c_string(instance_name),
            enabled: [logging_on; 5],
            pending: RefCell::new(Vec::new()),
        }
    }

    /// `fmi2SetDebugLogging` (FMI 2.0 section 2.1.5): switched on with categories, only
    /// those are logged; on or off without categories, all of them; off with categories,
    /// those are switched off and the rest stay as they were.
    pub fn set(&mut self, on: bool, categories: &[Category]) {
        if categories.is_empty() {
            self.enabled = [on; 5];
            return;
        }
        if on {
            self.enabled = [false; 5];
        }
        for &c in categories {
            self.enabled[c as usize] = on;
        }
    }

    /// Whether messages of `category` are logged (`logAll`, when on, includes every other).
    pub fn is_enabled(&self, category: Category) -> bool {
        self.enabled[category as usize] || self.enabled[Category::All as usize]
    }

    /// Queues a message: errors and fatal errors always, the rest when their category is on.
    pub fn log(&self, status: Status, category: Category, message: &str) {
        let always = matches!(status, Status::Error | Status::Fatal);
        if self.callback.is_none() || (!always && !self.is_enabled(category)) {
            return;
        }
        self.pending.borrow_mut().push(Message {
            status,
            category,
            text: to_c_string(message),
        });
    }

    /// The queued messages, if any (nothing is allocated when there are none). Inlined:
    /// every call ends with it, and almost every call has nothing queued.
    #[inline]
    pub fn take(&self) -> Option<Outbox> {
        if self.pending.borrow().is_empty() {
            return None;
        }
        self.take_queued()
    }

    #[cold]
    fn take_queued(&self) -> Option<Outbox> {
        let callback = self.callback?;
        let messages = std::mem::take(&mut *self.pending.borrow_mut());
        (!messages.is_empty()).then(|| Outbox {
            callback,
            environment: self.environment,
            instance_name: self.instance_name.clone(),
            messages,
        })
    }

    /// Sends the queued messages now (for callers that hold no lock).
    pub fn flush(&self) {
        if let Some(outbox) = self.take() {
            outbox.send();
        }
    }
}

impl Outbox {
    pub fn send(self) {
        let format: &CStr = c"%s";
        for m in &self.messages {
            let category = m.category.name_c().as_ptr();
            let text = m.text.as_ptr() as *const c_char;
            // SAFETY: the importer guaranteed the callback and its environment stay valid
            // for the instance's lifetime; every string is NUL-terminated and outlives the
            // call, and FMI 2.0's variadic argument matches the "%s" conversion.
            unsafe {
                match self.callback {
                    Callback::Fmi2(callback) => callback(
                        self.environment,
                        self.instance_name.as_ptr(),
                        m.status as fmi2Status,
                        category,
                        format.as_ptr(),
                        text,
                    ),
                    Callback::Fmi3(callback) => {
                        callback(self.environment, m.status as fmi3Status, category, text)
                    }
                }
            }
        }
    }
}

/// A C string of `text`, with any interior NUL replaced so nothing is cut off silently.
pub fn to_c_string(text: &str) -> CString {
    CString::new(text.replace('\0', "\u{2400}")).expect("interior NULs were replaced")
}
