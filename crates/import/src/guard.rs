//! Containing a dependency's panic: [`contain`] runs a call under `catch_unwind` and says, while
//! it runs, that a panic there is expected ([`containing_a_panic`]), so that a program's panic
//! hook can stay silent for it: the user gets the loader's one-line error, not a panic message
//! followed by it.

use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};

thread_local! {
    static CONTAINING: Cell<u32> = const { Cell::new(0) };
}

/// Runs `f`; `Err(())` if it panicked (the panic is contained).
pub(crate) fn contain<R>(f: impl FnOnce() -> R) -> Result<R, ()> {
    CONTAINING.with(|c| c.set(c.get() + 1));
    let result = catch_unwind(AssertUnwindSafe(f)).map_err(|_| ());
    CONTAINING.with(|c| c.set(c.get().saturating_sub(1)));
    result
}

/// Whether this thread is running a call whose panic a loader contains (a dependency's
/// validation, say): a panic hook may then stay silent, as the panic will become the loader's
/// one-line error.
#[must_use]
pub fn containing_a_panic() -> bool {
    CONTAINING.with(Cell::get) > 0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_contained_panic_is_an_error_and_flagged_while_it_runs() {
        assert!(!containing_a_panic());
        let seen = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let inside = seen.clone();
        let default_hook = std::panic::take_hook();
        // What a program's hook sees: the flag is up while the contained call panics.
        // (Only ever set: a panic of another test's thread must not clear it.)
        std::panic::set_hook(Box::new(move |_| {
            if containing_a_panic() {
                inside.store(true, std::sync::atomic::Ordering::SeqCst);
            }
        }));
        let result: Result<(), ()> = contain(|| panic!("a dependency's bug"));
        std::panic::set_hook(default_hook);
        assert_eq!(result, Err(()));
        assert!(seen.load(std::sync::atomic::Ordering::SeqCst));
        assert!(!containing_a_panic());
        assert_eq!(contain(|| 7), Ok(7));
    }
}
