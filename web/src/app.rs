//! The page: shared state in context, the worker's replies turned into state, and the layout
//! of the components (prompt, steps, viewer, timeline, toolbar, settings, about).

use crate::client::Client;
use crate::history::History;
use crate::messages::{Backend, LlmSettings, Reply, Request};
use crate::take::{plan_from_link, Take};
use crate::ui::{
    about::About, prompt::PromptBox, settings::Settings, status::StatusBar, steps::Steps,
    timeline::Timeline, toolbar::Toolbar, viewer::Viewer,
};
use coma::plan::Plan;
use coma::session::{Command, Outcome, Progress, RunOutcome};
use coma::share::{self, Edit};
use leptos::prelude::*;

/// Undo keeps this many states.
const HISTORY_LIMIT: usize = 100;

/// The loaded model as the worker described it.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelInfo {
    pub id: String,
    pub backend: Backend,
    pub note: Option<String>,
    /// Workers generating (2 with the guidance partner on the CPU backend).
    pub workers: u32,
    pub bytes: u64,
    pub millis: f64,
    /// What did not load, and what the page does without it.
    pub missing: Vec<String>,
    /// The motion data behind the weights, per source, and the terms they pass on.
    pub training_data: std::collections::BTreeMap<String, coma::dataset::DataTerms>,
}

impl ModelInfo {
    /// Where the model runs, for the user: "WebGPU", "the CPU (2 workers)", with the reason
    /// when it is not WebGPU or not two workers.
    pub fn runs_on(&self) -> String {
        match (self.backend, &self.note) {
            (Backend::WebGpu, _) => "WebGPU".to_string(),
            (Backend::Cpu, note) => format!(
                "the CPU ({} worker{}{})",
                self.workers,
                if self.workers == 1 { "" } else { "s" },
                note.as_ref().map_or(String::new(), |n| format!("; {n}"))
            ),
        }
    }
}

/// A line for the user: what happened, or what went wrong and what to do.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Status {
    pub text: String,
    pub error: bool,
}

/// What a request in flight will become when its motion arrives.
#[derive(Clone, Debug, PartialEq)]
pub enum Pending {
    /// A new take from the prompt, by the whole pipeline.
    Run { prompt: String, seed: u64 },
    /// An edit of the current take.
    Edit(Edit),
    /// A take rebuilt from a share link.
    Link(share::SharedMotion),
    /// The current take's tokens decoded with a new plan (a named posture laid on it, a path
    /// drawn for a segment); `line` says what changed, `edit` is what the take's history
    /// records of it, if anything.
    Plan {
        plan: Plan,
        line: String,
        edit: Option<Edit>,
    },
}

/// State every component reads through context.
#[derive(Clone, Copy)]
pub struct AppState {
    pub status: RwSignal<Status>,
    pub progress: RwSignal<Option<(String, u64, u64)>>,
    pub model: RwSignal<Option<ModelInfo>>,
    pub history: RwSignal<History<Option<Take>>>,
    pub pending: RwSignal<Option<Pending>>,
    /// The playhead, in frames (fractional while playing).
    pub frame: RwSignal<f64>,
    pub playing: RwSignal<bool>,
    pub speed: RwSignal<f64>,
    /// Milliseconds the last generation took in the worker.
    pub generate_millis: RwSignal<Option<f64>>,
    /// A link made with another model, waiting for the user to regenerate it.
    pub foreign_link: RwSignal<Option<share::SharedMotion>>,
    /// The progress lines of the last run, one per planner or pipeline step.
    pub steps: RwSignal<Vec<String>>,
    /// The plan of the run in flight, shown on the timeline before its motion exists.
    pub preview: RwSignal<Option<Plan>>,
    /// The LLM endpoint of the Settings panel (empty: no LLM, nothing is sent anywhere).
    pub settings: RwSignal<LlmSettings>,
    pub client: StoredValue<Option<Client>, LocalStorage>,
    /// What the prompt box holds (a share link that opens fills it with its own).
    pub prompt: crate::ui::prompt::PromptFields,
    /// The renderer that draws the 3D view ("WebGL2") and why the ones before it did not
    /// ("WebGPU: no adapter"); None while none draws.
    pub view_renderer: RwSignal<Option<(String, String)>>,
}

