// `craneassist web` in a real browser (Debian's Chromium, headless, driven by playwright-core):
// the page of a run in another process, from its DDS telemetry. `craneassist web` serves the
// page; a `craneassist replay --telemetry` on the same DDS domain moves the tip out; the drawing
// must follow, the page must be a view only, and the replay's end must show as `stopped`.
//
//   node tests/web/web_watch.mjs CRANEASSIST NODE_MODULES DOMAIN
//
// docs/web.md#watching-a-run.
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { check, checkLoadShown, checkPolytopeShown, failed, launchChromium, loadShown, openPage,
  polytopeShown, printedUrl, run }
  from './lib.mjs';

const [craneassist, nodeModules, domain] = process.argv.slice(2);
if (!craneassist || !nodeModules || !domain) {
  console.error('usage: web_watch.mjs CRANEASSIST NODE_MODULES DOMAIN');
  process.exit(2);
}

const work = mkdtempSync(join(tmpdir(), 'web-watch-'));
// Still for 5 s (DDS discovery between the two processes takes from 0.1 s to, now and then on
// a loaded machine, 2.5 s: the page must see the crane before it moves), out along +x for
// 2.5 s, then still: the replay ends about 8 s after it starts.
const holdS = 5.0;
const replayFile = join(work, 'out.csv');
writeFileSync(replayFile,
  `t,v_x,v_y,v_z\n0.0,0,0,0\n${holdS},0.3,0,0\n${holdS + 2.5},0,0,0\n${holdS + 3},0,0,0\n`);

const web = run(craneassist, ['web', '--web-listen', '127.0.0.1:0', '--domain', domain,
  '--duration', '60']);
const url = await printedUrl(web);
console.log(`page: ${url}`);

