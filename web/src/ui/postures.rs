//! The named-posture picker: a searchable list of the library's postures (T-pose, squat, dab,
//! …); the chosen one is held on the ticked body parts (none ticked: the parts the posture is
//! about) over the timeline's time range. The take's tokens are decoded again with a plan
//! whose segment holds the posture, so nothing is regenerated, the result is a new take (undo
//! goes back) and its share link rebuilds it.

use crate::app::AppState;
use crate::take::with_posture;
use coma::posture::library::Library;
use coma::skeleton::BodyPart;
use coma::timing::FPS;
use leptos::prelude::*;

/// Most postures the list shows at once.
const SHOWN: usize = 80;

/// The names of the parts, joined for a sentence ("left arm, right arm").
fn part_names(parts: &[BodyPart]) -> String {
    if parts.len() == BodyPart::ALL.len() {
        return "whole body".into();
    }
    parts
        .iter()
        .map(|p| p.name())
        .collect::<Vec<_>>()
        .join(", ")
}

#[component]
pub fn PosturePicker(
    from: RwSignal<f64>,
    to: RwSignal<f64>,
    parts: RwSignal<[bool; 4]>,
) -> impl IntoView {
    let state = expect_context::<AppState>();
    let library = Library::builtin();
    let query = RwSignal::new(String::new());
    let chosen = RwSignal::new(None::<String>);
    let has_take = move || state.history.with(|h| h.current().is_some());
    let matches = move || {
        query.with(|q| {
            library
                .search(q)
                .into_iter()
                .take(SHOWN)
                .map(|p| {
                    let about = format!(
                        "{}{}",
                        part_names(&p.parts),
                        if p.synonyms.is_empty() {
                            String::new()
                        } else {
                            format!("; also: {}", p.synonyms.join(", "))
                        }
                    );
                    (p.name.clone(), about)
                })
                .collect::<Vec<_>>()
        })
    };
    let apply = move |_| {
        let Some(take) = state.take() else { return };
        let Some(name) = chosen.get_untracked() else {
            return state.fail("Choose a posture from the list first.");
        };
        let Some(posture) = library.get(&name) else {
            return state.fail(format!("There is no posture named {name}."));
        };
        let (a, b) = (from.get_untracked(), to.get_untracked());
        // NaN or a backward range: nowhere to hold the posture.
        if a.partial_cmp(&b) != Some(std::cmp::Ordering::Less) {
            return state.fail("The range must start before it ends.");
        }
        // To the nearest frame: the range is typed in tenths of a second.
        let (a, b) = ((a * FPS).round() as usize, (b * FPS).round() as usize);
        let ticked = parts.get_untracked();
        let chosen_parts: Vec<BodyPart> = if ticked.contains(&true) {
            BodyPart::ALL
                .iter()
                .zip(ticked)
                .filter(|(_, t)| *t)
                .map(|(p, _)| *p)
                .collect()
        } else {
            posture.parts.clone()
        };
        match with_posture(&take, &posture.script, chosen_parts.clone(), a, b) {
            Err(e) => state.fail(e),
            Ok(edit) => {
                let mut line = format!(
                    "{} held on the {} from {:.1} to {:.1} s",
                    posture.name,
                    part_names(&chosen_parts),
                    edit.from as f64 / FPS,
                    edit.to as f64 / FPS
                );
                if edit.cut {
                    line.push_str(&format!(
                        " (cut at the end of segment {})",
                        edit.segment + 1
                    ));
                }
                if edit.replaced {
                    line.push_str(&format!(
                        "; it replaces the key poses segment {} had",
                        edit.segment + 1
                    ));
                }
                state.say(format!("laying the posture: {line}…"));
                state.decode_with_plan(&take, edit.plan, line, None);
            }
        }
    };
    view! {
        <details class="postures-picker">
            <summary id="postures-summary">"Named postures"</summary>
            <p class="hint">
                "Held on the ticked body parts (none ticked: the parts the posture is about) from "
                "the range's start to its end, within the segment where it starts."
            </p>
            <input
                id="posture-search"
                type="search"
                placeholder="Find a posture, e.g. T-pose, squat, salute"
                aria-label="Find a posture"
                prop:value=move || query.get()
                on:input=move |ev| query.set(event_target_value(&ev))
            />
            <ul id="posture-list" class="posture-list" aria-label="Named postures">
                {move || {
                    let found = matches();
                    if found.is_empty() {
                        return view! { <li class="none">"No posture has those words."</li> }
                            .into_any();
                    }
                    found
                        .into_iter()
                        .map(|(name, about)| {
                            let pick = name.clone();
                            let mine = name.clone();
                            let data = name.clone();
                            view! {
                                <li>
                                    <button
                                        class="posture-choice small"
                                        data-name=data
                                        title=about
                                        aria-pressed=move || {
                                            (chosen.with(|c| c.as_deref() == Some(mine.as_str())))
                                                .to_string()
                                        }
                                        on:click=move |_| chosen.set(Some(pick.clone()))
                                    >
                                        {name}
                                    </button>
                                </li>
                            }
                        })
                        .collect_view()
                        .into_any()
                }}
            </ul>
            <div class="row">
                <span class="chosen-posture">
                    {move || match chosen.get() {
                        Some(name) => format!("Chosen: {name}"),
                        None => "Choose a posture above.".to_string(),
                    }}
                </span>
                <button
                    id="apply-posture"
                    on:click=apply
                    disabled=move || state.busy() || !has_take() || chosen.with(Option::is_none)
                >
                    "Hold posture"
                </button>
            </div>
        </details>
    }
}
