//! The inference worker: a dedicated Web Worker running the same wasm module, which loads the
//! models and answers [`Request`]s, so generating never freezes the page. Replies go back as
//! [`Reply`] JSON; a failed request answers with an error and leaves the models as they were.

use crate::llm_fetch::FetchTransport;
use crate::messages::{
    from_json, to_json, Backend, LlmSettings, Motion, Reply, Request, SegmentScores,
};
use crate::planning;
use coma::agents::llm::{LlmClient, LlmConfig};
use coma::agents::pipeline::{self, RunOptions};
use coma::agents::plan::Plan;
use coma::agents::planner::{self, offline::Embedder};
use coma::agents::reviewer::Scorer;
use coma::dataset::Vocabulary;
use coma::eval::evaluator::{Evaluator, EvaluatorConfig};
use coma::model::generate::MotionTokens;
use coma::model::motion_model::{frames_for_seconds, TextFiles};
use coma::model::{MotionModel, SpamConfig, SpamFiles, RESIDUAL_FILE};
use coma::skeleton::BodyPart;
use coma::text::minilm::{MODEL_FILE, VOCAB_FILE, WORDS_FILE};
use std::cell::{Cell, RefCell};
use std::rc::Rc;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::{DedicatedWorkerGlobalScope, MessageEvent};

/// The sentence encoder's files, fetched after SPAM's.
const TEXT_FILES: [&str; 3] = [VOCAB_FILE, WORDS_FILE, MODEL_FILE];

/// The agents' files, fetched after the model: the page works without them, with less.
const EVALUATOR_FILES: [&str; 2] = ["evaluator.json", "evaluator.bpk"];
const VOCABULARY_FILE: &str = "vocabulary.json";

/// Everything loaded: the motion model, and what the reviewer and the LLM planner need
/// where it loaded.
struct Models {
    model: MotionModel,
    evaluator: Option<(Evaluator, EvaluatorConfig)>,
    vocabulary: Option<Vocabulary>,
}

