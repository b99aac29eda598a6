//! The About box: what the model is, what it was trained on, and the licences that come with
//! it (the default weights inherit CC BY-NC 4.0 from their training data).

use crate::app::AppState;
use leptos::prelude::*;

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
                        <strong>"Motion model weights: CC BY-NC 4.0. "</strong>
                        "They are trained on the Bandai Namco Research Motion Datasets 1 and 2 (Kobayashi et al. 2023, "
                        "\"Motion Capture Dataset for Practical Use of AI-based Motion Editing and Stylization\"), "
                        "licensed CC BY-NC 4.0: the weights and the motions they generate are for non-commercial use, with attribution."
                    </li>
                    <li>"Sentence encoder: all-MiniLM-L6-v2, Apache-2.0."</li>
                    <li>"Code: MIT or Apache-2.0."</li>
                </ul>
                <p>
                    "Output: a 22-joint SMPL skeleton at 20 fps, 1 to 9.8 s per generation. The model knows walking, running, "
                    "waving and raising hands, bowing, kicking, punching and a few styles; see MODEL_CARD.md for its limits."
                </p>
            </div>
        </details>
    }
}
