// What the browser tests share (web_page.mjs, web_watch.mjs): checks that count failures, a
// craneassist process with its output, the address it prints, and Debian's Chromium (headless,
// software WebGL) through playwright-core from the page's npm packages.
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import { resolve } from 'node:path';

let failures = 0;
export const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
  if (!ok) failures += 1;
};
export const failed = () => failures;
export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Runs craneassist with args: { child, output (stdout and stderr so far), exit (a promise) }.
export function run(craneassist, args) {
  const child = spawn(craneassist, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  const p = { child, output: '' };
  child.stdout.on('data', (d) => { p.output += d; });
  child.stderr.on('data', (d) => { p.output += d; });
  p.exit = new Promise((done) => child.on('exit', (code, signal) => done({ code, signal })));
  return p;
}

// The page's address the process prints ("web: open http://..."), within 15 s.
export function printedUrl(p) {
  return new Promise((done, fail) => {
    const timer = setTimeout(() => fail(new Error(`no address printed:\n${p.output}`)), 15000);
    const poll = setInterval(() => {
      const m = p.output.match(/web: open (http:\S+)/);
      if (m) { clearInterval(poll); clearTimeout(timer); done(m[1]); }
    }, 50);
  });
}

export async function launchChromium(nodeModules) {
  const require = createRequire(resolve(nodeModules) + '/');
  const { chromium } = require('playwright-core');
  return chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader',
      '--enable-unsafe-swiftshader', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
}

// A page of the given size whose script errors and console errors are collected in `errors`.
export async function openPage(browser, errors) {
  const context = await browser.newContext({ viewport: { width: 1360, height: 1020 } });
  const page = await context.newPage();
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  return { context, page };
}
