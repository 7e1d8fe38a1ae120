//! Turning a panic inside a kernel into an ordinary error value.

use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::OnceLock;

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

/// The first kernel panic of a pass whose kernel calls are caught one by one, on whichever
/// threads run them; later ones are dropped.
#[derive(Default)]
pub(crate) struct FirstPanic(OnceLock<KernelPanic>);

impl FirstPanic {
    /// Runs `f`, keeping its panic if it is the pass's first.
    pub(crate) fn catch(&self, f: impl FnOnce()) {
        if let Err(p) = catch(f) {
            let _ = self.0.set(p); // a later panic: the first one is kept
        }
    }

    /// The pass's outcome: its first kept panic, else `rest` (what escaped around the calls).
    pub(crate) fn or(self, rest: Result<(), KernelPanic>) -> Result<(), KernelPanic> {
        self.0.into_inner().map_or(rest, Err)
    }
}
