//! The guidance partner: a second worker holding SPAM's transformers, so the CPU backend uses
//! two cores. Wasm threads would need cross-origin isolation and a second build of the page
//! without WebGPU (wgpu's browser types cannot be shared between threads); two workers need
//! neither. At each unmasking step the engine's worker sends the tokens here and computes the
//! conditional pass while this worker computes the unconditional one (see
//! `coma::model::guidance`). Should the partner fail, the engine runs the pass itself.
//!
//! Messages are plain JS objects with typed arrays (the logits are 200 K floats a step; as
//! JSON they would cost more than they save), built and read only by [`ToPartner`] and
//! [`FromPartner`].

use crate::deadline::within;
use coma::model::guidance::{GuidancePartner, PartnerReply, Pass};
use coma::model::Spam;
use js_sys::{Array, Float32Array, Function, Int32Array, Object, Promise, Reflect, Uint8Array};
use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::rc::Rc;
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;
use web_sys::{
    DedicatedWorkerGlobalScope, ErrorEvent, MessageEvent, Worker, WorkerOptions, WorkerType,
};

/// What the engine's worker sends the partner.
enum ToPartner<'a> {
    /// The transformers' files: `spam.json`, `base.bpk`, `residual.bpk` (absent for a
    /// base-only model).
    Load {
        config: &'a str,
        base: &'a [u8],
        residual: Option<&'a [u8]>,
    },
    /// An unconditional pass; the answer carries the same `id`.
    Pass { id: u32, pass: Pass },
}

/// What the partner answers.
enum FromPartner {
    /// Its handler is installed: messages sent before this would be lost.
    Ready,
    Loaded,
    Logits {
        id: u32,
        values: Float32Array,
    },
    /// A pass failed (`id`), or loading did (`None`: every pass will).
    Failed {
        id: Option<u32>,
        message: String,
    },
}

fn set(object: &Object, key: &str, value: &JsValue) {
    // Setting a plain property on a fresh object cannot fail.
    let _ = Reflect::set(object, &key.into(), value);
}

fn get(object: &JsValue, key: &str) -> JsValue {
    Reflect::get(object, &key.into()).unwrap_or(JsValue::UNDEFINED)
}

fn number(object: &JsValue, key: &str) -> Option<u32> {
    get(object, key).as_f64().map(|v| v as u32)
}

impl ToPartner<'_> {
    fn to_js(&self) -> JsValue {
        let o = Object::new();
        match self {
            ToPartner::Load {
                config,
                base,
                residual,
            } => {
                set(&o, "kind", &"load".into());
                set(&o, "config", &(*config).into());
                set(&o, "base", &Uint8Array::from(*base).into());
                if let Some(residual) = residual {
                    set(&o, "residual", &Uint8Array::from(*residual).into());
                }
            }
            ToPartner::Pass { id, pass } => {
                set(&o, "kind", &"pass".into());
                set(&o, "id", &(*id).into());
                set(&o, "layer", &(pass.layer as u32).into());
                set(&o, "steps", &(pass.steps as u32).into());
                set(
                    &o,
                    "tokens",
                    &Int32Array::from(pass.tokens.as_slice()).into(),
                );
            }
        }
        o.into()
    }
}

/// The partner's side of [`ToPartner`], owning its bytes.
enum Received {
    Load {
        config: String,
        base: Vec<u8>,
        residual: Option<Vec<u8>>,
    },
    Pass {
        id: u32,
        pass: Pass,
    },
}

impl Received {
    fn from_js(data: &JsValue) -> Result<Received, String> {
        let bytes = |key| {
            get(data, key)
                .dyn_into::<Uint8Array>()
                .ok()
                .map(|a| a.to_vec())
        };
        match get(data, "kind").as_string().as_deref() {
            Some("load") => Ok(Received::Load {
                config: get(data, "config").as_string().ok_or("no spam.json")?,
                base: bytes("base").ok_or("no base.bpk")?,
                residual: bytes("residual"),
            }),
            Some("pass") => Ok(Received::Pass {
                id: number(data, "id").ok_or("a pass without an id")?,
                pass: Pass {
                    layer: number(data, "layer").ok_or("a pass without a layer")? as usize,
                    steps: number(data, "steps").ok_or("a pass without steps")? as usize,
                    tokens: get(data, "tokens")
                        .dyn_into::<Int32Array>()
                        .map_err(|_| "a pass without tokens")?
                        .to_vec(),
                },
            }),
            _ => Err("a message the partner does not know".into()),
        }
    }
}

impl FromPartner {
    fn to_js(&self) -> JsValue {
        let o = Object::new();
        match self {
            FromPartner::Ready => set(&o, "kind", &"ready".into()),
            FromPartner::Loaded => set(&o, "kind", &"loaded".into()),
            FromPartner::Logits { id, values } => {
                set(&o, "kind", &"logits".into());
                set(&o, "id", &(*id).into());
                set(&o, "values", values);
            }
            FromPartner::Failed { id, message } => {
                set(&o, "kind", &"failed".into());
                if let Some(id) = id {
                    set(&o, "id", &(*id).into());
                }
                set(&o, "message", &message.as_str().into());
            }
        }
        o.into()
    }

