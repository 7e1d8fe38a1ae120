//! Turning a panic inside a kernel into an ordinary error value.

use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// A kernel panicked while a strategy was running a pass.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("a kernel panicked on a worker thread: {message}")]
pub struct KernelPanic {
    /// The panic's message, when it carried a string.
    pub message: String,
}

impl KernelPanic {
    /// Builds the error from the payload that `catch_unwind` or a thread join returned.
    pub fn from_payload(payload: Box<dyn Any + Send>) -> Self {
        let message = if let Some(s) = payload.downcast_ref::<&str>() {
            (*s).to_owned()
        } else if let Some(s) = payload.downcast_ref::<String>() {
            s.clone()
        } else {
            "panic with a non-string payload".to_owned()
        };
        // Leaked, not dropped: a payload whose `Drop` panics would otherwise unwind out of
        // `catch` (rust-lang/rust#86027), past the code that relies on `catch` returning.
        std::mem::forget(payload);
        KernelPanic { message }
    }
}

/// Runs `f`, returning its panic (if any) as a [`KernelPanic`].
///
/// Unwind safety is asserted because a failed pass's outputs are discarded by contract
/// (see [`crate::Executor::for_each_chunk`]).
pub fn catch<R>(f: impl FnOnce() -> R) -> Result<R, KernelPanic> {
    catch_unwind(AssertUnwindSafe(f)).map_err(KernelPanic::from_payload)
}
