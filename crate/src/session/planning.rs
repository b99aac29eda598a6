//! The one place that decides who plans a prompt: the LLM planner when an LLM is configured
//! and the model's vocabulary loaded, else the built-in planner, with a note saying why
//! whenever a configured LLM was not used; then the user's length, if any, is fitted.

use super::command::{Llm, Progress, SessionError};
use super::progress::{plan_event_line, plan_events, Steps};
use crate::agents::llm::Transport;
use crate::agents::planner::{self, offline::Embedder};
use crate::dataset::Vocabulary;
use crate::plan::Plan;

/// What planning reads besides the prompt.
pub struct PlanningContext<'a> {
    /// The model's training vocabulary (`vocabulary.json`); the LLM planner needs it, and the
    /// built-in planner reads which actions the model makes from it.
    pub vocabulary: Option<&'a Vocabulary>,
    /// MiniLM sentence embeddings, so the built-in planner can map unknown movements onto
    /// the training actions.
    pub embed: Option<Embedder<'a>>,
}

/// Plans `prompt` and fits it to `seconds` when given, reporting every planner step.
pub async fn plan_prompt<T: Transport>(
    prompt: &str,
    seconds: Option<f64>,
    llm: &Llm<'_, T>,
    context: &PlanningContext<'_>,
    progress: &mut dyn FnMut(Progress),
) -> Result<Plan, SessionError> {
    let mut steps = Steps::new(progress);
    let plan = plan_with(prompt, None, seconds, llm, context, &mut steps).await?;
    steps.report(Progress::Planned { plan: plan.clone() });
    Ok(plan)
}

/// The plan of a run: `given` (a link's, say) as it is, else the prompt's from the planner;
/// then fitted to `seconds` and reported step by step.
pub(super) async fn plan_with<T: Transport>(
    prompt: &str,
    given: Option<Plan>,
    seconds: Option<f64>,
    llm: &Llm<'_, T>,
    context: &PlanningContext<'_>,
    steps: &mut Steps<'_>,
) -> Result<Plan, SessionError> {
    if given.is_none() && prompt.trim().is_empty() {
        return Err("type what the person should do first".into());
    }
    let mut fallback_note = None;
    let mut plan = match (given, llm, context.vocabulary) {
        (Some(plan), _, _) => plan,
        (None, Llm::On(client), Some(vocabulary)) => {
            steps.step(format!("planning with {}…", client.config().model));
            planner::llm::plan(client, prompt, vocabulary, context.embed, &mut |event| {
                steps.step(plan_event_line(event))
            })
            .await
        }
        (None, llm, _) => {
            fallback_note = match llm {
                Llm::On(_) => Some(
                    "the model's vocabulary did not load, so the built-in planner planned".into(),
                ),
                Llm::Unusable(why) => Some(format!(
                    "the LLM is not used ({why}); the built-in planner planned"
                )),
                Llm::Off => None,
            };
            planner::offline::plan_for(prompt, context.vocabulary, context.embed)
        }
    };
    plan.notes.splice(0..0, fallback_note);
    if let Some(seconds) = seconds {
        plan.fit_seconds(seconds);
    }
    if steps.done() == 0 {
        // Planned in one go: its steps, as fitted.
        for event in plan_events(&plan) {
            steps.step(plan_event_line(&event));
        }
    }
    Ok(plan)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::agents::llm::UreqTransport;
    use crate::executor::block_on;

    fn plan(vocabulary: &Vocabulary) -> Plan {
        let context = PlanningContext {
            vocabulary: Some(vocabulary),
            embed: None,
        };
        let off = Llm::<UreqTransport>::Off;
        block_on(plan_prompt(
            "a person squats",
            None,
            &off,
            &context,
            &mut |_| {},
        ))
        .unwrap()
    }

    #[test]
    fn the_built_in_planner_plans_the_actions_of_the_models_vocabulary() {
        let mut vocabulary: Vocabulary =
            serde_json::from_str(include_str!("../../../static/models/vocabulary.json")).unwrap();
        // A model without squats (the shipped v1 one): the posture library's squat.
        vocabulary.actions.remove("squat");
        let v1 = plan(&vocabulary);
        assert_eq!(v1.segments[0].base, "a person stands still");
        assert!(v1.segments[0].postures.is_some());
        vocabulary.actions.insert("squat".into(), 104);
        vocabulary.words.extend(["does".into(), "squat".into()]);
        let v2 = plan(&vocabulary);
        assert_eq!(v2.segments[0].base, "a person does a squat");
        assert!(v2.segments[0].postures.is_none());
    }
}
