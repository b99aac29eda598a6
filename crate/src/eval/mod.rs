//! Measuring the model: the text–motion evaluator, the field's metrics computed with it, the
//! evaluation protocol and its report, control probes, and the agents' figures.

// Runs the agents' loop to completion on this thread: native only.
#[cfg(feature = "native")]
pub mod agents;
pub mod evaluator;
pub mod metrics;
// Measurements run natively, blocking on the model's reads.
#[cfg(not(target_arch = "wasm32"))]
pub mod probes;
// The protocol reviews with the agents' pipeline, whose LLM client type is native-only.
#[cfg(feature = "native")]
pub mod protocol;
#[cfg(feature = "native")]
pub mod report;
