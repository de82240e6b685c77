// craneassist's Foxglove WebSocket server (docs/foxglove.md) against independent clients: npm's
// @foxglove/ws-protocol FoxgloveClient over the `ws` package, once with each subprotocol
// (foxglove.websocket.v1, foxglove.sdk.v1), /joint_states decoded with
// @foxglove/rosmsg2-serialization from the advertised ros2msg schema and checked against the CSV
// log of the same run, the JSON channels' advertised JSON Schemas within what Foxglove-class viewers
// parse (viewer_schema.mjs) and their messages valid against them (ajv; NaN travels as null).
//
//   node ws_check.mjs NODE_MODULES CRANEASSIST REPLAY.csv PORT OUTDIR live
//     a real-time replay; clients reading at full speed (each subprotocol), at 100 Hz and at
//     10 Hz (their socket read that often: a slow client loses frames, the run does not slow),
//     and one that sends garbage; prints each client's frame rate and latency
//   node ws_check.mjs NODE_MODULES CRANEASSIST REPLAY.csv PORT OUTDIR simtime
//     a replay as fast as possible (--foxglove-wait): the `time` capability, machine time
import { spawn } from "node:child_process";
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";

import { nanAsNull, viewerSchemaProblems } from "./viewer_schema.mjs";

const [modules, craneassist, replay, port, outdir, mode] = process.argv.slice(2);
const require = createRequire(`${modules}/`);
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parse: parseMsgDef } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const WebSocket = require("ws");
const Ajv2020 = require("ajv/dist/2020").default;

let failures = 0;
const check = (ok, what) => {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (!ok) failures += 1;
};
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const url = `ws://127.0.0.1:${port}`;
const csvPath = `${outdir}/foxglove_${mode}.csv`;
const realtime = mode === "live";

// simtime: the bundled demo (17 s of machine time, 1721 cycles, in well under a second).
const args = ["replay", ...(realtime ? [replay] : []), "--log", csvPath, "--foxglove", `127.0.0.1:${port}`,
  "--foxglove-wait", "15", "--settle", "1"];
if (realtime) args.push("--realtime");
const run = spawn(craneassist, args, { stdio: ["ignore", "pipe", "pipe"] });
let output = "";
run.stdout.on("data", (d) => { output += d; });
run.stderr.on("data", (d) => { output += d; });
const exited = new Promise((done) => run.on("exit", (code) => done(code)));

// A client: connects with `subprotocol`, subscribes to every channel, keeps what arrives.
// readHz: its socket is read only that often (0: as fast as it comes; -1: never, a client that
// has stalled).
function client(name, subprotocol, readHz = 0) {
  const ws = new WebSocket(url, [subprotocol]);
  const c = { name, subprotocol, ws, info: null, channels: [], bySub: new Map(), messages: [],
    times: [], statuses: [], closed: false, negotiated: "" };
  ws.on("upgrade", (res) => { c.negotiated = res.headers["sec-websocket-protocol"] ?? ""; });
  const fc = new FoxgloveClient({ ws });
  fc.on("serverInfo", (i) => { c.info = i; });
  fc.on("status", (s) => c.statuses.push(s));
  fc.on("advertise", (channels) => {
    c.channels.push(...channels);
    for (const ch of channels) c.bySub.set(fc.subscribe(ch.id), ch);
    if (readHz < 0) ws._socket.pause();
    if (readHz > 0) {
      const socket = ws._socket;
      socket.pause();
      c.pacer = setInterval(() => {
        socket.resume();
        setImmediate(() => socket.pause());
      }, 1000 / readHz);
    }
  });
  fc.on("message", ({ subscriptionId, timestamp, data }) => {
    c.messages.push({ channel: c.bySub.get(subscriptionId), timestamp, data,
      received: BigInt(Date.now()) * 1000000n });
  });
  fc.on("time", ({ timestamp }) => c.times.push(timestamp));
  c.done = new Promise((done) => fc.on("close", () => {
    c.closed = true;
    clearInterval(c.pacer);
    done();
  }));
  fc.on("error", () => {});
  return c;
}

// The server's address is up once the process says so.
for (let i = 0; i < 150 && !output.includes("foxglove: ws://"); ++i) await sleep(100);
check(output.includes("foxglove: ws://"), `craneassist listens (${url})`);

const clients = realtime
  ? [client("websocket.v1", "foxglove.websocket.v1"), client("sdk.v1", "foxglove.sdk.v1"),
     client("100 Hz", "foxglove.sdk.v1", 100), client("10 Hz", "foxglove.websocket.v1", 10)]
  : [client("sim time", "foxglove.sdk.v1")];