impl AppState {
    /// The current take, if any.
    pub fn take(&self) -> Option<Take> {
        self.history.with(|h| h.current().clone())
    }

    pub fn busy(&self) -> bool {
        self.pending.with(Option::is_some)
    }

    pub fn say(&self, text: impl Into<String>) {
        self.status.set(Status {
            text: text.into(),
            error: false,
        });
    }

    pub fn fail(&self, text: impl Into<String>) {
        self.status.set(Status {
            text: text.into(),
            error: true,
        });
    }

    /// Decodes `take`'s tokens again with `plan` (a posture laid on it, a path drawn for a
    /// segment): a new take once the worker answers, `line` saying what changed and `edit`
    /// what its history records.
    pub fn decode_with_plan(&self, take: &Take, plan: Plan, line: String, edit: Option<Edit>) {
        self.request(
            Command::Decode {
                tokens: take.motion.tokens.clone(),
                plan: Some(plan.clone()),
            },
            None,
            Pending::Plan { plan, line, edit },
        );
    }

    /// Sends an engine command (with the LLM to use, if any) whose motion becomes `pending`;
    /// refused while another one runs.
    pub fn request(&self, command: Command, llm: Option<LlmSettings>, pending: Pending) {
        let request = Request::Execute {
            command: Box::new(command),
            llm,
        };
        if self.busy() {
            self.fail("wait for the current step to finish");
            return;
        }
        if self.model.with(Option::is_none) {
            self.fail("the model is still loading");
            return;
        }
        let sent = self.client.with_value(|c| match c {
            Some(c) => c.send(&request),
            None => Err("the model worker is not running".into()),
        });
        match sent {
            Ok(()) => {
                if matches!(pending, Pending::Run { .. }) {
                    self.steps.set(Vec::new());
                }
                self.pending.set(Some(pending));
                self.progress.set(Some(("working".into(), 0, 1)));
            }
            Err(e) => self.fail(e),
        }
    }

    /// Writes the current take into the URL fragment, so the address is the share link.
    pub fn publish(&self) {
        if let Some(link) = self.link() {
            crate::browser::set_fragment(&link);
        }
    }

    /// The current take's share link (the fragment, without `#`), if there is a take.
    fn link(&self) -> Option<String> {
        let (take, model) = (self.take()?, self.model.get_untracked()?);
        share::model_id_bytes(&model.id).map(|id| share::encode(&take.shared(id)))
    }
}

