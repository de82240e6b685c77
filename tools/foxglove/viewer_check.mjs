// Opens a craneassist recording or live server in a real Foxglove-class viewer (a web build of
// Lichtblick, the open-source fork of Foxglove Studio) in headless Chromium, imports the shipped
// layout through the viewer's Layouts menu as a user would, and checks what a user would see:
// every panel of the layout draws data, and the viewer's Problems tab is empty. Writes a
// screenshot. Not part of CTest (the viewer is built outside the project: docs/foxglove.md).
//
//   node tools/foxglove/viewer_check.mjs --viewer DIR --mcap FILE --out PREFIX
//   node tools/foxglove/viewer_check.mjs --viewer DIR --ws ws://127.0.0.1:8765 --out PREFIX
//
// DIR: the viewer's web build (Lichtblick: web/.webpack after `yarn web:build:prod`). It and the
// recording are served on 127.0.0.1 (HTTP Range, CORS) by this script. Options: --layout FILE
// (default examples/foxglove/craneassist-layout.json), --wait S (seconds to let the viewer load
// and a live run flow, default 20), --play S (a recording: seconds of playback, default 8),
// --modules DIR (npm packages with playwright-core, default build/app/web/page/node_modules),
// --chromium PATH (default /usr/bin/chromium). Prints each panel's count of drawn pixels and
// "viewer check OK", or what is missing; exit 0 or 1.
import { createReadStream, existsSync, readFileSync, statSync } from "node:fs";
import { createServer } from "node:http";
import { createRequire } from "node:module";
import { basename, extname, join, resolve } from "node:path";

const root = resolve(new URL("../..", import.meta.url).pathname);
const opts = {
  layout: join(root, "examples/foxglove/craneassist-layout.json"),
  wait: "20",
  play: "8",
  modules: join(root, "build/app/web/page/node_modules"),
  chromium: "/usr/bin/chromium",
};
const argv = process.argv.slice(2);
for (let i = 0; i < argv.length; i += 2) {
  if (!argv[i].startsWith("--") || argv[i + 1] === undefined) {
    console.error(`viewer_check: '${argv[i]}': expected --option VALUE (see the file's header)`);
    process.exit(2);
  }
  opts[argv[i].slice(2)] = argv[i + 1];
}
if (!opts.viewer || !opts.out || !(opts.mcap || opts.ws)) {
  console.error("usage: viewer_check.mjs --viewer DIR (--mcap FILE | --ws URL) --out PREFIX");
  process.exit(2);
}
for (const [what, path] of [["--viewer", join(opts.viewer, "index.html")], ["--layout", opts.layout],
                            ["--modules", join(opts.modules, "playwright-core")], ["--chromium", opts.chromium],
                            ...(opts.mcap ? [["--mcap", opts.mcap]] : [])]) {
  if (!existsSync(path)) {
    console.error(`viewer_check: ${what}: ${path} not found`);
    process.exit(2);
  }
}
const require = createRequire(`${resolve(opts.modules)}/`);
const { chromium } = require("playwright-core");

// --- a static server for the viewer and the recording (Range requests, CORS) -----------------------
const types = { ".html": "text/html", ".js": "text/javascript", ".css": "text/css", ".wasm": "application/wasm",
                ".json": "application/json", ".svg": "image/svg+xml", ".woff2": "font/woff2", ".png": "image/png" };
const server = createServer((req, res) => {
  const name = decodeURIComponent(new URL(req.url, "http://x").pathname);
  const file = opts.mcap && name === `/${basename(opts.mcap)}` ? resolve(opts.mcap)
    : join(resolve(opts.viewer), name === "/" ? "index.html" : name);
  res.setHeader("Access-Control-Allow-Origin", "*");
  res.setHeader("Access-Control-Allow-Headers", "Range");
  res.setHeader("Access-Control-Expose-Headers", "Content-Length, Content-Range, Accept-Ranges");
  if (req.method === "OPTIONS") return res.end();
  if (!file.startsWith(resolve(opts.viewer)) && file !== resolve(opts.mcap ?? "")) return res.writeHead(403).end();
  if (!existsSync(file) || !statSync(file).isFile()) return res.writeHead(404).end();
  const size = statSync(file).size;
  res.setHeader("Accept-Ranges", "bytes");
  res.setHeader("Content-Type", types[extname(file)] ?? "application/octet-stream");
  const range = /bytes=(\d*)-(\d*)/.exec(req.headers.range ?? "");
  if (range) {
    const start = range[1] === "" ? size - Number(range[2]) : Number(range[1]);
    const end = range[1] !== "" && range[2] !== "" ? Math.min(Number(range[2]), size - 1) : size - 1;
    res.writeHead(206, { "Content-Range": `bytes ${start}-${end}/${size}`, "Content-Length": end - start + 1 });
    if (req.method === "HEAD") return res.end();
    return createReadStream(file, { start, end }).pipe(res);
  }
  res.writeHead(200, { "Content-Length": size });
  if (req.method === "HEAD") return res.end();
  createReadStream(file).pipe(res);
});
await new Promise((ok) => server.listen(0, "127.0.0.1", ok));
const base = `http://127.0.0.1:${server.address().port}`;
const source = opts.mcap ? `ds=remote-file&ds.url=${encodeURIComponent(`${base}/${basename(opts.mcap)}`)}`
  : `ds=foxglove-websocket&ds.url=${encodeURIComponent(opts.ws)}`;

