//! The inference worker: a dedicated Web Worker running the same wasm module, which loads the
//! models into the engine ([`Session`]) and hands it the page's commands, so generating never
//! freezes the page. It only translates: JSON in, the engine's typed command, the engine's
//! progress and outcome back as [`Reply`] JSON; a failed request answers with an error and
//! leaves the models as they were.

use crate::deadline::within;
use crate::llm_fetch::FetchTransport;
use crate::messages::{from_json, to_json, Backend, LlmSettings, Reply, Request};
use crate::partner::PartnerWorker;
use coma::agents::llm::LlmClient;
use coma::model::evaluator::Evaluator;
use coma::model::guidance::GuidancePartner;
use coma::model::motion_model::TextFiles;
use coma::model::{
    model_id_from_digest, MotionModel, SpamConfig, SpamFiles, PRIOR_FILE, RESIDUAL_FILE,
};
use coma::session::{Command, Session, VOCABULARY_FILE};
use coma::text::minilm::{MODEL_FILE, VOCAB_FILE, WORDS_FILE};
use futures::future::join_all;
use std::cell::{Cell, RefCell};
use std::rc::Rc;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::{DedicatedWorkerGlobalScope, MessageEvent};

/// The sentence encoder's files, fetched after SPAM's.
const TEXT_FILES: [&str; 3] = [VOCAB_FILE, WORDS_FILE, MODEL_FILE];

/// The agents' files, fetched after the model: the page works without them, with less.
const EVALUATOR_FILES: [&str; 2] = ["evaluator.json", "evaluator.bpk"];

