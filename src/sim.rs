//! In-process closed loop (in progress).
