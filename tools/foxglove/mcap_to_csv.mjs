// Reads a craneassist MCAP recording with @mcap/core (the reader Foxglove uses) and writes, per
// cycle, what the shipped Foxglove layout plots (examples/foxglove/craneassist-layout.json): the
// /craneassist/hydraulics, limits and polytope values and the link origins that /tf puts
// the crane's URDF at (composed from base_link), as one CSV for tools/foxglove/plot_layout.py.
//   node mcap_to_csv.mjs NODE_MODULES FILE.mcap OUT.csv
import { readFileSync, writeFileSync } from "node:fs";
import { createRequire } from "node:module";

const [modules, file, out] = process.argv.slice(2);
const require = createRequire(`${modules}/`);
const { McapIndexedReader } = require("@mcap/core");
const { parse: parseMsgDef } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const { decompress } = require("fzstd");

const bytes = new Uint8Array(readFileSync(file));
const reader = await McapIndexedReader.Initialize({
  readable: { size: async () => BigInt(bytes.length), read: async (o, n) => bytes.subarray(Number(o), Number(o + n)) },
  decompressHandlers: { zstd: (b) => decompress(b) },
});
const topicOf = new Map([...reader.channelsById].map(([id, c]) => [id, c.topic]));
const tfChannel = [...reader.channelsById.values()].find((c) => c.topic === "/tf");
const tfReader = new MessageReader(parseMsgDef(
  new TextDecoder().decode(reader.schemasById.get(tfChannel.schemaId).data), { ros2: true }));

// Quaternion rotation of a vector, and frame composition.
const rotate = (q, v) => {
  const [x, y, z, w] = [q.x, q.y, q.z, q.w];
  const t = [2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])];
  return [v[0] + w * t[0] + (y * t[2] - z * t[1]), v[1] + w * t[1] + (z * t[0] - x * t[2]),
          v[2] + w * t[2] + (x * t[1] - y * t[0])];
};
const mul = (a, b) => ({
  x: a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, y: a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
  z: a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, w: a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
});

const rows = new Map();  // log time -> row
const row = (t) => rows.get(t) ?? rows.set(t, {}).get(t);
const wanted = {
  "/craneassist/hydraulics": ["pump_power_w", "ref_power_w", "power_limit_w", "pump_flow_m3s", "flow_demand_m3s", "flow_limit_m3s"],
  "/craneassist/limits": ["scale", "active_limit"],
  "/craneassist/polytope": ["avail_speed_m_s"],
  "/craneassist/status": ["t"],
};
const frames = ["slew_link", "lift_link", "tilt_link", "extension_link", "tip_link", "grapple_link"];
for await (const m of reader.readMessages()) {
  const topic = topicOf.get(m.channelId);
  if (wanted[topic]) {
    const v = JSON.parse(new TextDecoder().decode(m.data));
    for (const k of wanted[topic]) row(m.logTime)[k] = v[k];
  } else if (topic === "/tf") {
    const pose = new Map([["base_link", { p: [0, 0, 0], q: { x: 0, y: 0, z: 0, w: 1 } }]]);
    for (const tr of tfReader.readMessage(m.data).transforms) {
      const parent = pose.get(tr.header.frame_id);
      if (!parent) continue;
      const t = tr.transform.translation;
      const d = rotate(parent.q, [t.x, t.y, t.z]);
      pose.set(tr.child_frame_id, { p: parent.p.map((x, i) => x + d[i]), q: mul(parent.q, tr.transform.rotation) });
    }
    for (const f of frames) {
      const p = pose.get(f)?.p ?? [NaN, NaN, NaN];
      Object.assign(row(m.logTime), { [`${f}_x`]: p[0], [`${f}_y`]: p[1], [`${f}_z`]: p[2] });
    }
  }
}
const columns = [...new Set([...rows.values()].flatMap((r) => Object.keys(r)))];
const lines = [columns.join(",")];
for (const [, r] of [...rows].sort((a, b) => (a[0] < b[0] ? -1 : 1))) {
  lines.push(columns.map((c) => (r[c] ?? "")).join(","));
}
writeFileSync(out, lines.join("\n") + "\n");
console.log(`${out}: ${rows.size} cycles, ${columns.length} columns from ${file}`);
