// The inference worker: the page's own wasm module, run off the UI thread (see web/src/worker.rs).
import init, { worker_main } from "../pkg/coma_web.js";

await init({ module_or_path: new URL("../pkg/coma_web_bg.wasm", import.meta.url) });
worker_main();
