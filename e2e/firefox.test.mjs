// The core end-to-end test in a second browser engine: Debian's Firefox ESR, driven over
// WebDriver BiDi by puppeteer-core. It loads the page, generates a motion with no LLM (the
// built-in planner; Firefox has no WebGPU adapter here, so the model runs on the CPU backend),
// copies the share link and opens it in a fresh browser context, which must rebuild the same
// joints. Console errors and warnings and uncaught errors of the pages and their workers fail it.
//
// Needs: the built page in DIST (default ../dist), the coma binary in COMA (serves the page),
// Firefox in FIREFOX (default /usr/bin/firefox-esr). Never downloads a browser.
import { test } from "node:test";
import assert from "node:assert/strict";
import { spawn } from "node:child_process";
import { join, resolve } from "node:path";
import puppeteer from "puppeteer-core";
import { LOAD_TIMEOUT } from "./page_driver.mjs";

const here = new URL(".", import.meta.url).pathname;
const DIST = resolve(process.env.DIST ?? join(here, "../dist"));
const COMA = process.env.COMA ?? "coma";
const FIREFOX = process.env.FIREFOX ?? "/usr/bin/firefox-esr";
// Not page.test.mjs's port, so a server it left behind cannot answer for this one.
const PORT = Number(process.env.FIREFOX_PORT ?? 8098);
const BASE = `http://127.0.0.1:${PORT}/`;

// On top of puppeteer's own test profile (no updates, no safe browsing, no first-run pages):
// nothing else Firefox does on its own leaves the machine. Telemetry, the captive portal and
// connectivity checks, remote settings and DNS prefetching stay off, and every proxied request
// goes to a closed local port, so anything still trying fails here instead of reaching out
// (127.0.0.1 itself is never proxied).
const PREFS = {
  "toolkit.telemetry.enabled": false,
  "toolkit.telemetry.unified": false,
  "toolkit.telemetry.server": "",
  "datareporting.healthreport.uploadEnabled": false,
  "datareporting.policy.dataSubmissionEnabled": false,
  "app.update.auto": false,
  "app.update.enabled": false,
  "app.normandy.enabled": false,
  "network.captive-portal-service.enabled": false,
  "network.connectivity-service.enabled": false,
  "network.dns.disablePrefetch": true,
  "network.prefetch-next": false,
  "network.predictor.enabled": false,
  "browser.safebrowsing.provider.mozilla.updateURL": "",
  "services.settings.server": "http://127.0.0.1:9/",
  "browser.ping-centre.telemetry": false,
  "extensions.getAddons.cache.enabled": false,
  "network.proxy.type": 1,
  "network.proxy.http": "127.0.0.1",
  "network.proxy.http_port": 9,
  "network.proxy.ssl": "127.0.0.1",
  "network.proxy.ssl_port": 9,
  "network.proxy.no_proxies_on": "127.0.0.1",
};

/** Starts `coma serve` on PORT. */
function serve() {
  return spawn(COMA, ["serve", DIST, "--port", String(PORT)], { stdio: "inherit" });
}

/** Stops the server and waits until it has exited. */
async function stop(server) {
  if (server.exitCode !== null || server.signalCode !== null) return;
  const exited = new Promise((r) => server.once("exit", r));
  server.kill();
  await exited;
}

async function waitForServer(server) {
  for (let i = 0; i < 100; i++) {
    if (server.exitCode !== null) throw new Error(`${COMA} serve exited with ${server.exitCode}`);
    try {
      if ((await fetch(BASE)).ok) return;
    } catch {}
    await new Promise((r) => setTimeout(r, 100));
  }
  throw new Error(`the page server did not start on ${BASE}`);
}

/** Opens `url` in a new tab of `context`, recording console lines (the workers' too), console
 * errors, uncaught errors and requests that leave 127.0.0.1:PORT. */
async function open(context, url) {
  const page = await context.newPage();
  await page.setViewport({ width: 1280, height: 800 });
  const problems = [];
  const outside = [];
  const log = [];
  const keep = (line) => { log.push(line); if (log.length > 200) log.shift(); };
  // Warnings count too: the page warns only when something stopped working (the guidance
  // partner worker, for one), and Firefox itself says nothing on this page today. Firefox
  // reports the workers' console lines as the page's (with the worker listener kept for
  // browsers that report them on the worker).
  const bad = (type) => type === "error" || type === "warn" || type === "warning";
  page.on("console", (m) => {
    keep(`${m.type()}: ${m.text()}`);
    if (bad(m.type())) problems.push(`console ${m.type()}: ${m.text()}`);
  });
  // An uncaught error (Firefox reports the workers' as the page's) ends any wait at once.
  let crash;
  const crashed = new Promise((_, reject) => { crash = reject; });
  crashed.catch(() => {});
  page.on("pageerror", (e) => {
    keep(`uncaught: ${e.message}`);
    problems.push(`uncaught: ${e.message}`);
    crash(new Error(`uncaught error: ${e.message}`));
  });
  page.on("workercreated", (w) => {
    keep(`worker started: ${w.url()}`);
    w.on("console", (m) => {
      keep(`worker ${m.type()}: ${m.text()}`);
      if (bad(m.type())) problems.push(`worker console ${m.type()}: ${m.text()}`);
    });
  });
  // data: URLs load nothing from anywhere (Firefox reports the page's `data:,` icon and a font
  // it decodes from a data: URL as requests; Chromium does not), so they are not "out".
  page.on("request", (req) => {
    const url = req.url();
    if (!url.startsWith(BASE) && !url.startsWith("data:")) outside.push(url);
  });
  await page.goto(url);
  return { page, problems, outside, log, crashed };
}

