// Loads the page's wasm module; a failure is shown instead of a blank page.
import init from "../pkg/coma_web.js";

init().catch((err) => {
  const status = document.getElementById("status");
  if (status) status.textContent = "The page could not start: " + err;
});