    fn from_js(data: &JsValue) -> Result<FromPartner, String> {
        match get(data, "kind").as_string().as_deref() {
            Some("ready") => Ok(FromPartner::Ready),
            Some("loaded") => Ok(FromPartner::Loaded),
            Some("logits") => Ok(FromPartner::Logits {
                id: number(data, "id").ok_or("logits without an id")?,
                values: get(data, "values")
                    .dyn_into::<Float32Array>()
                    .map_err(|_| "logits without values")?,
            }),
            Some("failed") => Ok(FromPartner::Failed {
                id: number(data, "id"),
                message: get(data, "message").as_string().unwrap_or_default(),
            }),
            _ => Err("an answer the engine does not know".into()),
        }
    }
}

/// How long a pass may take the partner before the engine runs it itself and stops sending
/// it passes: a pass takes a fraction of a second, and a partner that crashed without an
/// error event (out of memory, a trap inside a promise) would otherwise stall generation for
/// good.
const REPLY_WAIT_MS: u32 = 10_000;

/// Promises of passes in flight, by id: their resolve and reject functions.
type Pending = Rc<RefCell<HashMap<u32, (Function, Function)>>>;

/// Where the partner is. Passes go to it only once it has loaded: before its handler is
/// installed a message would be lost, and until it has the weights the engine is faster alone.
enum State {
    /// Started; holds the load message until the partner says it is ready.
    Starting(Option<JsValue>),
    Loading,
    Loaded,
    /// It can no longer help, and why.
    Broken(String),
}

/// The engine's handle on the partner worker.
pub struct PartnerWorker {
    worker: Worker,
    pending: Pending,
    next_id: Cell<u32>,
    state: Rc<RefCell<State>>,
    _on_message: Closure<dyn FnMut(MessageEvent)>,
    _on_error: Closure<dyn FnMut(ErrorEvent)>,
}

impl std::fmt::Debug for PartnerWorker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PartnerWorker")
            .field("in_flight", &self.pending.borrow().len())
            .field("loaded", &matches!(*self.state.borrow(), State::Loaded))
            .finish()
    }
}

/// Rejects every pass in flight with `message` and refuses the next ones.
fn give_up(pending: &Pending, state: &RefCell<State>, message: String) {
    web_sys::console::warn_1(&format!("the guidance partner stopped: {message}").into());
    for (_, (_, reject)) in pending.borrow_mut().drain() {
        let _ = reject.call1(&JsValue::NULL, &message.as_str().into());
    }
    *state.borrow_mut() = State::Broken(message);
}

impl PartnerWorker {
    /// Starts the partner (`static/worker.js` in its partner role, with our compiled module)
    /// and sends it the transformers' files; it loads them while the engine loads the rest.
    pub fn spawn(
        config: &str,
        base: &[u8],
        residual: Option<&[u8]>,
    ) -> Result<PartnerWorker, String> {
        let options = WorkerOptions::new();
        options.set_type(WorkerType::Module);
        // Relative to this worker's script, static/worker.js: the same script.
        let worker = Worker::new_with_options("worker.js", &options)
            .map_err(|e| format!("cannot start a second worker: {e:?}"))?;
        let pending: Pending = Rc::default();
        let load = ToPartner::Load {
            config,
            base,
            residual,
        };
        let state = Rc::new(RefCell::new(State::Starting(Some(load.to_js()))));
        let (p, st, w) = (pending.clone(), state.clone(), worker.clone());
        let on_message = Closure::<dyn FnMut(MessageEvent)>::new(move |event: MessageEvent| {
            match FromPartner::from_js(&event.data()) {
                Ok(FromPartner::Ready) => {
                    let load = match &mut *st.borrow_mut() {
                        State::Starting(load) => load.take(),
                        _ => None,
                    };
                    if let Some(load) = load {
                        match w.post_message(&load) {
                            Ok(()) => *st.borrow_mut() = State::Loading,
                            Err(e) => give_up(&p, &st, format!("{e:?}")),
                        }
                    }
                }
                Ok(FromPartner::Loaded) => *st.borrow_mut() = State::Loaded,
                Ok(FromPartner::Logits { id, values }) => {
                    if let Some((resolve, _)) = p.borrow_mut().remove(&id) {
                        let _ = resolve.call1(&JsValue::NULL, &values);
                    }
                }
                Ok(FromPartner::Failed {
                    id: Some(id),
                    message,
                }) => {
                    if let Some((_, reject)) = p.borrow_mut().remove(&id) {
                        let _ = reject.call1(&JsValue::NULL, &message.into());
                    }
                }
                Ok(FromPartner::Failed { id: None, message }) => give_up(&p, &st, message),
                Err(message) => give_up(&p, &st, message),
            }
        });
        let (p, st) = (pending.clone(), state.clone());
        let on_error = Closure::<dyn FnMut(ErrorEvent)>::new(move |event: ErrorEvent| {
            give_up(&p, &st, event.message());
        });
        worker.set_onmessage(Some(on_message.as_ref().unchecked_ref()));
        worker.set_onerror(Some(on_error.as_ref().unchecked_ref()));
        let role = Array::of2(&wasm_bindgen::module(), &"partner".into());
        worker
            .post_message(&role)
            .map_err(|e| format!("cannot hand the second worker its code: {e:?}"))?;
        Ok(PartnerWorker {
            worker,
            pending,
            next_id: Cell::new(0),
            state,
            _on_message: on_message,
            _on_error: on_error,
        })
    }
}

