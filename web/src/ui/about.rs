//! The About box: what the model is, what it was trained on, and the licences that come with
//! it (the default weights inherit CC BY-NC 4.0 from their training data, and the terms of
//! every other source listed in the model's `vocabulary.json`).

use crate::app::AppState;
use leptos::prelude::*;

/// The credit for the data every default model is trained on, shown when the model's list of
/// sources did not load.
const BANDAI_NAMCO: &str =
    "CC BY-NC 4.0: Bandai Namco Research Motion Datasets 1 and 2 (Kobayashi et al. 2023, \
     \"Motion Capture Dataset for Practical Use of AI-based Motion Editing and Stylization\").";

#[component]
pub fn About() -> impl IntoView {
    let state = expect_context::<AppState>();
    let model_line = move || {
        state.model.with(|m| match m {
            None => "The model is loading.".to_string(),
            Some(m) => {
                format!(
                    "Model {} ({:.1} MB), running on {}.",
                    m.id,
                    m.bytes as f64 / 1e6,
                    m.runs_on()
                ) + &m
                    .missing
                    .iter()
                    .map(|n| format!(" Not loaded: {n}."))
                    .collect::<String>()
            }
        })
    };
    // The model's vocabulary.json lists its data; without it, the data every model has.
    let training_data = move || {
        let listed = state.model.with(|m| {
            m.as_ref()
                .map(|m| m.training_data.values().cloned().collect::<Vec<_>>())
                .unwrap_or_default()
        });
        if listed.is_empty() {
            return view! { <li>{BANDAI_NAMCO}</li> }.into_any();
        }
        listed
            .into_iter()
            .map(|terms| {
                view! {
                    <li>
                        <strong>{terms.licence}": "</strong>
                        {terms.attribution}
                    </li>
                }
            })
            .collect_view()
            .into_any()
    };
    view! {
        <details class="about">
            <summary>"About"</summary>
            <div class="about-body">
                <p>
                    "Type a motion prompt; the page generates a 3D human motion with SPAM, a body-part-aware "
                    "residual VQ-VAE and masked transformers, entirely in this browser. A built-in planner cuts the "
                    "prompt into segments and body-part edits and an evaluator reviews the result, so nothing is sent "
                    "anywhere unless you set an LLM endpoint under Settings."
                </p>
                <p id="model-line">{model_line}</p>
                <h3>"Licences"</h3>
                <ul>
                    <li>
                        <strong>"Motion model weights: non-commercial use, with attribution. "</strong>
                        "They inherit the terms of the motion data they were trained on (below): the Bandai Namco "
                        "Research Motion Datasets' CC BY-NC 4.0 makes the weights and the motions they generate "
                        "non-commercial; where HDM05 (CC BY-SA 3.0) is listed, what is adapted from it is shared "
                        "under the same licence."
                    </li>
                    <li>
                        "Training data:"
                        <ul id="training-data">{training_data}</ul>
                    </li>
                    <li>"Sentence encoder: all-MiniLM-L6-v2, Apache-2.0."</li>
                    <li>"Code: MIT or Apache-2.0."</li>
                </ul>
                <p>
                    "Output: a 22-joint SMPL skeleton at 20 fps, 1 to 9.8 s per generation. The model knows walking, running, "
                    "waving and raising hands, bowing, punching and a few styles of walking, and, less finely, squats, jumps, "
                    "kicks, throws and the other actions of its smaller sources; see MODEL_CARD.md for its limits."
                </p>
            </div>
        </details>
    }
}