thread_local! {
    // Shared out as an Rc so a request can hold the models across the awaits of an LLM call.
    static MODELS: RefCell<Option<Rc<Models>>> = const { RefCell::new(None) };
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

/// Whether the browser offers a WebGPU adapter: `None` without one, else whether it is a
/// software (fallback) adapter such as SwiftShader.
async fn webgpu_adapter() -> Option<bool> {
    let navigator = js_sys::Reflect::get(&scope(), &"navigator".into()).ok()?;
    let gpu = js_sys::Reflect::get(&navigator, &"gpu".into()).ok()?;
    let request = js_sys::Reflect::get(&gpu, &"requestAdapter".into())
        .ok()?
        .dyn_into::<js_sys::Function>()
        .ok()?;
    let promise = request
        .call0(&gpu)
        .ok()?
        .dyn_into::<js_sys::Promise>()
        .ok()?;
    let adapter = wasm_bindgen_futures::JsFuture::from(promise).await.ok()?;
    if adapter.is_null() || adapter.is_undefined() {
        return None;
    }
    // Newer browsers say it in `adapter.info`, older ones on the adapter itself.
    let flag = |of: &JsValue| {
        js_sys::Reflect::get(of, &"isFallbackAdapter".into())
            .ok()
            .and_then(|v| v.as_bool())
    };
    let info = js_sys::Reflect::get(&adapter, &"info".into()).ok();
    Some(
        info.as_ref()
            .and_then(flag)
            .or_else(|| flag(&adapter))
            .unwrap_or(false),
    )
}

/// The device SPAM runs on: WebGPU where the browser has a hardware adapter (or where it is
/// asked for), else the CPU backend, with the reason.
async fn choose_device(asked: Option<Backend>) -> (burn::tensor::Device, Backend, Option<String>) {
    let cpu = |why: String| (burn::tensor::Device::flex(), Backend::Cpu, Some(why));
    if asked == Some(Backend::Cpu) {
        return cpu("the page asked for the CPU backend (?backend=cpu)".into());
    }
    match webgpu_adapter().await {
        None => cpu("this browser offers no WebGPU adapter, so the model runs on the CPU".into()),
        Some(true) if asked != Some(Backend::WebGpu) => cpu(
            "the browser's only WebGPU adapter is a software one, slower than the CPU backend, \
             so the model runs on the CPU (?backend=webgpu uses it anyway)"
                .into(),
        ),
        Some(_) => match burn::tensor::Device::wgpu_options().init_async().await {
            Ok(device) => (device, Backend::WebGpu, None),
            Err(e) => cpu(format!(
                "WebGPU did not start ({e}), so the model runs on the CPU"
            )),
        },
    }
}

async fn load(base: &str, asked: Option<Backend>) -> Result<Reply, String> {
    let started = now();
    let base = base.trim_end_matches('/');
    let not_here = |e: String| {
        format!(
            "The motion model is not on this server ({e}). See README.md for how to serve it \
             with the page."
        )
    };
    // spam.json says which weight files the model has (a base-only model has no residual
    // transformer), so it comes first.
    let config_bytes = fetch(&format!("{base}/spam.json"))
        .await
        .map_err(not_here)?;
    let sizes: SpamConfig = serde_json::from_slice(&config_bytes)
        .map_err(|e| format!("spam.json on this server is not a model's sizes: {e}"))?;
    let names: Vec<&str> = sizes.weight_files()[1..]
        .iter()
        .copied()
        .chain(TEXT_FILES)
        .collect();
    let total = (names.len() + 1 + EVALUATOR_FILES.len() + 1) as u64;
    let mut done = 1u64;
    let mut bytes = config_bytes.len() as u64;
    let mut download = async |name: &str| {
        post(&Reply::Progress {
            stage: format!("downloading the model: {name}"),
            done,
            total,
        });
        done += 1;
        let data = fetch(&format!("{base}/{name}")).await?;
        bytes += data.len() as u64;
        Ok::<_, String>(data)
    };
    let mut files = std::collections::HashMap::new();
    for name in names {
        files.insert(name, download(name).await?);
    }
    // Optional: a failure here costs the review or the LLM planner, not the page.
    let evaluator_files = [
        download(EVALUATOR_FILES[0]).await,
        download(EVALUATOR_FILES[1]).await,
    ];
    let vocabulary_file = download(VOCABULARY_FILE).await;
    post(&Reply::Progress {
        stage: "preparing the model".into(),
        done: total,
        total,
    });
    let file = |name: &str| files.get(name).map(Vec::as_slice).unwrap_or_default();
    let text = |name: &str| {
        std::str::from_utf8(file(name)).map_err(|_| format!("{name} is not UTF-8 text"))
    };
    let config = std::str::from_utf8(&config_bytes)
        .map_err(|_| "spam.json is not UTF-8 text".to_string())?;
    let (device, backend, note) = choose_device(asked).await;
    // The sentence encoder and the evaluator stay on the CPU: they answer synchronous calls
    // of the planner and the reviewer, and are quick there.
    let cpu = burn::tensor::Device::flex();
    let model = MotionModel::from_files(
        &SpamFiles {
            config,
            vq: file("vq.bpk"),
            base: file("base.bpk"),
            residual: files.get(RESIDUAL_FILE).map(Vec::as_slice),
            mean: file("mean.npy"),
            std: file("std.npy"),
        },
        &TextFiles {
            vocab: text(VOCAB_FILE)?,
            words: file(WORDS_FILE),
            model: file(MODEL_FILE),
        },
        &device,
        &cpu,
    )
    .map_err(|e| format!("the model does not load: {e}"))?;
    let mut missing = Vec::new();
    let evaluator = match evaluator_files {
        [Ok(config), Ok(weights)] => std::str::from_utf8(&config)
            .map_err(|_| "evaluator.json is not UTF-8 text".to_string())
            .and_then(|config| {
                Evaluator::from_bytes(config, &weights, &cpu).map_err(|e| e.to_string())
            }),
        [config, weights] => Err(config.err().or(weights.err()).unwrap_or_default()),
    };
    let evaluator = match evaluator {
        Ok(evaluator) => Some(evaluator),
        Err(e) => {
            missing.push(format!("the evaluator ({e}): motions are not reviewed"));
            None
        }
    };
    let vocabulary = vocabulary_file.and_then(|data| {
        serde_json::from_slice::<Vocabulary>(&data)
            .map_err(|e| format!("{VOCABULARY_FILE} does not read: {e}"))
    });
    let vocabulary = match vocabulary {
        Ok(vocabulary) => Some(vocabulary),
        Err(e) => {
            missing.push(format!(
                "the model's vocabulary ({e}): the built-in planner plans even with an LLM set"
            ));
            None
        }
    };
    let model_id = model.id.clone();
    MODELS.with(|m| {
        *m.borrow_mut() = Some(Rc::new(Models {
            model,
            evaluator,
            vocabulary,
        }))
    });
    Ok(Reply::Loaded {
        model_id,
        backend,
        note,
        bytes,
        millis: now() - started,
        missing,
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

/// Tokens from a link or the page must fit the model: 4 parts, the same number of layers in
/// each (1 to the VQ-VAE's; a base-only model makes 1, and the decoder takes any prefix),
/// codes of its codebook and a length it can decode.
fn check_tokens(model: &MotionModel, tokens: &MotionTokens) -> Result<(), String> {
    let most = model.spam.vq_config.layers;
    let layers = tokens.first().map_or(0, Vec::len);
    let codes = model.spam.vq_config.codebook_size as u32;
    let steps = tokens.first().and_then(|p| p.first()).map_or(0, Vec::len);
    let fits = tokens.len() == 4
        && (1..=most).contains(&layers)
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
            "these tokens do not fit the loaded model (4 parts × 1 to {most} layers of codes below {codes} expected)"
        ))
    }
}

/// The motion of `tokens`, with the paths of `plan` (JSON) laid on its root where it reads
/// as a plan; the notes say which paths could not be laid.
async fn motion(
    model: &MotionModel,
    tokens: MotionTokens,
    plan: Option<&str>,
) -> (Motion, Vec<String>) {
    let plan = plan.and_then(|p| planning::parse_plan(p).ok());
    let (features, notes) = match &plan {
        Some(plan) => pipeline::motion_features(model, plan, &tokens).await,
        None => (model.features(&tokens).await, Vec::new()),
    };
    let joints = coma::features::features_to_joints(&features)
        .iter()
        .map(|p| p.map(|j| j.map(|v| v as f32)))
        .collect();
    let motion = Motion {
        tokens,
        joints,
        features: features.iter().map(|f| f.to_vec()).collect(),
    };
    (motion, notes)
}

fn models() -> Result<Rc<Models>, String> {
    MODELS
        .with(|m| m.borrow().clone())
        .ok_or("the model is not loaded yet".to_string())
}

async fn answer(request: Request) -> Result<Reply, String> {
    match request {
        Request::Load { base, backend } => load(&base, backend).await,
        Request::Run {
            prompt,
            seed,
            rounds,
            seconds,
            llm,
            plan,
        } => {
            let models = models()?;
            run(&models, &prompt, seed, rounds, seconds, llm, plan).await
        }
        other => {
            let models = models()?;
            edit(&models.model, other).await
        }
    }
}

/// The LLM client for `settings`, or why there is none.
fn llm_client(settings: LlmSettings) -> Result<LlmClient<FetchTransport>, String> {
    let mut config =
        LlmConfig::new(settings.base_url, settings.model).with_api_key(settings.api_key);
    config.vision_model = (!settings.vision_model.is_empty()).then_some(settings.vision_model);
    LlmClient::new(config, FetchTransport).map_err(|e| e.to_string())
}

/// A Run: plan (or take the given plan), then the whole loop, posting every step.
async fn run(
    models: &Models,
    prompt: &str,
    seed: u64,
    rounds: usize,
    seconds: Option<f64>,
    llm: Option<LlmSettings>,
    given: Option<String>,
) -> Result<Reply, String> {
    let started = now();
    if prompt.trim().is_empty() && given.is_none() {
        return Err("type what the person should do first".into());
    }
    let model = &models.model;
    // Steps so far; a Cell, since the planner's and the pipeline's callbacks both count.
    let done = Cell::new(0u64);
    let step = |line: String, total: u64| {
        done.set(done.get() + 1);
        post(&Reply::Step {
            line,
            done: done.get(),
            total: total.max(done.get()),
        });
    };
    let mut notes = Vec::new();
    let client = match llm.map(llm_client) {
        Some(Ok(client)) => Some(client),
        Some(Err(e)) => {
            notes.push(format!(
                "the LLM is not used ({e}); the built-in planner planned"
            ));
            None
        }
        None => None,
    };
    let embed_fn = |s: &str| model.text.encode(&[s])[0].to_vec();
    let embed: Embedder = &embed_fn;
    let mut plan: Plan = match (given, &client, &models.vocabulary) {
        (Some(json), _, _) => planning::parse_plan(&json)?,
        (None, Some(client), Some(vocabulary)) => {
            step(format!("planning with {}…", client.config().model), 1);
            planner::llm::plan(client, prompt, vocabulary, Some(embed), &mut |event| {
                step(planning::plan_event_line(event), 0)
            })
            .await
        }
        (None, client, _) => {
            if client.is_some() {
                notes.push(
                    "the model's vocabulary did not load, so the built-in planner planned".into(),
                );
            }
            planner::offline::plan(prompt, Some(embed))
        }
    };
    if let Some(seconds) = seconds {
        planning::fit_seconds(&mut plan, seconds);
    }
    if done.get() == 0 {
        // Planned in one go (the built-in planner, or a given plan): its steps, as fitted.
        for event in planning::plan_events(&plan) {
            step(planning::plan_event_line(&event), 0);
        }
    }
    post(&Reply::Plan {
        plan: serde_json::to_string(&plan).map_err(|e| e.to_string())?,
    });
    let total = done.get() + planning::run_steps(&plan, rounds);
    let scorer = models.evaluator.as_ref().map(|(evaluator, config)| Scorer {
        evaluator,
        config,
        model,
    });
    let run = pipeline::run(
        model,
        scorer.as_ref(),
        client.as_ref(),
        plan,
        RunOptions { rounds, seed },
        &mut |event| step(pipeline::describe_event(&event), total),
    )
    .await;
    let (motion, path_notes) = motion(
        model,
        run.tokens.clone(),
        serde_json::to_string(&run.plan).ok().as_deref(),
    )
    .await;
    let scores: Vec<SegmentScores> = planning::scores(&run);
    notes.extend(run.plan.notes.iter().cloned());
    notes.extend(run.notes.iter().cloned());
    notes.extend(path_notes);
    Ok(Reply::Run {
        motion,
        plan: serde_json::to_string(&run.plan).map_err(|e| e.to_string())?,
        history: run.history,
        notes,
        scores,
        millis: now() - started,
    })
}

/// The requests that make or change tokens without the agents.
async fn edit(model: &MotionModel, request: Request) -> Result<Reply, String> {
    let started = now();
    let (tokens, plan) = match request {
        Request::Load { .. } | Request::Run { .. } => {
            return Err("this request is not an edit".into())
        }
        Request::Generate {
            prompt,
            seconds,
            seed,
            parts,
        } => {
            let parts = parts
                .iter()
                .map(|(name, text)| Ok((parse_parts(std::slice::from_ref(name))?[0], text.clone())))
                .collect::<Result<Vec<_>, String>>()?;
            if prompt.trim().is_empty() {
                return Err("type what the person should do first".into());
            }
            (
                model
                    .generate(&prompt, &parts, frames_for_seconds(seconds), seed)
                    .await,
                None,
            )
        }
        Request::InBetween {
            tokens,
            text,
            from,
            to,
            seed,
            plan,
        } => {
            check_tokens(model, &tokens)?;
            let frames = tokens[0][0].len() * 4;
            if from >= to || from >= frames {
                return Err(format!(
                    "choose a time range inside the motion (0 to {:.1} s)",
                    frames as f64 / 20.0
                ));
            }
            (
                model
                    .inbetween(&tokens, &text, from, to.min(frames), seed)
                    .await,
                plan,
            )
        }
        Request::EditParts {
            tokens,
            text,
            parts,
            seed,
            plan,
        } => {
            check_tokens(model, &tokens)?;
            let parts = parse_parts(&parts)?;
            if parts.is_empty() {
                return Err("choose at least one body part to edit".into());
            }
            let rest = coma::posecodes::describe_motion(&model.joints(&tokens).await);
            (
                model.edit_parts(&tokens, &text, &parts, &rest, seed).await,
                plan,
            )
        }
        Request::Decode { tokens, plan } => {
            check_tokens(model, &tokens)?;
            (tokens, plan)
        }
    };
    let (motion, notes) = motion(model, tokens, plan.as_deref()).await;
    Ok(Reply::Motion {
        motion,
        millis: now() - started,
        notes,
    })
}
