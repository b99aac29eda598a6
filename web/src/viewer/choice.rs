//! Which renderer draws the 3D view: WebGPU where the browser has it, else WebGL2 (wgpu's GL
//! backend), else Canvas 2D, which every browser has; `?renderer=webgpu|webgl2|2d` puts one
//! first. Plain data, tested natively; the viewer tries the renderers in this order and falls
//! to the next when one cannot start or loses its device.

/// One way of drawing the view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RendererKind {
    WebGpu,
    WebGl2,
    Canvas2d,
}

impl RendererKind {
    /// Every renderer, the most capable first: the order the viewer falls through.
    pub const ALL: [RendererKind; 3] = [
        RendererKind::WebGpu,
        RendererKind::WebGl2,
        RendererKind::Canvas2d,
    ];

    /// The name the page shows ("View: WebGL2").
    pub fn name(self) -> &'static str {
        match self {
            RendererKind::WebGpu => "WebGPU",
            RendererKind::WebGl2 => "WebGL2",
            RendererKind::Canvas2d => "Canvas 2D",
        }
    }

    /// The query string's word for it, also the `data-renderer` attribute's value.
    pub fn key(self) -> &'static str {
        match self {
            RendererKind::WebGpu => "webgpu",
            RendererKind::WebGl2 => "webgl2",
            RendererKind::Canvas2d => "2d",
        }
    }
}

/// The renderers to try, in order, and what to tell the user about the choice, if anything.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RendererChoice {
    pub order: Vec<RendererKind>,
    pub note: Option<String>,
}

/// The renderers to try for the query string's `renderer` value (`asked`, if the address has
/// one) in a browser that does or does not offer WebGPU (`has_webgpu`): the asked one first,
/// then the ones after it in [`RendererKind::ALL`]; with nothing asked, WebGPU only where the
/// browser has it. An unknown value is named in the note and the usual order is kept.
pub fn renderer_order(asked: Option<&str>, has_webgpu: bool) -> RendererChoice {
    let usual = |note: Option<String>| RendererChoice {
        order: RendererKind::ALL
            .into_iter()
            .filter(|k| has_webgpu || *k != RendererKind::WebGpu)
            .collect(),
        note,
    };
    let Some(asked) = asked.map(str::trim).filter(|a| !a.is_empty()) else {
        return usual(None);
    };
    match RendererKind::ALL
        .iter()
        .position(|k| k.key().eq_ignore_ascii_case(asked))
    {
        Some(i) => RendererChoice {
            order: RendererKind::ALL[i..].to_vec(),
            note: None,
        },
        None => usual(Some(format!(
            "the address asks for renderer '{}', which this page does not know (webgpu, webgl2 or 2d); it chose one itself",
            asked.chars().take(40).collect::<String>()
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::RendererKind::*;
    use super::*;

    #[test]
    fn without_a_query_the_best_renderer_the_browser_has_comes_first() {
        assert_eq!(
            renderer_order(None, true).order,
            vec![WebGpu, WebGl2, Canvas2d]
        );
        assert_eq!(renderer_order(None, false).order, vec![WebGl2, Canvas2d]);
        assert_eq!(renderer_order(Some(""), false).note, None);
    }

    #[test]
    fn the_query_puts_its_renderer_first_and_keeps_the_fallbacks_after_it() {
        assert_eq!(renderer_order(Some("2d"), true).order, vec![Canvas2d]);
        assert_eq!(
            renderer_order(Some("webgl2"), true).order,
            vec![WebGl2, Canvas2d]
        );
        // Asked for WebGPU where the browser shows none: it is tried (and says why it fails).
        assert_eq!(
            renderer_order(Some("WebGPU"), false).order,
            vec![WebGpu, WebGl2, Canvas2d]
        );
    }

    #[test]
    fn an_unknown_renderer_is_named_and_the_usual_order_kept() {
        let choice = renderer_order(Some("vulkan"), false);
        assert_eq!(choice.order, vec![WebGl2, Canvas2d]);
        assert!(choice.note.unwrap().contains("'vulkan'"));
        let long = "x".repeat(500);
        assert!(renderer_order(Some(&long), true).note.unwrap().len() < 200);
    }
}
