//! The inference worker: a dedicated Web Worker running the same wasm module, which loads the
//! models and answers [`Request`]s, so generating never freezes the page. Replies go back as
//! [`Reply`] JSON; a failed request answers with an error and leaves the models as they were.

use crate::messages::{from_json, to_json, Backend, Motion, Reply, Request};
use coma::model::generate::MotionTokens;
use coma::model::motion_model::{frames_for_seconds, TextFiles};
use coma::model::{MotionModel, SpamFiles};
use coma::skeleton::BodyPart;
use std::cell::RefCell;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::{DedicatedWorkerGlobalScope, MessageEvent};

/// The files of the default model, in the order they are fetched: SPAM's, then the sentence
/// encoder's.
fn model_files() -> Vec<&'static str> {
    use coma::text::minilm::{MODEL_FILE, VOCAB_FILE, WORDS_FILE};
    let mut files = coma::model::WEIGHT_FILES.to_vec();
    files.extend([VOCAB_FILE, WORDS_FILE, MODEL_FILE]);
    files
}

thread_local! {
    static MODEL: RefCell<Option<MotionModel>> = const { RefCell::new(None) };
}

fn scope() -> DedicatedWorkerGlobalScope {
    js_sys::global().unchecked_into()
}

fn post(reply: &Reply) {
    // A worker whose page has gone has no one to tell.
    let _ = scope().post_message(&JsValue::from_str(&to_json(reply)));
}

/// Installs the message handler and says the worker is ready.
pub fn start() {
    let handler = Closure::<dyn FnMut(MessageEvent)>::new(|event: MessageEvent| {
        let text = event.data().as_string().unwrap_or_default();
        wasm_bindgen_futures::spawn_local(async move {
            let reply = match from_json::<Request>(&text) {
                Ok(request) => answer(request)
                    .await
                    .unwrap_or_else(|message| Reply::Error { message }),
                Err(message) => Reply::Error { message },
            };
            post(&reply);
        });
    });
    scope().set_onmessage(Some(handler.as_ref().unchecked_ref()));
    handler.forget();
    post(&Reply::Ready);
}

fn now() -> f64 {
    js_sys::Date::now()
}

async fn fetch(url: &str) -> Result<Vec<u8>, String> {
    let response = gloo_net::http::Request::get(url)
        .send()
        .await
        .map_err(|e| format!("cannot download {url}: {e}"))?;
    if !response.ok() {
        return Err(format!(
            "cannot download {url}: the server answered {} {}",
            response.status(),
            response.status_text()
        ));
    }
    response
        .binary()
        .await
        .map_err(|e| format!("cannot download {url}: {e}"))
}

async fn load(base: &str) -> Result<Reply, String> {
    let started = now();
    let base = base.trim_end_matches('/');
    let names = model_files();
    let mut files = Vec::with_capacity(names.len());
    let mut bytes = 0u64;
    for (i, name) in names.iter().enumerate() {
        post(&Reply::Progress {
            stage: format!("downloading the model: {name}"),
            done: i as u64,
            total: names.len() as u64,
        });
        let data = fetch(&format!("{base}/{name}")).await.map_err(|e| {
            if i == 0 {
                format!(
                    "The motion model is not on this server ({e}). Its default weights are still \
                     being trained: see README.md and MODEL_CARD.md."
                )
            } else {
                e
            }
        })?;
        bytes += data.len() as u64;
        files.push(data);
    }
    post(&Reply::Progress {
        stage: "preparing the model".into(),
        done: names.len() as u64,
        total: names.len() as u64,
    });
    let text = |i: usize| {
        std::str::from_utf8(&files[i]).map_err(|_| format!("{} is not UTF-8 text", names[i]))
    };
    // The models run on the CPU backend: generation reads logits back synchronously, which
    // WebGPU in a browser cannot do.
    let device = burn::tensor::Device::flex();
    let model = MotionModel::from_files(
        &SpamFiles {
            config: text(0)?,
            vq: &files[1],
            base: &files[2],
            residual: &files[3],
            mean: &files[4],
            std: &files[5],
        },
        &TextFiles {
            vocab: text(6)?,
            words: &files[7],
            model: &files[8],
        },
        &device,
    )
    .map_err(|e| format!("the model does not load: {e}"))?;
    let model_id = model.id.clone();
    MODEL.with(|m| *m.borrow_mut() = Some(model));
    Ok(Reply::Loaded {
        model_id,
        backend: Backend::Cpu,
        note: Some("the model runs on the CPU backend in this version".into()),
        bytes,
        millis: now() - started,
    })
}