// A client that subscribes to everything and then never reads: it loses messages, the others
// and the run do not notice.
const stalled = realtime ? null : client("stalled", "foxglove.sdk.v1", -1);

// A client that sends what a server must survive: not JSON, an unknown op, a bad subscription,
// a binary frame (client publish, not offered), and a request without a Foxglove subprotocol.
const garbage = new WebSocket(url, ["foxglove.websocket.v1"]);
const garbageStatuses = [];
garbage.on("message", (d, binary) => {
  if (!binary) {
    const m = JSON.parse(d.toString());
    if (m.op === "status") garbageStatuses.push(m);
  }
});
garbage.on("open", () => {
  garbage.send("{not json");
  garbage.send(JSON.stringify({ op: "setParameters", parameters: [] }));
  garbage.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: 999 }] }));
  garbage.send(JSON.stringify({ op: "subscribe", subscriptions: "x" }));
  garbage.send(Buffer.from([0x01, 0, 0, 0, 0, 1, 2, 3]));
});
garbage.on("error", () => {});
const refused = await new Promise((done) => {
  const plain = new WebSocket(url, ["not.foxglove"]);
  plain.on("unexpected-response", (_req, res) => done(res.statusCode));
  plain.on("open", () => done("opened"));
  plain.on("error", () => done("error"));
});
check(refused === 400, `a client without a Foxglove subprotocol is refused (HTTP ${refused})`);

const code = await exited;
await Promise.all(clients.map((c) => Promise.race([c.done, sleep(3000)])));
check(code === 0, `the replay exits 0 (${code})`);

// The CSV log: rows by machine time.
const csv = readFileSync(csvPath, "utf8").trim().split("\n");
const header = csv[0].split(",");
const col = (n) => header.indexOf(n);
const rowsByT = new Map(csv.slice(1).map((l) => {
  const r = l.split(",");
  return [Number(r[col("t")]).toFixed(4), r];
}));
const dof = header.filter((h) => /^q\d+$/.test(h)).length;

