// The drive mode in the web view, in a real browser (docs/mobile.md#live): `craneassist sim
// --drive --web` with its default mapping (config/joysticks/web_drive.yaml: the right stick
// drives); the frames carry the base, the page shows its panel, and the page's right stick
// forward drives the base ahead.
//
//   node tests/web/web_drive.mjs CRANEASSIST NODE_MODULES SOURCE_DIR [SCREENSHOT.png]
import { check, failed, launchChromium, openPage, printedUrl, run, sleep } from './lib.mjs';

const [craneassist, nodeModules, source, screenshot] = process.argv.slice(2);
if (!craneassist || !nodeModules || !source) {
  console.error('usage: web_drive.mjs CRANEASSIST NODE_MODULES SOURCE_DIR');
  process.exit(2);
}

const sim = run(craneassist, ['sim', '--drive', '--pump', 'shared', '--web', '--web-listen', '127.0.0.1:0',
  '--no-telemetry', '--duration', '60']);
const url = await printedUrl(sim);
console.log(`page: ${url}`);

const browser = await launchChromium(nodeModules);
const errors = [];
try {
  const { page } = await openPage(browser, errors);
  await page.goto(url);
  await page.waitForFunction(() => window.craneassist.crane && window.craneassist.drawn > 20,
    null, { timeout: 20000 });
  const first = await page.evaluate(() => window.craneassist.last);
  check(first.base && first.base.boxes && first.base.boxes.length === 5,
    'the frames carry the base: the chassis and four wheels');
  check(await page.evaluate(() => !document.getElementById('base-panel').hidden), 'the base panel shows');
  check(/L\/min \(motors \+ crane\)/.test(await page.evaluate(() => document.getElementById('drive-text').textContent)),
    'the drive-flow gauge counts the motors and the crane (shared pump)');

  await page.evaluate(() => window.craneassist.deadman(true));
  await sleep(600);  // the deadman must be held 300 ms before commands pass
  await page.evaluate(() => window.craneassist.stick('right', 0, 1));  // drive ahead
  await sleep(3000);
  const later = await page.evaluate(() => window.craneassist.last);
  const dx = later.base.pose[0] - first.base.pose[0];
  check(dx > 0.3, `the right stick forward drove the base ahead ${dx.toFixed(2)} m`);
  check(later.base.flow_sum <= later.base.flow_max * (1 + 1e-9),
    `the hub motors within Q_max: ${(later.base.flow_sum * 6e4).toFixed(1)} of ${(later.base.flow_max * 6e4).toFixed(0)} L/min`);
  check(Math.abs(later.base.root_p[0] - first.base.root_p[0] - dx) < 0.05, 'the crane rides on the base');
  await page.evaluate(() => window.craneassist.stick('right', 0.8, 0.8));  // ahead, turning right
  await sleep(3000);
  const turned = await page.evaluate(() => window.craneassist.last);
  const dphi = turned.base.pose[2] - later.base.pose[2];
  check(dphi < -0.05, `the right stick to the right turned the base right: ${(dphi * 180 / Math.PI).toFixed(1)} deg`);
  if (screenshot) {
    await page.screenshot({ path: screenshot });
    console.log(`screenshot: ${screenshot}`);
  }
  await page.evaluate(() => { window.craneassist.stick('right', 0, 0); window.craneassist.deadman(false); });
  check(errors.length === 0, `no errors in the page${errors.length ? ': ' + errors.join('; ') : ''}`);
} finally {
  await browser.close();
  sim.child.kill('SIGINT');
}
const { code } = await sim.exit;
check(code === 0, `sim ended with exit ${code}`);
check(/input \(<embedded config\/joysticks\/web_drive.yaml>\)/.test(sim.output),
  'sim --drive --web takes the page\'s drive mapping by default');
process.exit(failed() === 0 ? 0 : 1);