const browser = await launchChromium(nodeModules);
const errors = [];
let replay;
let dying;
try {
  const { page } = await openPage(browser, errors);
  await page.goto(url);
  await page.waitForFunction(() => window.craneassist.crane && window.craneassist.command !== 'none',
    null, { timeout: 20000 });
  check((await page.evaluate(() => window.craneassist.command)) === 'view',
    'the page of a watched run is a view only (even with the token, from this host)');

  // The run starts in another process; its telemetry reaches the page through `craneassist web`.
  replay = run(craneassist, ['replay', replayFile, '--realtime', '--settle', '1', '--telemetry', '--domain',
    domain, '--no-log']);
  await page.waitForFunction(() => window.craneassist.drawn > 10, null, { timeout: 20000 });
  const first = await page.evaluate(() => window.craneassist.last);
  check(first.points && first.points.length === 5, `the crane is drawn from ${first.points.length} joint frames`);
  check(first.t < holdS, `the page shows the crane before it moves: first frame at t = ${first.t.toFixed(2)} s`);
  // Out by 0.4 m (of the 0.75 m the replay moves), within the replay's 2.5 s plus a second.
  await page.waitForFunction((x0) => window.craneassist.last.tip[0] - x0 > 0.4, first.tip[0],
    { timeout: (holdS + 3.5) * 1000 }).catch(() => {});
  const later = await page.evaluate(() => window.craneassist.last);
  const dx = later.tip[0] - first.tip[0];
  check(dx > 0.4 && Math.abs(later.tip[2] - first.tip[2]) < 0.1 * dx,
    `the drawn tip follows the replay out along +x: ${dx.toFixed(2)} m, ${(later.tip[2] - first.tip[2]).toFixed(3)} m in z, at t = ${later.t.toFixed(2)} s`);
  const moved = Math.hypot(...later.points[4].map((v, i) => v - first.points[4][i]));
  check(moved > 0.4, `the drawn boom end moved ${moved.toFixed(2)} m`);
  // The polytope's figures came over DDS (the status topic): shown as in sim --web.
  const shown = await polytopeShown(page);
  checkPolytopeShown(shown, 'watched run');
  // The crane scale and the load moment came over DDS too.
  checkLoadShown(await loadShown(page), 'watched run');
  check(shown.frame.avail > 0, `available along the stick: ${shown.frame.avail.toFixed(2)} m/s`);
  const rate = await page.evaluate(() => window.craneassist.rate_hz);
  check(rate >= 20 && rate <= 40, `frames received: ${rate} per second (30 streamed)`);

  const { code } = await replay.exit;
  check(code === 0, `the replay ended with exit ${code}`);
  await page.waitForFunction(() => window.craneassist.last && window.craneassist.last.status === 'stopped',
    null, { timeout: 5000 }).catch(() => {});
  const end = await page.evaluate(() => window.craneassist.last);
  check(end.status === 'stopped', `the replay's end shows on the page: ${end.status}${end.stop_reason ? ': ' + end.stop_reason : ''}`);

  // A run on the wheeled base (sim --drive): its base comes over craneassist/base and is drawn.
  const driving = run(craneassist, ['sim', '--drive', '--input', 'replay', replayFile, '--duration', '4',
    '--domain', domain]);
  await page.waitForFunction(() => window.craneassist.last && window.craneassist.last.base, null,
    { timeout: 20000 }).catch(() => {});
  const onBase = await page.evaluate(() => window.craneassist.last);
  check(onBase.base && onBase.base.boxes && onBase.base.boxes.length === 5,
    'a watched run on a base: the frames carry its chassis and four wheels');
  check(await page.evaluate(() => !document.getElementById('base-panel').hidden),
    'a watched run on a base: the base panel shows');
  const drove = await driving.exit;
  check(drove.code === 0, `the drive run ended with exit ${drove.code}${drove.code === 0 ? '' : ': ' + driving.output}`);

  // A run that dies (kill -9: no end state sent) shows as lost, not as running forever.
  const dyingFile = join(work, 'dying.csv');
  writeFileSync(dyingFile, 't,v_x,v_y,v_z\n0.0,0,0,0\n60,0,0,0\n');
  dying = run(craneassist, ['replay', dyingFile, '--realtime', '--settle', '1', '--telemetry',
    '--domain', domain, '--no-log']);
  await page.waitForFunction(() => window.craneassist.last.status === 'running', null,
    { timeout: 20000 }).catch(() => {});
  const alive = await page.evaluate(() => window.craneassist.last.status);
  check(alive === 'running', `a second run shows as running: ${alive}`);
  await page.waitForFunction(() => !window.craneassist.last.base, null, { timeout: 5000 })
    .catch(() => {});
  check(await page.evaluate(() => !window.craneassist.last.base &&
    document.getElementById('base-panel').hidden), 'a run without a base: no base drawn');
  dying.child.kill('SIGKILL');
  const killedAt = Date.now();
  await page.waitForFunction(() => window.craneassist.last.status === 'lost', null,
    { timeout: 10000 }).catch(() => {});
  const gone = await page.evaluate(() => window.craneassist.last);
  check(gone.status === 'lost' && /died/.test(gone.stop_reason),
    `a run killed with SIGKILL shows '${gone.status}: ${gone.stop_reason}' ${((Date.now() - killedAt) / 1000).toFixed(1)} s later`);
  check(errors.length === 0, `no errors in the page${errors.length ? ': ' + errors.join('; ') : ''}`);
} finally {
  await browser.close();
  if (replay) replay.child.kill('SIGINT');
  if (dying) dying.child.kill('SIGKILL');
  web.child.kill('SIGINT');
  rmSync(work, { recursive: true, force: true });
}
const { code } = await web.exit;
check(code === 0, `web ended with exit ${code}`);
check(/web: receiving from crane 'K70M/.test(web.output), 'web named the watched crane');
check(/web: no telemetry from the watched run for .* before it said it stopped/.test(web.output),
  'web said the killed run went silent');
const report = web.output.match(/ {2}web watch: .*\n.*/);
console.log(failed() === 0 && report ? report[0] : `web printed:\n${web.output}\nreplay printed:\n${replay ? replay.output : ''}`);
process.exit(failed() === 0 ? 0 : 1);
