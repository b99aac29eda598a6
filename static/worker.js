// The inference worker: the page's own wasm module, run off the UI thread (see web/src/worker.rs).
// The page posts its compiled WebAssembly.Module as the first message, so the wasm is
// downloaded and compiled once per page load rather than once by the page and once here.
import init, { worker_main } from "../pkg/coma_web.js";

self.addEventListener(
  "message",
  (event) => {
    const module_or_path =
      event.data instanceof WebAssembly.Module
        ? event.data
        : new URL("../pkg/coma_web_bg.wasm", import.meta.url);
    init({ module_or_path })
      .then(() => worker_main())
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