/** What the page shows, for failure messages: its status, joints hash and console. */
async function describe(opened) {
  const seen = await opened.page.evaluate(() => ({
    status: document.querySelector("#status")?.textContent,
    // The stage of a long step ("downloading the model: base.bpk received"), which says
    // where a load that never ends stopped.
    progress: document.querySelector(".status .progress")?.textContent,
    hash: document.querySelector(".viewer")?.dataset.jointsHash,
    busy: document.querySelector("#generate")?.disabled,
    viewer: document.querySelector(".viewer-problem")?.textContent,
  })).catch((why) => ({ unreadable: String(why) }));
  return `the page shows ${JSON.stringify(seen)}\nconsole:\n${opened.log.slice(-40).join("\n")}`;
}

/** Waits until `check` (run in the page with `arg`) holds; on a timeout or an uncaught error
 * the error says what the page shows and what its console said. Polls on an interval: a tab
 * in the background gets no animation frames. */
async function until(opened, what, check, arg) {
  const waiting = opened.page.waitForFunction(check, { timeout: LOAD_TIMEOUT, polling: 200 }, arg);
  waiting.catch(() => {});
  try {
    await Promise.race([waiting, opened.crashed]);
  } catch (e) {
    throw new Error(`waiting for ${what}: ${e.message}\n${await describe(opened)}`);
  }
}

const idle = () => {
  const b = document.querySelector("#generate");
  return b !== null && !b.disabled;
};

test("in Firefox, the page generates a motion and its share link rebuilds the same joints", { timeout: 30 * 60_000 }, async () => {
  const server = serve();
  let browser;
  try {
    await waitForServer(server);
    // A fresh temporary profile (puppeteer's, removed on close), headless, over WebDriver BiDi.
    browser = await puppeteer.launch({
      browser: "firefox",
      executablePath: FIREFOX,
      headless: true,
      extraPrefsFirefox: PREFS,
      // A wait is one WebDriver BiDi command that returns when its condition holds, and
      // puppeteer ends any command after `protocolTimeout` (180 s unless set), so the waits'
      // own LOAD_TIMEOUT only holds with a longer one.
      protocolTimeout: LOAD_TIMEOUT + 60_000,
    });
    const version = await browser.version();
    console.log(`browser: ${version} (${FIREFOX})`);

    const loadStarted = Date.now();
    const first = await open(browser.defaultBrowserContext(), BASE);
    const { page } = first;
    await until(first, "the model to load", idle);
    const status = await page.$eval("#status", (e) => e.textContent);
    const modelLine = await page.$eval("#model-line", (e) => e.textContent).catch(() => "");
    console.log(`loaded in ${((Date.now() - loadStarted) / 1000).toFixed(1)} s: ${modelLine || status}`);
    assert.match(status, /loaded .* on (WebGPU|the CPU)/, await describe(first));

    // A 196-frame walk, no review round, typed as a user would.
    await page.locator("#prompt").fill("a person walks forward");
    await page.locator("#seconds").fill("9.8");
    await page.$eval("#seconds", (e) => e.dispatchEvent(new Event("change", { bubbles: true })));
    await page.select("#rounds", "0");
    await page.locator("#seed").fill("1");
    await page.$eval("#seed", (e) => e.dispatchEvent(new Event("change", { bubbles: true })));
    const before = await page.$eval(".viewer", (v) => v.dataset.jointsHash ?? "");
    const started = Date.now();
    await page.click("#generate");
    await until(first, "a generated motion", (h) => {
      const v = document.querySelector(".viewer");
      return !!v?.dataset.jointsHash && v.dataset.jointsHash !== h && !document.querySelector("#generate").disabled;
    }, before);
    const seconds = (Date.now() - started) / 1000;
    const frames = Number(await page.$eval(".viewer", (v) => v.dataset.frames));
    const hash = await page.$eval(".viewer", (v) => v.dataset.jointsHash);
    const said = await page.$eval("#status", (e) => e.textContent);
    console.log(`generated ${frames} frames in ${seconds.toFixed(1)} s in Firefox (${said})`);
    assert.ok(Math.abs(frames - 196) <= 4, `asked 196 frames, got ${frames}`);
    assert.match(hash, /^[0-9a-f]{16}$/);

    // Share: the button puts the page's own address, with the motion in its fragment, in the
    // link box (and on the clipboard, which headless Firefox may refuse: the page then says so).
    await page.click("#share");
    await until(first, "the share link", () => document.querySelector("#share-link")?.value.includes("#m="));
    const link = await page.$eval("#share-link", (e) => e.value);
    assert.equal(link, await page.evaluate(() => location.href), "the share link is not the page's address");
    assert.ok(link.startsWith(BASE), link);
    console.log(`share link: ${link.length} characters; ${await page.$eval("#status", (e) => e.textContent)}`);

    // The link in a fresh browser context (nothing shared with the first tab) rebuilds it.
    const other = await browser.createBrowserContext();
    const second = await open(other, link);
    await until(second, "the shared motion", () => !!document.querySelector(".viewer")?.dataset.jointsHash
      && !document.querySelector("#generate").disabled);
    const rebuilt = await second.page.$eval(".viewer", (v) => v.dataset.jointsHash);
    assert.equal(rebuilt, hash, `the share link rebuilt other joints\n${await describe(second)}`);

    for (const p of [first, second]) {
      assert.deepEqual(p.problems, [], `errors or warnings in Firefox's console\n${await describe(p)}`);
      assert.deepEqual(p.outside, [], "the page sent something out");
      const error = await p.page.$eval("#status", (e) => e.classList.contains("error"));
      assert.ok(!error, `the page shows an error\n${await describe(p)}`);
    }
  } finally {
    await browser?.close();
    await stop(server);
  }
});