fn on_reply(state: AppState, reply: Reply) {
    match reply {
        Reply::Ready => {
            state.say("downloading the model…");
            let sent = state.client.with_value(|c| {
                c.as_ref().map(|c| {
                    c.send(&Request::Load {
                        base: crate::browser::absolute_url("static/models/"),
                        backend: crate::browser::query("backend").and_then(|b| match b.as_str() {
                            "cpu" => Some(Backend::Cpu),
                            "webgpu" => Some(Backend::WebGpu),
                            _ => None,
                        }),
                    })
                })
            });
            if let Some(Err(e)) = sent {
                state.fail(e);
            }
        }
        Reply::Loading { stage, done, total } => state.progress.set(Some((stage, done, total))),
        Reply::Loaded {
            model_id,
            backend,
            note,
            workers,
            bytes,
            millis,
            missing,
            training_data,
        } => {
            state.progress.set(None);
            let info = ModelInfo {
                id: model_id,
                backend,
                note,
                workers,
                bytes,
                millis,
                missing,
                training_data,
            };
            state.say(format!(
                "Model {} loaded ({:.1} MB in {:.1} s) on {}{}. Type a prompt and press Generate.",
                info.id,
                info.bytes as f64 / 1e6,
                info.millis / 1000.0,
                info.runs_on(),
                if info.missing.is_empty() {
                    String::new()
                } else {
                    format!("; not loaded: {}", info.missing.join("; "))
                }
            ));
            state.model.set(Some(info));
            open_link(state);
        }
        Reply::Progress {
            progress: Progress::Planned { plan },
        } => state.preview.set(Some(plan)),
        Reply::Progress {
            progress: Progress::Step { line, done, total },
        } => {
            state.progress.set(Some((line.clone(), done, total)));
            state.steps.update(|s| s.push(line));
        }
        Reply::Done {
            outcome: Outcome::Run(run),
            millis,
        } => on_run(state, *run, millis),
        Reply::Done {
            outcome: Outcome::Motion { motion, notes },
            millis,
        } => {
            state.progress.set(None);
            let pending = state.pending.get_untracked();
            state.pending.set(None);
            let what = match &pending {
                Some(Pending::Plan { line, .. }) => format!(": {line}"),
                _ => String::new(),
            };
            let take = match pending {
                Some(Pending::Edit(edit)) => match state.take() {
                    Some(mut take) => {
                        take.motion = motion;
                        take.edits.push(edit);
                        // The review scored the motion before this edit.
                        take.scores.clear();
                        take
                    }
                    None => return state.fail("there was no motion to edit"),
                },
                Some(Pending::Plan { plan, edit, .. }) => match state.take() {
                    Some(mut take) => {
                        take.segments = crate::take::plan_segments(&plan, motion.joints.len());
                        take.plan = Some(plan);
                        take.motion = motion;
                        take.edits.extend(edit);
                        // The review scored the motion before the change.
                        take.scores.clear();
                        take
                    }
                    None => return state.fail("there was no motion to change"),
                },
                Some(Pending::Link(link)) => {
                    let (plan, legacy) =
                        plan_from_link(&link.plan, &link.prompt, motion.joints.len());
                    let mut take =
                        Take::new(motion, link.prompt, link.seed, link.history, plan, legacy);
                    take.restore_record(link.record);
                    take.notes.extend(link.notes);
                    take
                }
                Some(Pending::Run { .. }) | None => return,
            };
            show(state, take);
            state.say(match notes.first() {
                None => format!("Done in {:.1} s{what}.", millis / 1000.0),
                Some(note) => format!("Done in {:.1} s{what}. Note: {note}", millis / 1000.0),
            });
        }
        // The page asks for no plan alone.
        Reply::Done {
            outcome: Outcome::Plan { .. },
            ..
        } => {
            state.progress.set(None);
            state.pending.set(None);
        }
        Reply::Error { message } => {
            state.progress.set(None);
            state.pending.set(None);
            state.preview.set(None);
            state.fail(message);
        }
    }
}

/// A run's motion becomes the new take, with its plan, steps, review scores and notes.
fn on_run(state: AppState, run: RunOutcome, millis: f64) {
    state.progress.set(None);
    state.preview.set(None);
    let Some(Pending::Run { prompt, seed }) = state.pending.get_untracked() else {
        state.pending.set(None);
        return;
    };
    state.pending.set(None);
    state.generate_millis.set(Some(millis));
    let scores = run.scores();
    let notes = run.all_notes();
    let mut take = Take::new(
        run.motion,
        prompt,
        seed,
        run.history,
        Some(run.plan),
        Vec::new(),
    );
    take.scores = scores;
    take.steps = state.steps.get_untracked();
    let summary = match notes.first() {
        None => format!("Done in {:.1} s.", millis / 1000.0),
        Some(first) => format!(
            "Done in {:.1} s. Note: {first}{}",
            millis / 1000.0,
            if notes.len() > 1 {
                format!(" (and {} more under Steps)", notes.len() - 1)
            } else {
                String::new()
            }
        ),
    };
    take.notes = notes;
    show(state, take);
    state.say(summary);
}

/// Makes `take` the current state (undoable), plays it and puts it in the address.
fn show(state: AppState, take: Take) {
    state.history.update(|h| h.push(Some(take)));
    state.frame.set(0.0);
    state.playing.set(true);
    state.publish();
}

/// Opens the share link in the URL, if there is one.
fn open_link(state: AppState) {
    open_fragment(state, &crate::browser::fragment());
}

