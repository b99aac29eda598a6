//! The agents of CoMA's pipeline (design §2): the LLM client, the planner, the reviewer and
//! the loop that runs them with the motion model.

pub mod llm;
pub mod pipeline;
pub mod planner;
pub mod reviewer;
