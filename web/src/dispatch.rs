//! The worker's one job besides loading, without the browser in it, so it builds and is
//! tested natively: an engine command from the page and its LLM settings in, the engine's
//! progress and outcome out as [`Reply`]s. The worker (wasm) calls it with the browser's
//! `fetch` transport and `postMessage`.

use crate::messages::{LlmSettings, Reply};
use coma::agents::llm::{LlmClient, LlmConfig, Transport};
use coma::session::{Command, Llm, Session};

/// The LLM configuration of the Settings panel's endpoint.
pub fn llm_config(settings: LlmSettings) -> LlmConfig {
    let mut config =
        LlmConfig::new(settings.base_url, settings.model).with_api_key(settings.api_key);
    config.vision_model = (!settings.vision_model.is_empty()).then_some(settings.vision_model);
    config
}

/// Carries out `command` in `session` with the LLM of `settings` (made by `client`, whose
/// failure the engine notes and works around), posting each progress step; answers with the
/// outcome and the milliseconds `clock` measured, or the engine's error.
pub async fn execute<T: Transport>(
    session: &Session,
    command: Command,
    settings: Option<LlmSettings>,
    client: impl FnOnce(LlmConfig) -> Result<LlmClient<T>, String>,
    post: &mut dyn FnMut(Reply),
    clock: &dyn Fn() -> f64,
) -> Reply {
    let started = clock();
    let client = settings.map(|s| client(llm_config(s)));
    let llm = match &client {
        None => Llm::Off,
        Some(Ok(client)) => Llm::On(client),
        Some(Err(why)) => Llm::Unusable(why.clone()),
    };
    match session
        .execute(command, &llm, &mut |progress| {
            post(Reply::Progress { progress })
        })
        .await
    {
        Ok(outcome) => Reply::Done {
            outcome,
            millis: clock() - started,
        },
        Err(e) => Reply::Error {
            message: e.to_string(),
        },
    }
}
