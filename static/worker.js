// The inference worker (see web/src/worker.rs), or its guidance partner (web/src/partner.rs):
// the page's own wasm module, run off the UI thread. The first message is the compiled
// WebAssembly.Module (the page's, or for the partner [module, "partner"] from the inference
// worker), so the wasm is downloaded and compiled once per page load.
import init, { worker_main, partner_main } from "../pkg/coma_web.js";

self.addEventListener(
  "message",
  (event) => {
    const [module, role] = Array.isArray(event.data) ? event.data : [event.data, "engine"];
    const module_or_path =
      module instanceof WebAssembly.Module ? module : new URL("../pkg/coma_web_bg.wasm", import.meta.url);
    init({ module_or_path })
      .then(() => (role === "partner" ? partner_main() : worker_main()))
      .catch((err) => {
        // A rejected promise would not reach the page's onerror; a thrown error does, and
        // the page then says the worker stopped instead of waiting for it forever.
        setTimeout(() => {
          throw err;
        });
      });
  },
  { once: true },
);