impl Drop for PartnerWorker {
    fn drop(&mut self) {
        self.worker.terminate();
    }
}

impl GuidancePartner for PartnerWorker {
    fn unconditional(&self, pass: &Pass) -> PartnerReply {
        let not_yet = match &*self.state.borrow() {
            State::Loaded => None,
            State::Broken(why) => Some(why.clone()),
            State::Starting(_) | State::Loading => Some("the partner is still loading".into()),
        };
        if let Some(why) = not_yet {
            return Box::pin(std::future::ready(Err(why)));
        }
        let id = self.next_id.get();
        self.next_id.set(id.wrapping_add(1));
        let pending = self.pending.clone();
        let promise = Promise::new(&mut |resolve, reject| {
            pending.borrow_mut().insert(id, (resolve, reject));
        });
        let sent = self.worker.post_message(
            &ToPartner::Pass {
                id,
                pass: pass.clone(),
            }
            .to_js(),
        );
        if let Err(e) = sent {
            self.pending.borrow_mut().remove(&id);
            return Box::pin(std::future::ready(Err(format!("{e:?}"))));
        }
        let (pending, state) = (self.pending.clone(), self.state.clone());
        Box::pin(async move {
            let answer = within(REPLY_WAIT_MS, wasm_bindgen_futures::JsFuture::from(promise));
            let Some(answer) = answer.await else {
                let why = format!("no answer to a pass within {} s", REPLY_WAIT_MS / 1000);
                give_up(&pending, &state, why.clone());
                return Err(why);
            };
            let values = answer.map_err(|e| e.as_string().unwrap_or_else(|| format!("{e:?}")))?;
            Ok(values
                .dyn_into::<Float32Array>()
                .map_err(|_| "the partner answered without logits".to_string())?
                .to_vec())
        })
    }
}

thread_local! {
    /// The partner's transformers, once loaded.
    static TRANSFORMERS: RefCell<Option<Rc<Spam>>> = const { RefCell::new(None) };
}

fn answer(reply: &FromPartner) {
    let scope: DedicatedWorkerGlobalScope = js_sys::global().unchecked_into();
    let _ = scope.post_message(&reply.to_js());
}

/// The partner's side: answers [`ToPartner`] messages until the engine's worker ends it.
pub fn serve() {
    let scope: DedicatedWorkerGlobalScope = js_sys::global().unchecked_into();
    let handler = Closure::<dyn FnMut(MessageEvent)>::new(|event: MessageEvent| {
        match Received::from_js(&event.data()) {
            Ok(Received::Load {
                config,
                base,
                residual,
            }) => {
                let device = burn::tensor::Device::flex();
                let reply = match Spam::transformers_from_bytes(
                    &config,
                    &base,
                    residual.as_deref(),
                    &device,
                ) {
                    Ok(spam) => {
                        TRANSFORMERS.with(|t| *t.borrow_mut() = Some(Rc::new(spam)));
                        FromPartner::Loaded
                    }
                    Err(e) => FromPartner::Failed {
                        id: None,
                        message: e.to_string(),
                    },
                };
                answer(&reply);
            }
            Ok(Received::Pass { id, pass }) => {
                let Some(spam) = TRANSFORMERS.with(|t| t.borrow().clone()) else {
                    return answer(&FromPartner::Failed {
                        id: Some(id),
                        message: "the partner has no model".into(),
                    });
                };
                wasm_bindgen_futures::spawn_local(async move {
                    answer(&match spam.unconditional_logits(&pass).await {
                        Ok(values) => FromPartner::Logits {
                            id,
                            values: Float32Array::from(values.as_slice()),
                        },
                        Err(message) => FromPartner::Failed {
                            id: Some(id),
                            message,
                        },
                    });
                });
            }
            Err(message) => answer(&FromPartner::Failed { id: None, message }),
        }
    });
    scope.set_onmessage(Some(handler.as_ref().unchecked_ref()));
    handler.forget();
    answer(&FromPartner::Ready);
}
