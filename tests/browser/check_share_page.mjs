// Opens a visitor's page (`avatarbooth share`) at URL in headless Chromium as a phone (Debian's /usr/bin/chromium
// driven by puppeteer-core, 390x844 at 3x, touch): the <model-viewer> must load the avatar and draw it (not a
// blank canvas), its AR attributes must point at the glb and the usdz, every request must stay on the page's own
// server, and the page must log no console error (a CSP violation is one) and fail no request. Saves a screenshot.
// Usage: node check_share_page.mjs URL SCREENSHOT.png
// Prints one JSON object with the findings; exit code 0 when all is well, 1 otherwise, 2 on a usage/launch error.
import puppeteer from 'puppeteer-core';
import { existsSync } from 'node:fs';
import { viewerPixels } from './viewer_pixels.mjs';

const [url, screenshot] = process.argv.slice(2);
if (!url || !screenshot) {
  console.error('usage: node check_share_page.mjs URL SCREENSHOT.png');
  process.exit(2);
}
const chromium = process.env.CHROMIUM || '/usr/bin/chromium';
if (!existsSync(chromium)) {
  console.error(`no browser at ${chromium} (install Debian's chromium, or set CHROMIUM)`);
  process.exit(2);
}
const origin = new URL(url).origin;
const findings = { loaded: false, consoleErrors: [], failedRequests: [], foreignRequests: [], requests: 0, bytes: 0 };
const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 390, height: 844, deviceScaleFactor: 3, isMobile: true, hasTouch: true });
  page.on('console', (msg) => { if (msg.type() === 'error') findings.consoleErrors.push(msg.text()); });
  page.on('pageerror', (err) => findings.consoleErrors.push(`page error: ${err.message}`));
  page.on('requestfailed', (req) => findings.failedRequests.push(`${req.url().slice(0, 200)}: ${req.failure()?.errorText}`));
  page.on('request', (req) => {
    const u = req.url();
    if (!u.startsWith(origin + '/') && !u.startsWith('blob:') && !u.startsWith('data:')) findings.foreignRequests.push(u);
  });
  page.on('response', async (res) => {
    findings.requests += 1;
    const length = Number(res.headers()['content-length'] || 0);
    findings.bytes += Number.isFinite(length) ? length : 0;
  });
  const t0 = Date.now();
  await page.goto(url, { waitUntil: 'load' });
  findings.domLoadedMs = Date.now() - t0;
  findings.status = await page.evaluate(() => document.title);
  const state = await page.waitForFunction(() => {
    const el = document.querySelector('model-viewer');
    return el && el.loaded ? 'loaded' : false;
  }, { timeout: 120000, polling: 250 }).then(() => 'loaded').catch((e) => `not loaded: ${e.message}`);
  findings.modelLoadedMs = Date.now() - t0;
  findings.loaded = state === 'loaded';
  findings.ar = await page.$eval('model-viewer', (el) => ({
    src: el.getAttribute('src'), iosSrc: el.getAttribute('ios-src'), ar: el.hasAttribute('ar'),
    modes: el.getAttribute('ar-modes') }));
  if (findings.loaded) {
    findings.pixels = await page.$eval('model-viewer', viewerPixels);
  }
  findings.fitsTheScreen = await page.evaluate(() => document.documentElement.scrollWidth <= window.innerWidth);
  await page.screenshot({ path: screenshot, fullPage: true });
} finally {
  await browser.close();
}
const drawn = findings.pixels && findings.pixels.coveredFraction > 0.03 && findings.pixels.lumaStd > 4;
const ok = findings.loaded && drawn && findings.fitsTheScreen && findings.ar.ar &&
           findings.ar.modes === 'scene-viewer quick-look' && /avatar\.glb$/.test(findings.ar.src || '') &&
           /avatar\.usdz$/.test(findings.ar.iosSrc || '') && findings.consoleErrors.length === 0 &&
           findings.failedRequests.length === 0 && findings.foreignRequests.length === 0;
console.log(JSON.stringify({ ok, ...findings }));
process.exit(ok ? 0 : 1);