// --- the viewer in Chromium -------------------------------------------------------------------------
let failures = 0;
const check = (ok, what) => {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (!ok) failures += 1;
};
// As root (CI, containers) Chromium needs --no-sandbox; swiftshader draws WebGL without a GPU, and
// the closed network wants no background connections.
const browser = await chromium.launch({
  executablePath: opts.chromium,
  args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist",
         "--disable-background-networking", "--disable-component-update", "--no-first-run"],
});
const page = await browser.newPage({ viewport: { width: 1600, height: 1000 } });
const layoutText = readFileSync(opts.layout, "utf8");
const layoutPanels = Object.keys(JSON.parse(layoutText).configById);
// The Layouts menu's "Import layout" opens the system's file picker: here it returns the layout.
await page.addInitScript((text) => {
  window.showOpenFilePicker = async () => [{ kind: "file", name: "craneassist-layout.json",
    getFile: async () => new File([text], "craneassist-layout.json", { type: "application/json" }) }];
}, layoutText);
await page.goto(`${base}/?${source}`, { waitUntil: "domcontentloaded", timeout: 120000 });
await page.getByTestId("layouts-left").click({ timeout: 60000 });
await page.getByText("Import from file").first().click({ timeout: 30000 });
const panel = (id) => page.getByTestId(`panel-mouseenter-container ${id}`);
for (const id of layoutPanels) await panel(id).waitFor({ timeout: 30000 });
check(true, `the layout imported through the Layouts menu: ${layoutPanels.join(", ")}`);
await page.waitForTimeout(Number(opts.wait) * 1000);
if (opts.mcap) {
  await page.locator('button[title="Play"]').click();
  await page.waitForTimeout(Number(opts.play) * 1000);
  await page.locator('button[title="Pause"]').click();
  await page.waitForTimeout(3000);
}

// The Problems tab, left open in the screenshot: the channels the viewer could not read, the
// schemas it rejected.
await page.getByTestId("problems-left").click();
await page.waitForTimeout(1500);
const sidebar = (await page.getByTestId("sidebar-left").innerText()).trim();
const problems = sidebar.split("\n").slice(4).join(" | ");
check(sidebar.includes("No problems found"), `Problems tab: ${problems.slice(0, 600)}`);

// Drawn pixels per panel: saturated colours on each panel's canvas (the plots' series, the state
// transitions' bars; in 3-D the crane's warm colours, not the blue grid). The legends float over
// the plots' left part, so a plot counts its right 55 %.
const shot = await page.screenshot({ path: `${opts.out}.png` });
const boxes = {};
for (const id of layoutPanels) {
  const canvas = panel(id).locator("canvas").first();
  boxes[id] = await canvas.boundingBox();
}
const counts = await page.evaluate(async ({ png, boxes }) => {
  const img = new Image();
  img.src = `data:image/png;base64,${png}`;
  await img.decode();
  const c = document.createElement("canvas");
  c.width = img.width;
  c.height = img.height;
  const g = c.getContext("2d");
  g.drawImage(img, 0, 0);
  const out = {};
  for (const [id, b] of Object.entries(boxes)) {
    if (!b) { out[id] = -1; continue; }
    const x0 = Math.round(id.startsWith("Plot!") ? b.x + 0.45 * b.width : b.x);
    const w = Math.round(b.x + b.width) - x0, h = Math.round(b.height);
    const d = g.getImageData(x0, Math.round(b.y), w, h).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) {
      const [r, gr, bl] = [d[i], d[i + 1], d[i + 2]];
      const saturated = Math.max(r, gr, bl) - Math.min(r, gr, bl) > 60;
      if (id.startsWith("3D!") ? saturated && r > bl + 40 : saturated) ++n;
    }
    out[id] = n;
  }
  return out;
}, { png: shot.toString("base64"), boxes });
for (const id of layoutPanels) {
  const need = id.startsWith("3D!") ? 2000 : 300;
  check(counts[id] >= need, `${id}: ${counts[id]} drawn pixels (at least ${need})`);
}

await browser.close();
server.close();
console.log(failures === 0 ? `viewer check OK: ${opts.out}.png` : `viewer check: ${failures} FAILED (${opts.out}.png)`);
process.exit(failures === 0 ? 0 : 1);
