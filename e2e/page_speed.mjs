// Times generation in the page served at a URL: node page_speed.mjs URL LABEL. Three
// 196-frame walks without review (the first one cold) and two reviewed ones, in headless
// Chromium without software WebGPU (the CPU backend, as on a machine without a GPU). Run by
// scripts/page_speed.sh, which alternates builds of the page so they share the machine's load.
import { chromium } from "playwright-core";
import { PLAIN_ARGS, modelLoaded, timeGenerations } from "./page_driver.mjs";

const [url, label] = process.argv.slice(2);
const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", args: PLAIN_ARGS });
try {
  const page = await browser.newPage();
  await page.goto(url);
  await modelLoaded(page);
  const { plain, reviewed } = await timeGenerations(page);
  console.log(`${label}: without review ${plain.join(", ")} s (first cold); reviewed (2 rounds) ${reviewed.join(", ")} s`);
} finally {
  await browser.close();
}