/// Opens `fragment` (a URL fragment without `#`) if it is a share link.
fn open_fragment(state: AppState, fragment: &str) {
    if fragment.is_empty() {
        return;
    }
    match share::decode(fragment) {
        Err(share::LinkError::NotALink) => {}
        Err(e) => state.fail(format!("This link cannot be opened: {e}.")),
        Ok(link) => {
            // The prompt box shows what made the link, so Generate starts from it.
            state.prompt.fill(
                &link.prompt,
                coma::timing::seconds(link.tokens.frames()),
                link.seed,
            );
            let ours = state
                .model
                .with_untracked(|m| m.as_ref().map(|m| m.id.clone()))
                .unwrap_or_default();
            if share::model_id_hex(&link.model_id) != ours {
                state.fail(format!(
                    "This link was made with model {}, and this page has model {ours}: the motion cannot be rebuilt exactly. You can regenerate it from its prompt.",
                    share::model_id_hex(&link.model_id)
                ));
                state.foreign_link.set(Some(link));
            } else {
                state.say("opening the shared motion…");
                state.request(
                    Command::Decode {
                        tokens: link.tokens.clone(),
                        plan: link.plan.plan().cloned(),
                    },
                    None,
                    Pending::Link(link),
                );
            }
        }
    }
}

/// Opens a share link pasted into the address bar of this tab, where only the fragment
/// changes and the page does not reload, as [`open_link`] opens one at load. Before the model
/// has loaded, the load opens whatever link the address holds then. The page's own writes
/// (`publish`, by replaceState) fire no hashchange, and a link equal to the current take's is
/// not reopened. A link that comes while a request runs opens when that request is done.
fn watch_links(state: AppState) {
    let waiting = StoredValue::new(None::<String>);
    let watched = crate::browser::on_fragment_change(move || {
        let fragment = crate::browser::fragment();
        if state.model.with_untracked(Option::is_none)
            || matches!(share::decode(&fragment), Err(share::LinkError::NotALink))
            || state.link().as_deref() == Some(fragment.as_str())
        {
            return;
        }
        if state.busy() {
            waiting.set_value(Some(fragment));
            state.say("The pasted link opens when the current step is done.");
        } else {
            waiting.set_value(None);
            state.foreign_link.set(None);
            open_fragment(state, &fragment);
        }
    });
    if let Err(e) = watched {
        state.fail(e);
    }
    // Runs after the reply that ended the request is handled (its take shown and published).
    Effect::new(move |_| {
        if state.pending.with(Option::is_none) {
            if let Some(fragment) = waiting.try_update_value(Option::take).flatten() {
                untrack(|| {
                    state.foreign_link.set(None);
                    open_fragment(state, &fragment);
                });
            }
        }
    });
}

#[component]
pub fn App() -> impl IntoView {
    let state = AppState {
        status: RwSignal::new(Status {
            text: "starting…".into(),
            error: false,
        }),
        progress: RwSignal::new(None),
        model: RwSignal::new(None),
        history: RwSignal::new(History::new(None, HISTORY_LIMIT)),
        pending: RwSignal::new(None),
        frame: RwSignal::new(0.0),
        playing: RwSignal::new(false),
        speed: RwSignal::new(1.0),
        generate_millis: RwSignal::new(None),
        foreign_link: RwSignal::new(None),
        steps: RwSignal::new(Vec::new()),
        preview: RwSignal::new(None),
        settings: RwSignal::new(crate::ui::settings::stored()),
        client: StoredValue::new_local(None),
        prompt: crate::ui::prompt::PromptFields::default(),
        view_renderer: RwSignal::new(None),
    };
    provide_context(state);
    watch_links(state);
    match Client::spawn("./static/worker.js", move |reply| on_reply(state, reply)) {
        Ok(client) => state.client.set_value(Some(client)),
        Err(e) => state.fail(e),
    }
    view! {
        <header>
            <h1>"CoMA in the browser"</h1>
            <Settings/>
            <About/>
        </header>
        <main>
            <section class="left">
                <PromptBox/>
                <Steps/>
                <Timeline/>
                <Toolbar/>
            </section>
            <section class="right">
                <Viewer/>
            </section>
        </main>
        <StatusBar/>
    }
}
