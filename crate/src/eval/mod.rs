//! Measuring the model: the field's metrics ([`crate::metrics`]) computed with the text–motion evaluator
//! ([`crate::model::evaluator`]), how far its shipped precision moves them, the
//! evaluation protocol and its report, control probes, and the agents' figures.

// Runs the agents' loop to completion on this thread: native only.
#[cfg(feature = "native")]
pub mod agents;
pub mod agreement;

// Measurements run natively, blocking on the model's reads.
#[cfg(not(target_arch = "wasm32"))]
pub mod probes;
// The dataset motions the probes compare with, read from files: not in the page.
#[cfg(not(target_arch = "wasm32"))]
pub mod references;
// The protocol reviews with the agents' pipeline, whose LLM client type is native-only.
#[cfg(feature = "native")]
pub mod protocol;
#[cfg(feature = "native")]
pub mod report;
// A whole evaluation runs the protocol and the agents: native only.
#[cfg(feature = "native")]
pub mod run;