fn parse_parts(names: &[String]) -> Result<Vec<BodyPart>, String> {
    names
        .iter()
        .map(|n| {
            BodyPart::parse(n).ok_or_else(|| {
                format!("unknown body part '{n}' (left arm, right arm, left leg, right leg)")
            })
        })
        .collect()
}

/// Tokens from a link or the page must fit the model: 4 parts, its layer count, codes of its
/// codebook and a length it can decode.
fn check_tokens(model: &MotionModel, tokens: &MotionTokens) -> Result<(), String> {
    let layers = model.spam.vq_config.layers;
    let codes = model.spam.vq_config.codebook_size as u32;
    let steps = tokens.first().and_then(|p| p.first()).map_or(0, Vec::len);
    let fits = tokens.len() == 4
        && steps > 0
        && steps <= coma::share::MAX_STEPS
        && tokens.iter().all(|p| {
            p.len() == layers
                && p.iter()
                    .all(|l| l.len() == steps && l.iter().all(|c| *c < codes))
        });
    if fits {
        Ok(())
    } else {
        Err(format!(
            "these tokens do not fit the loaded model (4 parts × {layers} layers of codes below {codes} expected)"
        ))
    }
}

fn motion(model: &MotionModel, tokens: MotionTokens) -> Motion {
    let features = model.features(&tokens);
    let joints = coma::features::features_to_joints(&features)
        .iter()
        .map(|p| p.map(|j| j.map(|v| v as f32)))
        .collect();
    Motion {
        tokens,
        joints,
        features: features.iter().map(|f| f.to_vec()).collect(),
    }
}

async fn answer(request: Request) -> Result<Reply, String> {
    if let Request::Load { base } = &request {
        return load(base).await;
    }
    let started = now();
    MODEL.with(|m| {
        let guard = m.borrow();
        let model = guard
            .as_ref()
            .ok_or("the model is not loaded yet".to_string())?;
        let tokens = match request {
            Request::Load { .. } => unreachable!("answered above"),
            Request::Generate {
                prompt,
                seconds,
                seed,
                parts,
            } => {
                let parts = parts
                    .iter()
                    .map(|(name, text)| {
                        Ok((parse_parts(std::slice::from_ref(name))?[0], text.clone()))
                    })
                    .collect::<Result<Vec<_>, String>>()?;
                if prompt.trim().is_empty() {
                    return Err("type what the person should do first".into());
                }
                model.generate(&prompt, &parts, frames_for_seconds(seconds), seed)
            }
            Request::InBetween {
                tokens,
                text,
                from,
                to,
                seed,
            } => {
                check_tokens(model, &tokens)?;
                let frames = tokens[0][0].len() * 4;
                if from >= to || from >= frames {
                    return Err(format!(
                        "choose a time range inside the motion (0 to {:.1} s)",
                        frames as f64 / 20.0
                    ));
                }
                model.inbetween(&tokens, &text, from, to.min(frames), seed)
            }
            Request::EditParts {
                tokens,
                text,
                parts,
                seed,
            } => {
                check_tokens(model, &tokens)?;
                let parts = parse_parts(&parts)?;
                if parts.is_empty() {
                    return Err("choose at least one body part to edit".into());
                }
                let rest = coma::posecodes::describe_motion(&model.joints(&tokens));
                model.edit_parts(&tokens, &text, &parts, &rest, seed)
            }
            Request::Decode { tokens } => {
                check_tokens(model, &tokens)?;
                tokens
            }
        };
        Ok(Reply::Motion {
            motion: motion(model, tokens),
            millis: now() - started,
        })
    })
}