const ajv = new Ajv2020({ strict: false, allErrors: true });
for (const c of clients) {
  check(c.negotiated === c.subprotocol, `${c.name}: subprotocol ${c.negotiated}`);
  check(c.info?.name === "craneassist", `${c.name}: serverInfo from craneassist`);
  check((c.info?.capabilities ?? []).includes("time") === !realtime,
        `${c.name}: capabilities [${c.info?.capabilities}] (time only when not real time)`);
  const topics = c.channels.map((ch) => ch.topic);
  for (const t of ["/joint_states", "/tf", "/robot_description", "/craneassist/tip_velocity/command",
                   "/craneassist/tip_velocity/reference", "/craneassist/status",
                   "/craneassist/hydraulics", "/craneassist/limits", "/craneassist/polytope",
                   "/craneassist/loads"]) {
    check(topics.includes(t), `${c.name}: advertises ${t}`);
  }
  const of = (topic) => c.messages.filter((m) => m.channel.topic === topic);
  const reader = (topic) => new MessageReader(
    parseMsgDef(c.channels.find((ch) => ch.topic === topic).schema, { ros2: true }));
  // Machine time of each stamp, from the status channel's t.
  const tOf = new Map();
  for (const m of of("/craneassist/status")) {
    tOf.set(m.timestamp, JSON.parse(new TextDecoder().decode(m.data)).t);
  }
  const js = of("/joint_states");
  const jsReader = reader("/joint_states");
  let worst = 0, compared = 0;
  for (const m of js) {
    const t = tOf.get(m.timestamp);
    if (t === undefined) continue;
    const row = rowsByT.get(Number(t).toFixed(4));
    if (!row) continue;
    const msg = jsReader.readMessage(m.data);
    for (let i = 0; i < dof; ++i) worst = Math.max(worst, Math.abs(msg.position[i] - Number(row[col(`q${i + 1}`)])));
    ++compared;
  }
  check(compared > 0 && worst < 1e-6,
        `${c.name}: /joint_states ${compared} messages equal the CSV's q (|diff| <= ${worst.toExponential(2)})`);
  const urdf = of("/robot_description");
  check(urdf.length === 1 && reader("/robot_description").readMessage(urdf[0].data).data.includes("<robot"),
        `${c.name}: /robot_description once, a URDF`);
  if (!realtime && urdf.length > 0) {
    // Subscribed before the first cycle (--foxglove-wait): the URDF waits for the first pose and
    // comes with it, so a viewer never draws the crane with every joint at zero.
    const tf = of("/tf");
    const first = tf.length > 0 ? tf[0] : null;
    check(first !== null && urdf[0].timestamp === first.timestamp &&
          c.messages.indexOf(urdf[0]) < c.messages.indexOf(first),
          `${c.name}: /robot_description comes with the first /tf (stamps ${urdf[0].timestamp}, ${first?.timestamp})`);
  }
  let jsonOk = 0, jsonBad = "";
  for (const ch of c.channels.filter((x) => x.encoding === "json")) {
    const problems = viewerSchemaProblems(JSON.parse(ch.schema));
    check(problems.length === 0, `${c.name}: ${ch.topic}'s schema read by a viewer ${problems}`);
    const validate = ajv.compile(nanAsNull(JSON.parse(ch.schema)));
    for (const m of of(ch.topic)) {
      if (validate(JSON.parse(new TextDecoder().decode(m.data)))) ++jsonOk;
      else jsonBad = `${ch.topic}: ${ajv.errorsText(validate.errors)}`;
    }
  }
  check(jsonOk > 0 && jsonBad === "", `${c.name}: ${jsonOk} JSON messages valid against their schemas ${jsonBad}`);
  if (realtime && js.length > 1) {
    // Frame rate of /joint_states and latency (arrival minus the message's wall-clock stamp).
    const span = Number(js[js.length - 1].received - js[0].received) / 1e9;
    const lat = js.map((m) => Number(m.received - m.timestamp) / 1e6).sort((a, b) => a - b);
    const q = (p) => lat[Math.min(lat.length - 1, Math.floor(p * lat.length))].toFixed(1);
    console.log(`rate ${c.name}: /joint_states ${js.length} messages in ${span.toFixed(2)} s = ` +
                `${(js.length / span).toFixed(1)} Hz; latency median ${q(0.5)} ms, p95 ${q(0.95)} ms, max ${q(1)} ms`);
  }
  if (!realtime) {
    const monotonic = c.times.every((t, i) => i === 0 || t >= c.times[i - 1]);
    check(c.times.length > 0 && monotonic, `${c.name}: ${c.times.length} time messages, machine time, in order`);
    // Machine time on the wall clock of the run's start: not 1970, and as long as the run.
    const first = Number(c.times[0] ?? 0n) / 1e9, last = Number(c.times[c.times.length - 1] ?? 0n) / 1e9;
    const ageS = Date.now() / 1e3 - first;
    const spanT = Math.max(...[...tOf.values()]) - Math.min(...[...tOf.values()]);
    check(ageS > -5 && ageS < 600 && Math.abs(last - first - spanT) < 0.05,
          `${c.name}: time starts at the run's wall clock (${ageS.toFixed(1)} s ago) and spans its ${spanT.toFixed(2)} s of machine time (${(last - first).toFixed(2)} s)`);
  }
}
check(garbageStatuses.length >= 4, `garbage client: ${garbageStatuses.length} status replies (${garbageStatuses.map((s) => s.message.slice(0, 30)).join(" | ")})`);
const report = output.split("\n").find((l) => l.includes("foxglove:") && l.includes("clients")) ?? "";
console.log(report);
if (realtime) {
  for (const c of clients) {
    const n = c.messages.filter((m) => m.channel.topic === "/joint_states").length;
    check(n >= 0.95 * rowsByT.size - 5, `${c.name}: ${n} of ${rowsByT.size} cycles on /joint_states`);
  }
  const last = clients[0].messages.filter((m) => m.channel.topic === "/craneassist/status").pop();
  const st = last ? JSON.parse(new TextDecoder().decode(last.data)) : {};
  console.log(`loop: worst start latency ${(1e3 * st.loop_latency_max_s).toFixed(2)} ms, ${st.loop_overruns} overruns`);
} else {
  // The stalled client's queue filled: it lost messages; the run went on at its own pace.
  const dropped = Number((/\((\d+) dropped: a client behind/.exec(report) ?? [0, 0])[1]);
  check(dropped > 0, `the stalled client lost ${dropped} messages`);
  const ran = /ran ([0-9.]+) s of machine time in ([0-9.]+) s/.exec(output);
  check(ran !== null && Number(ran[2]) < Number(ran[1]),
        `the run was not held up: ${ran ? ran[1] : "?"} s of machine time in ${ran ? ran[2] : "?"} s`);
  stalled.ws.terminate();
}
check(/client messages [1-9]\d* malformed, [1-9]\d* unsupported/.test(report), "the server counted the malformed and unsupported messages");
garbage.close();
if (failures > 0) {
  console.log(output);
  console.log(`${failures} FAILED`);
  process.exit(1);
}
console.log(`foxglove ${mode} OK`);
process.exit(0);
