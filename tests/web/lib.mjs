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

// What the page's gauges show of the flow polytope, with the frame they show (read at once, so
// the two belong together): the stick against the available speed, the speed along the chosen
// joint motion, the polytope's measure, and the available-speed arrow ({length, dir} or null).
export function polytopeShown(page) {
  return page.evaluate(() => ({
    frame: window.craneassist.shown,
    gauge: document.getElementById('avail-text')?.textContent,
    resolved: document.getElementById('avail-resolved')?.textContent,
    polytope: document.getElementById('polytope')?.textContent,
    arrow: window.craneassist.avail_arrow,
  }));
}

// What the page shows of the load, with the frame it shows: the crane scale's line and the load
// moment gauge (docs/loads.md).
export function loadShown(page) {
  return page.evaluate(() => ({
    frame: window.craneassist.shown,
    scale: document.getElementById('scale-load')?.textContent,
    moment: document.getElementById('moment-text')?.textContent,
  }));
}

// Checks that `shown` (loadShown) displays its frame's load: the estimate in kg and the load
// moment as a share of the chart's rated load.
export function checkLoadShown(shown, what) {
  const l = shown.frame && shown.frame.load;
  if (!l) { check(false, `${what}: no load in the frame`); return; }
  check(shown.scale && shown.scale.startsWith(`${l.estimate.toFixed(0)} kg`),
    `${what}: the crane scale shows '${shown.scale}' (frame: ${l.estimate} kg)`);
  const want = `${(l.ratio * 100).toFixed(0)} % of ${l.rated.toFixed(0)} kg`;
  check(l.rated > 0 && shown.moment && shown.moment.startsWith(want),
    `${what}: the load moment shows '${shown.moment}' (frame: ${want})`);
}

// Checks that `shown` (polytopeShown) displays its frame's figures: the stick's speed against
// the available speed along it, the volume of a solid polytope, the arrow along the stick.
export function checkPolytopeShown(shown, what) {
  const f = shown.frame;
  if (!f) { check(false, `${what}: no frame shown`); return; }
  const stick = f.cmd.every((x) => x !== null) ? Math.hypot(...f.cmd) : null;
  const want = `${stick === null ? '-' : stick.toFixed(2)} / ${f.avail.toFixed(2)} m/s`;
  check(shown.gauge === want, `${what}: stick / available shows '${shown.gauge}' (frame: ${want})`);
  check(shown.resolved === `${f.avail_resolved.toFixed(2)} m/s`,
    `${what}: along the chosen joint motion '${shown.resolved}' (frame: ${f.avail_resolved})`);
  const volume = `volume ${Number(f.polytope.volume.toPrecision(4))} m³/s³`;
  check(f.polytope.dim === 3 && f.polytope.volume > 0 && shown.polytope === volume,
    `${what}: the polytope shows '${shown.polytope}' (frame: dimension ${f.polytope.dim}, volume ${f.polytope.volume})`);
  if (f.avail > 1e-3 && stick !== null && stick > 1e-3) {
    const a = shown.arrow;
    const along = a ? a.dir.reduce((s, v, i) => s + v * f.cmd[i], 0) / stick : 0;
    check(a !== null && Math.abs(a.length - (0.3 + 2 * f.avail)) < 1e-9 && along > 0.999,
      `${what}: the available-speed arrow is along the stick, ${a ? a.length.toFixed(2) : '-'} m for ${f.avail.toFixed(2)} m/s`);
  }
}

// A page of the given size whose script errors and console errors are collected in `errors`.
export async function openPage(browser, errors) {
  const context = await browser.newContext({ viewport: { width: 1360, height: 1020 } });
  const page = await context.newPage();
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  return { context, page };
}
