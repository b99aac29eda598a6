//! Waiting on the browser with a limit. Some browser calls can stay unanswered for good (a
//! busy or wedged GPU process never resolves `requestAdapter`; a worker that dies without an
//! error event never answers), and a page that waits on them forever looks dead: the callers
//! give up after a while and take the slower path they already have.

use futures::future::{select, Either};
use std::future::Future;

/// `future`'s output, or `None` when `millis` milliseconds pass first (the future is then
/// dropped; a JS promise behind it settles unobserved).
pub async fn within<T>(millis: u32, future: impl Future<Output = T>) -> Option<T> {
    let timer = gloo_timers::future::TimeoutFuture::new(millis);
    match select(std::pin::pin!(future), timer).await {
        Either::Left((value, _)) => Some(value),
        Either::Right(_) => None,
    }
}
