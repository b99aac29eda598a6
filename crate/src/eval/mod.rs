//! Measuring the model: the text–motion evaluator, the field's metrics computed with it, the
//! evaluation protocol and its report, and control probes.

pub mod evaluator;
pub mod metrics;
pub mod probes;
pub mod protocol;
pub mod report;
