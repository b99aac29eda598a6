//! The one executor the native side needs: the library's async calls (reading tensors back
//! from a device, the LLM client) are awaited in the page and blocked on natively.

/// Runs a future to completion on the current thread, parking between polls (pollster's).
///
/// Natively, the model's reads from its device and the LLM client's transport complete their
/// futures synchronously or from another thread, so this is all the executor they need. Not
/// available on wasm32, where the thread cannot block and the page awaits instead.
#[cfg(not(target_arch = "wasm32"))]
pub use pollster::block_on;

#[cfg(all(test, not(target_arch = "wasm32")))]
mod tests {
    use super::*;

    #[test]
    fn block_on_drives_a_future_woken_from_another_thread() {
        use std::future::Future;
        use std::pin::Pin;
        use std::sync::{Arc, Mutex};
        use std::task::{Context, Poll};

        // Pending until a helper thread sets the flag and wakes us.
        struct Flag(Arc<Mutex<(bool, bool)>>);
        impl Future for Flag {
            type Output = u8;
            fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<u8> {
                let mut state = self.0.lock().unwrap();
                if state.0 {
                    return Poll::Ready(7);
                }
                if !state.1 {
                    state.1 = true;
                    let shared = Arc::clone(&self.0);
                    let waker = cx.waker().clone();
                    std::thread::spawn(move || {
                        shared.lock().unwrap().0 = true;
                        waker.wake();
                    });
                }
                Poll::Pending
            }
        }
        assert_eq!(block_on(async { 1 }), 1);
        assert_eq!(block_on(Flag(Arc::new(Mutex::new((false, false))))), 7);
    }
}
