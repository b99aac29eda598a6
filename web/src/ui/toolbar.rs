//! The toolbar: the share link (the page's own address, which holds the motion) and the
//! downloads.

use crate::app::AppState;
use crate::exports::{export, Format};
use leptos::prelude::*;

#[component]
pub fn Toolbar() -> impl IntoView {
    let state = expect_context::<AppState>();
    let link = RwSignal::new(String::new());
    let has_take = move || state.history.with(|h| h.current().is_some());
    let copy = move |_| {
        let url = crate::browser::href();
        link.set(url.clone());
        leptos::task::spawn_local(async move {
            match crate::browser::copy_text(&url).await {
                Ok(()) => {
                    state.say("The share link is copied: it rebuilds this motion, with no server.")
                }
                Err(e) => state.say(format!("Copy the share link from the box ({e}).")),
            }
        });
    };
    let download = move |format: Format| {
        let Some(take) = state.take() else { return };
        match export(&take, format)
            .and_then(|bytes| crate::browser::download(&bytes, format.file_name(), format.mime()))
        {
            Ok(()) => state.say(format!("Downloaded {}.", format.file_name())),
            Err(e) => state.fail(e),
        }
    };
    view! {
        <div class="panel toolbar">
            <div class="row">
                <button id="share" on:click=copy disabled=move || !has_take()>
                    "Copy share link"
                </button>
                <input
                    id="share-link"
                    type="text"
                    readonly
                    aria-label="Share link"
                    prop:value=move || link.get()
                />
            </div>
            <div class="row">
                "Download: "
                {Format::ALL
                    .iter()
                    .map(|f| {
                        let f = *f;
                        view! {
                            <button
                                class="export"
                                data-format=f.file_name()
                                on:click=move |_| download(f)
                                disabled=move || !has_take()
                            >
                                {f.label()}
                            </button>
                        }
                    })
                    .collect_view()}
            </div>
        </div>
    }
}