thread_local! {
    // Shared out as an Rc so a request can hold the engine across the awaits of an LLM call.
    static SESSION: RefCell<Option<Rc<Session>>> = const { RefCell::new(None) };
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

/// How long the browser may take to offer a WebGPU adapter, and then to open the device,
/// before the model goes to the CPU: a GPU answers in about a second, and a GPU process that
/// is busy (other tabs rendering on a software adapter) or wedged may never answer.
const WEBGPU_WAIT_MS: u32 = 8_000;

/// The device SPAM runs on: WebGPU where the browser has a hardware adapter (or where it is
/// asked for), else the CPU backend, with the reason.
async fn choose_device(asked: Option<Backend>) -> (burn::tensor::Device, Backend, Option<String>) {
    let cpu = |why: String| (burn::tensor::Device::flex(), Backend::Cpu, Some(why));
    if asked == Some(Backend::Cpu) {
        return cpu("the page asked for the CPU backend (?backend=cpu)".into());
    }
    let silent = || {
        format!(
            "the browser's WebGPU did not answer within {} s, so the model runs on the CPU",
            WEBGPU_WAIT_MS / 1000
        )
    };
    match within(WEBGPU_WAIT_MS, webgpu_adapter()).await {
        None => cpu(silent()),
        Some(None) => {
            cpu("this browser offers no WebGPU adapter, so the model runs on the CPU".into())
        }
        Some(Some(true)) if asked != Some(Backend::WebGpu) => cpu(
            "the browser's only WebGPU adapter is a software one, slower than the CPU backend, \
             so the model runs on the CPU (?backend=webgpu uses it anyway)"
                .into(),
        ),
        Some(Some(_)) => {
            let device = burn::tensor::Device::wgpu_options().init_async();
            match within(WEBGPU_WAIT_MS, device).await {
                Some(Ok(device)) => (device, Backend::WebGpu, None),
                Some(Err(e)) => cpu(format!(
                    "WebGPU did not start ({e}), so the model runs on the CPU"
                )),
                None => cpu(silent()),
            }
        }
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
    let done = Cell::new(1u64);
    let bytes = Cell::new(config_bytes.len() as u64);
    // Every file is asked for at once, and the device chosen meanwhile: a repeat visit's
    // files come from the browser's cache after one revalidation each, so waiting for them one
    // by one and then for the WebGPU adapter would be most of its start.
    let download = async |name: &str| {
        let data = fetch(&format!("{base}/{name}")).await?;
        done.set(done.get() + 1);
        bytes.set(bytes.get() + data.len() as u64);
        post(&Reply::Loading {
            stage: format!("downloading the model: {name} received"),
            done: done.get(),
            total,
        });
        Ok::<_, String>(data)
    };
    // The evaluator and the vocabulary are optional: a failure there costs the review or the
    // LLM planner, not the page.
    let (model_files, evaluator_config, evaluator_weights, vocabulary_file, chosen) = futures::join!(
        join_all(names.iter().map(|&name| download(name))),
        download(EVALUATOR_FILES[0]),
        download(EVALUATOR_FILES[1]),
        download(VOCABULARY_FILE),
        choose_device(asked),
    );
    let (device, backend, mut note) = chosen;
    let mut files = std::collections::HashMap::new();
    for (name, data) in names.into_iter().zip(model_files) {
        files.insert(name, data?);
    }
    post(&Reply::Loading {
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
    // On the CPU a second worker runs guidance's unconditional passes (see partner.rs); it
    // loads its copy of the transformers while this one loads the rest.
    let partner = match backend {
        Backend::WebGpu => None,
        Backend::Cpu if cores() < 2 => {
            note = Some(join_notes(note, "one worker: the browser reports one core"));
            None
        }
        Backend::Cpu => match PartnerWorker::spawn(
            config,
            file("base.bpk"),
            files.get(RESIDUAL_FILE).map(Vec::as_slice),
        ) {
            Ok(partner) => Some(Rc::new(partner)),
            Err(e) => {
                note = Some(join_notes(note, &format!("one worker: {e}")));
                None
            }
        },
    };
    // The sentence encoder and the evaluator stay on the CPU: they answer synchronous calls
    // of the planner and the reviewer, and are quick there.
    let cpu = burn::tensor::Device::flex();
    let spam_files = SpamFiles {
        config,
        vq: file("vq.bpk"),
        base: file("base.bpk"),
        residual: files.get(RESIDUAL_FILE).map(Vec::as_slice),
        mean: file("mean.npy"),
        std: file("std.npy"),
        prior: files.get(PRIOR_FILE).map(Vec::as_slice),
    };
    let mut model = MotionModel::from_files_hashed(
        &spam_files,
        &TextFiles {
            vocab: text(VOCAB_FILE)?,
            words: file(WORDS_FILE),
            model: file(MODEL_FILE),
        },
        model_id(&spam_files),
        &device,
        &cpu,
    )
    .await
    .map_err(|e| format!("the model does not load: {e}"))?;
    let workers = 1 + partner.is_some() as u32;
    model.spam.partner = partner.map(|p| p as Rc<dyn GuidancePartner>);
    let evaluator = match [evaluator_config, evaluator_weights] {
        [Ok(config), Ok(weights)] => std::str::from_utf8(&config)
            .map_err(|_| "evaluator.json is not UTF-8 text".to_string())
            .and_then(|config| {
                Evaluator::from_bytes(config, &weights, &cpu).map_err(|e| e.to_string())
            }),
        [config, weights] => Err(config.err().or(weights.err()).unwrap_or_default()),
    };
    let vocabulary = vocabulary_file.and_then(|data| {
        serde_json::from_slice(&data).map_err(|e| format!("{VOCABULARY_FILE} does not read: {e}"))
    });
    let model_id = model.id.clone();
    let training_data = vocabulary
        .as_ref()
        .map(|v: &coma::dataset::Vocabulary| v.sources.clone())
        .unwrap_or_default();
    let (session, missing) = Session::new(model, evaluator, vocabulary);
    SESSION.with(|s| *s.borrow_mut() = Some(Rc::new(session)));
    Ok(Reply::Loaded {
        model_id,
        backend,
        note,
        workers,
        bytes: bytes.get(),
        millis: now() - started,
        missing,
        training_data,
    })
}

/// The model id of `files` (see [`coma::model::model_id`]), hashed by the browser's SHA-256
/// (WebCrypto, on its own threads, many times faster than one compiled to wasm), which starts
/// at once; the wasm's own where the browser offers none (a page not from a secure origin).
fn model_id<'a>(files: &'a SpamFiles<'a>) -> impl std::future::Future<Output = String> + 'a {
    let digest = js_sys::Reflect::get(&scope(), &"crypto".into())
        .ok()
        .and_then(|crypto| crypto.dyn_into::<web_sys::Crypto>().ok())
        .and_then(|crypto| {
            crypto
                .subtle()
                .digest_with_str_and_u8_array("SHA-256", &files.id_message())
                .ok()
        })
        .map(wasm_bindgen_futures::JsFuture::from);
    async move {
        if let Some(digest) = digest {
            if let Ok(buffer) = digest.await {
                return model_id_from_digest(&js_sys::Uint8Array::new(&buffer).to_vec());
            }
        }
        files.id()
    }
}

/// Logical cores the browser reports (`navigator.hardwareConcurrency`; 1 if it does not say).
fn cores() -> u32 {
    js_sys::Reflect::get(&scope(), &"navigator".into())
        .and_then(|n| js_sys::Reflect::get(&n, &"hardwareConcurrency".into()))
        .ok()
        .and_then(|c| c.as_f64())
        .map_or(1, |c| c as u32)
}

fn join_notes(note: Option<String>, more: &str) -> String {
    match note {
        Some(note) => format!("{note}; {more}"),
        None => more.to_string(),
    }
}

fn session() -> Result<Rc<Session>, String> {
    SESSION
        .with(|s| s.borrow().clone())
        .ok_or("the model is not loaded yet".to_string())
}

async fn answer(request: Request) -> Result<Reply, String> {
    match request {
        Request::Load { base, backend } => load(&base, backend).await,
        Request::Execute { command, llm } => execute(*command, llm).await,
    }
}

/// Hands a command to the engine, posting its progress as it comes.
async fn execute(command: Command, llm: Option<LlmSettings>) -> Result<Reply, String> {
    let session = session()?;
    let client = |config| LlmClient::new(config, FetchTransport).map_err(|e| e.to_string());
    Ok(crate::dispatch::execute(
        &session,
        command,
        llm,
        client,
        &mut |reply| post(&reply),
        &now,
    )
    .await)
}
