//! PID, Mamdani fuzzy engine and cross-coupled controller (in progress).
