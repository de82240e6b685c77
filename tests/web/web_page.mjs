// The web view in a real browser (Debian's Chromium, headless, driven by playwright-core):
// `craneassist sim --web` serves the page; the page must load and draw the crane, move with the
// simulator, steer the tip the way the on-screen sticks point, and stop the crane when it closes.
//
//   node tests/web/web_page.mjs CRANEASSIST NODE_MODULES [SCREENSHOT.png]
//
// Prints the figures (frames per second the page received, stick-to-drawing latency) and exits
// 0 when every check holds. docs/web.md#tests.
import { check, checkLoadShown, checkPolytopeShown, failed, launchChromium, loadShown, openPage,
  polytopeShown, printedUrl, run, sleep } from './lib.mjs';

const [craneassist, nodeModules, screenshot] = process.argv.slice(2);
if (!craneassist || !nodeModules) {
  console.error('usage: web_page.mjs CRANEASSIST NODE_MODULES [SCREENSHOT.png]');
  process.exit(2);
}

// The simulator with the web view on any free port; its address from the first line it prints.
const sim = run(craneassist, ['sim', '--web', '--web-listen', '127.0.0.1:0', '--no-telemetry',
  '--duration', '60']);
const url = await printedUrl(sim);
console.log(`page: ${url}`);

const browser = await launchChromium(nodeModules);
const errors = [];
try {
  const { context, page } = await openPage(browser, errors);
  await page.goto(url);

  // 1. The page loads, connects and draws the crane from the stream.
  await page.waitForFunction(() => window.craneassist.crane && window.craneassist.drawn > 20,
    null, { timeout: 20000 });
  const first = await page.evaluate(() => window.craneassist.last);
  check(first.points && first.points.length === 5, `the crane is drawn from ${first.points.length} joint frames`);
  const state = await page.evaluate(() => window.craneassist.command);
  check(state === 'available' || state === 'yours', `the page may command (local, with the token): ${state}`);
  await sleep(1200);
  const rate = await page.evaluate(() => window.craneassist.rate_hz);
  check(rate >= 20 && rate <= 40, `frames received: ${rate} per second (30 streamed)`);
  // The "All values" list: every field of the table (crane.json), each filled from the frames.
  await page.evaluate(() => { document.getElementById('all-values').open = true; });
  await sleep(300);
  const values = await page.evaluate(() => ({
    fields: window.craneassist.crane.fields.length,
    rows: document.querySelectorAll('#fields-table tr').length,
    power: [...document.querySelectorAll('#fields-table tr')]
      .find((r) => r.cells[0].textContent === 'hydraulics.pump_pressure_pa')?.cells[1].textContent,
  }));
  check(values.fields > 60 && values.rows === values.fields && /^[0-9.e+-]+$/.test(values.power ?? ''),
    `all values: ${values.rows} rows of ${values.fields} fields, pump pressure ${values.power} Pa`);
  // Before any stick motion: the polytope's volume at the start pose, no stick direction yet.
  const idle = await polytopeShown(page);
  checkPolytopeShown(idle, 'at rest');

  // 2. Hold the deadman, then push the left stick forward: the tip goes out (radial, +x at slew
  //    0), and the drawing follows the simulator.
  await page.evaluate(() => window.craneassist.deadman(true));
  await sleep(600);  // the deadman must be held 300 ms before commands pass
  const before = await page.evaluate(() => window.craneassist.last);
  await page.evaluate(() => window.craneassist.stick('left', 0, 1));
  await sleep(2000);
  const out = await page.evaluate(() => window.craneassist.last);
  const dx = out.tip[0] - before.tip[0], dy = out.tip[1] - before.tip[1], dz = out.tip[2] - before.tip[2];
  check(dx > 0.3, `left stick forward: the tip went out ${dx.toFixed(2)} m`);
  check(Math.abs(dz) < 0.1 * dx && Math.abs(dy) < 0.2 * dx,
    `... and not sideways or up (${dz.toFixed(3)} m, ${dy.toFixed(3)} m)`);
  const moved = Math.hypot(...out.points[4].map((v, i) => v - before.points[4][i]));
  check(moved > 0.3, `the drawn boom end moved ${moved.toFixed(2)} m`);
  // The available speed along the stick and the polytope's volume, shown and updated as the
  // crane moves.
  const going = await polytopeShown(page);
  checkPolytopeShown(going, 'stick forward');
  checkLoadShown(await loadShown(page), 'stick forward');
  check(going.frame.avail > 0 && going.frame.avail >= Math.hypot(...going.frame.ref) - 1e-9,
    `available along the stick ${going.frame.avail.toFixed(2)} m/s, the reference ${Math.hypot(...going.frame.ref).toFixed(2)} m/s within it`);
  check(going.polytope !== idle.polytope && going.gauge !== idle.gauge,
    `the polytope's figures follow the crane: '${idle.polytope}', '${idle.gauge}' at rest, then '${going.polytope}', '${going.gauge}'`);
  // The hanging grapple (docs/sway.md): drawn its hanger length below the tip, swinging as the
  // crane starts, its swing shown.
  const grapple = await page.evaluate(() => ({
    g: window.craneassist.grapple, max: window.craneassist.swing_max,
    text: document.getElementById('swing')?.textContent,
  }));
  check(grapple.g !== null, 'the grapple is drawn');
  if (grapple.g) {
    const l = Math.hypot(...grapple.g.at.map((v, i) => v - grapple.g.tip[i]));
    check(Math.abs(l - 0.7) < 0.01 && grapple.g.at[1] < grapple.g.tip[1] - 0.6,
      `the grapple hangs ${l.toFixed(3)} m below the tip`);
  }
  check(grapple.max > 0.5, `the grapple swung up to ${grapple.max.toFixed(1)} deg as the crane started`);
  check(/^[0-9.]+ deg \(out -?[0-9.]+, across -?[0-9.]+\)$/.test(grapple.text || ''),
    `the page shows the swing: '${grapple.text}'`);
  const latency = await page.evaluate(() => window.craneassist.latency_ms);
  check(latency.length > 0, `stick to drawing: ${latency.map((v) => v.toFixed(0)).join(', ')} ms`);

  // 3. The right stick up: the tip rises.
  await page.evaluate(() => { window.craneassist.stick('left', 0, 0); window.craneassist.stick('right', 0, 1); });
  await sleep(300);
  const low = await page.evaluate(() => window.craneassist.last);
  await sleep(1500);
  const high = await page.evaluate(() => window.craneassist.last);
  check(high.tip[1] - low.tip[1] > 0.2, `right stick up: the tip rose ${(high.tip[1] - low.tip[1]).toFixed(2)} m (${high.status}${high.stop_reason ? ": " + high.stop_reason : ""})`);

  if (screenshot) {  // the picture in README and docs/web.md: out and to the side
    await page.evaluate(() => { window.craneassist.stick('right', 0, 0); window.craneassist.stick('left', 0.6, 0.7); });
    await sleep(1500);
    await page.screenshot({ path: screenshot });
    console.log(`screenshot: ${screenshot}`);
  }

  // 4. Close the page while the crane moves: the connection is lost, the crane stops.
  await page.evaluate(() => window.craneassist.stick('left', 0.8, 0.6));
  await sleep(800);
  const moving = await page.evaluate(() => window.craneassist.last);
  check(Math.hypot(...moving.tip_v) > 0.1, `moving before the page closes: ${Math.hypot(...moving.tip_v).toFixed(2)} m/s`);
  await page.close();
  await sleep(2500);
  const watcher = await context.newPage();
  await watcher.goto(url.replace(/\?token=.*/, ''));  // no token: a view only
  await watcher.waitForFunction(() => window.craneassist.frames > 5, null, { timeout: 10000 });
  const after = await watcher.evaluate(() => window.craneassist.last);
  check((await watcher.evaluate(() => window.craneassist.command)) === 'view', 'a page without the token is a view only');
  check(Math.hypot(...after.tip_v) < 0.01, `after the page closed the crane is at rest (${Math.hypot(...after.tip_v).toFixed(3)} m/s, ${after.status}: ${after.stop_reason})`);
  check(errors.length === 0, `no errors in the page${errors.length ? ': ' + errors.join('; ') : ''}`);
} finally {
  await browser.close();
  sim.child.kill('SIGINT');
}
const { code } = await sim.exit;
check(code === 0, `sim ended with exit ${code}`);
check(/input device disconnected: stopping/.test(sim.output), 'sim reported the lost page as a disconnected input');
const report = sim.output.match(/ {2}web: .*/);
console.log(report ? report[0] : sim.output);
process.exit(failed() === 0 ? 0 : 1);
