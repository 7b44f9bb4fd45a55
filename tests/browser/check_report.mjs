// Opens a batch report (report.html) in headless Chromium (Debian's /usr/bin/chromium, driven by puppeteer-core),
// loads every avatar viewer and checks that each <model-viewer> loaded its model and draws something (not a blank
// canvas), that the page logged no console error and no request failed; saves a screenshot of the whole page.
// Usage: node check_report.mjs REPORT.html SCREENSHOT.png
// Prints one JSON object with the findings; exit code 0 when all is well, 1 otherwise, 2 on a usage/launch error.
import puppeteer from 'puppeteer-core';
import { existsSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { viewerPixels } from './viewer_pixels.mjs';

const [report, screenshot] = process.argv.slice(2);
if (!report || !screenshot) {
  console.error('usage: node check_report.mjs REPORT.html SCREENSHOT.png');
  process.exit(2);
}
const chromium = process.env.CHROMIUM || '/usr/bin/chromium';
if (!existsSync(chromium)) {
  console.error(`no browser at ${chromium} (install Debian's chromium, or set CHROMIUM)`);
  process.exit(2);
}

const findings = { viewers: 0, loaded: 0, blank: [], failedViewers: [], consoleErrors: [], failedRequests: [], pixels: {} };
const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  // No sandbox: the tests run as root in CI. WebGL through SwiftShader: there is no GPU.
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
         '--window-size=1400,1000'],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1400, height: 1000 });
  page.on('console', (msg) => { if (msg.type() === 'error') findings.consoleErrors.push(msg.text()); });
  page.on('pageerror', (err) => findings.consoleErrors.push(`page error: ${err.message}`));
  page.on('requestfailed', (req) => findings.failedRequests.push(`${req.url().slice(0, 200)}: ${req.failure()?.errorText}`));
  await page.goto(pathToFileURL(resolve(report)).href, { waitUntil: 'load' });
  findings.viewers = await page.$$eval('model-viewer', (all) => all.length);
  await page.evaluate(() => window.avatarboothLoadAll && window.avatarboothLoadAll());
  // Every viewer ends in data-state "loaded" or "error" (set by the report's own script from model-viewer's events).
  try {
    await page.waitForFunction(
      () => [...document.querySelectorAll('model-viewer')].every((el) => el.dataset.state === 'loaded' || el.dataset.state === 'error'),
      { timeout: 120000, polling: 250 });
  } catch (e) {
    findings.consoleErrors.push(`viewers still loading after 120 s: ${e.message}`);
  }
  const ids = await page.$$eval('model-viewer', (all) => all.map((el) => el.dataset.id));
  for (const id of ids) {
    const el = await page.evaluateHandle(
        (id) => document.querySelector(`model-viewer[data-id="${CSS.escape(id)}"]`), id);
    const loaded = await el.evaluate((v) => {
      if (v.dataset.state !== 'loaded' || !v.loaded) return false;
      v.scrollIntoView();
      return true;
    });
    const result = loaded ? { state: 'loaded', ...(await el.evaluate(viewerPixels)) }
                          : { state: await el.evaluate((v) => v.dataset.state) };
    await el.dispose();
    findings.pixels[id] = result;
    if (result.state !== 'loaded') { findings.failedViewers.push(id); continue; }
    findings.loaded += 1;
    // A head filling a fair part of the view, shaded and textured: not one flat colour.
    if (!(result.coveredFraction > 0.03 && result.lumaStd > 4)) findings.blank.push(id);
  }
  await page.evaluate(() => window.scrollTo(0, 0));
  await page.screenshot({ path: screenshot, fullPage: true });
} finally {
  await browser.close();
}
const ok = findings.viewers > 0 && findings.loaded === findings.viewers && findings.blank.length === 0 &&
           findings.consoleErrors.length === 0 && findings.failedRequests.length === 0;
console.log(JSON.stringify({ ok, ...findings }));
process.exit(ok ? 0 : 1);
