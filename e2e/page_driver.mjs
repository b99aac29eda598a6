// Drives the page in headless Chromium: what the e2e tests (page.test.mjs) and the speed
// comparison (page_speed.mjs) share.

/** Longest wait for the model to load or a generation to finish (`LOAD_TIMEOUT_S` seconds,
 * 600 unless set: shorter when chasing a hang). */
export const LOAD_TIMEOUT = Number(process.env.LOAD_TIMEOUT_S ?? 600) * 1000;

// Software WebGPU (SwiftShader) for compute and canvas (ANGLE on SwiftShader too, or the
// compositor shows WebGPU canvases blank in screenshots), and no calls out of the machine.
export const ARGS = [
  "--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu-sandbox",
  "--enable-unsafe-webgpu", "--enable-features=Vulkan", "--use-vulkan=swiftshader", "--use-angle=swiftshader",
  "--disable-background-networking", "--disable-component-update", "--disable-sync",
  "--no-first-run", "--disable-quic",
];

// Chromium without the software WebGPU the other tests force: as on a machine without a GPU,
// the page then runs on the CPU backend and draws with its 2D renderer, and SwiftShader does
// not render the playing motion on the same two cores while the model generates.
export const PLAIN_ARGS = ARGS.filter((a) => !/webgpu|vulkan|angle/i.test(a));

/** Waits until the model has loaded and Generate can be pressed. */
export async function modelLoaded(page) {
  await page.waitForFunction(() => {
    const b = document.querySelector("#generate");
    return b && !b.disabled;
  }, null, { timeout: LOAD_TIMEOUT });
}

/** The joints hash of the motion the page shows ("" for none). */
export async function jointsHash(page) {
  return (await page.locator(".viewer").getAttribute("data-joints-hash")) ?? "";
}

/** Fills the prompt box with `prompt`, `seconds` ("" for the plan's own length) and `seed`,
 * no review round. */
export async function fillPrompt(page, prompt, seconds, seed) {
  await page.fill("#prompt", prompt);
  await page.fill("#seconds", seconds);
  await page.locator("#seconds").dispatchEvent("change");
  await page.selectOption("#rounds", "0");
  await page.fill("#seed", String(seed));
  await page.locator("#seed").dispatchEvent("change");
}

/** Presses Generate and waits until the page shows a new motion and is idle again. */
export async function generateNew(page) {
  const before = await jointsHash(page);
  await page.click("#generate");
  await page.waitForFunction((h) => {
    const v = document.querySelector(".viewer");
    return v?.dataset.jointsHash && v.dataset.jointsHash !== h && !document.querySelector("#generate").disabled;
  }, before, { timeout: LOAD_TIMEOUT });
}

/** Times, on the page as it is, three 196-frame generations of "a person walks forward"
 * without review (the first one cold) and two with two review rounds; seconds, as text. */
export async function timeGenerations(page) {
  const timed = async (seed, rounds) => {
    await fillPrompt(page, "a person walks forward", "9.8", seed);
    await page.selectOption("#rounds", rounds);
    const started = Date.now();
    await generateNew(page);
    const frames = Number(await page.locator(".viewer").getAttribute("data-frames"));
    if (Math.abs(frames - 196) > 4) throw new Error(`asked 196 frames, got ${frames}`);
    return ((Date.now() - started) / 1000).toFixed(2);
  };
  const plain = [];
  for (const seed of [1, 2, 3]) plain.push(await timed(seed, "0"));
  const reviewed = [];
  for (const seed of [4, 5]) reviewed.push(await timed(seed, "2"));
  return { plain, reviewed };
}
