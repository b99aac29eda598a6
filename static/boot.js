// Loads the page's wasm module; a failure is shown instead of a blank page.
import init from "../pkg/coma_web.js";

init({ module_or_path: new URL("../pkg/coma_web_bg.wasm", import.meta.url) }).catch((err) => {
  const p = document.createElement("p");
  p.setAttribute("role", "alert");
  p.textContent = "The page could not start: " + err;
  document.body.prepend(p);
});
