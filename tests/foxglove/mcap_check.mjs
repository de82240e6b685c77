// Reads a craneassist MCAP recording with @mcap/core, as Foxglove and PlotJuggler would, and
// checks it against the CSV log of the same run (docs/foxglove.md):
//   - the indexed reader (footer, summary and its CRC, chunk indexes): the statistics equal the
//     messages read, per channel; every channel has its schema;
//   - the stream reader with every CRC checked (each chunk's), and the data section's CRC
//     (Data End) recomputed over the file;
//   - /joint_states decoded with @foxglove/rosmsg2-serialization from the channel's own ros2msg
//     schema, equal to the CSV's q columns cycle by cycle; the tip twists likewise;
//   - every JSON channel's schema within what Foxglove-class viewers parse (viewer_schema.mjs),
//     and every message valid against it (ajv, draft 2020-12; NaN travels as null);
//   - with --flip: the same file with one byte flipped in a chunk must fail a CRC.
// Usage: node mcap_check.mjs NODE_MODULES FILE.mcap LOG.csv [--flip] [--truncated]
// (NODE_MODULES: the web page's npm packages, where the build installed these readers.)
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";

import { nanAsNull, viewerSchemaProblems } from "./viewer_schema.mjs";

const [modules, file, csvFile, ...flags] = process.argv.slice(2);
const require = createRequire(`${modules}/`);
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { crc32 } = require("@foxglove/crc");
const { parse: parseMsgDef } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const { decompress: zstdDecompress } = require("fzstd");
const Ajv2020 = require("ajv/dist/2020").default;
const fail = (why) => {
  console.error(`mcap_check: FAIL: ${why}`);
  process.exit(1);
};
const decompressHandlers = {
  zstd: (buffer, size) => {
    const out = zstdDecompress(buffer);
    if (out.byteLength !== Number(size)) throw new Error(`zstd: ${out.byteLength} != ${size}`);
    return out;
  },
};

let bytes = new Uint8Array(readFileSync(file));

function streamRecords(data) {
  const reader = new McapStreamReader({ validateCrcs: true, decompressHandlers });
  reader.append(data);
  const records = [];
  for (let r; (r = reader.nextRecord()); ) records.push(r);
  return { records, done: reader.done() };
}

// The integrity checks a reader can make: the stream reader with every chunk CRC, the data
// section CRC of Data End, the indexed reader (summary CRC). Throws naming the first that fails.
async function checkIntegrity(data) {
  const { records, done } = streamRecords(data);
  if (!done) throw new Error("stream reader: did not reach the end magic");
  const dataEnd = records.find((r) => r.type === "DataEnd");
  const view = new DataView(data.buffer, data.byteOffset, data.byteLength);
  const summaryStart = Number(view.getBigUint64(data.length - 8 - 20, true));
  const crc = crc32(data.subarray(0, summaryStart - 13));
  if (!dataEnd || crc !== dataEnd.dataSectionCrc) throw new Error("data section CRC");
  const readable = {
    size: async () => BigInt(data.length),
    read: async (o, n) => data.subarray(Number(o), Number(o + n)),
  };
  const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  for await (const m of indexed.readMessages()) void m;
}

if (flags.includes("--flip")) {
  // One byte flipped: in the first chunk, between chunks (a message index), in the summary.
  const { records } = streamRecords(bytes);
  void records;
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const summaryStart = Number(view.getBigUint64(bytes.length - 8 - 20, true));
  let firstChunk = 8;
  while (bytes[firstChunk] !== 0x06) firstChunk += 9 + Number(view.getBigUint64(firstChunk + 1, true));
  const chunkLength = Number(view.getBigUint64(firstChunk + 1, true));
  const places = {
    "a chunk's records": firstChunk + 9 + Math.floor(chunkLength * 0.8),
    "a message index": firstChunk + 9 + chunkLength + 20,
    "the summary": summaryStart + 40,
  };
  for (const [where, at] of Object.entries(places)) {
    const flipped = bytes.slice();
    flipped[at] ^= 0x40;
    let caught = "";
    try {
      await checkIntegrity(flipped);
    } catch (e) {
      caught = String(e.message ?? e);
    }
    if (!caught) fail(`a byte flipped in ${where} (offset ${at}) passed every check`);
    console.log(`byte flipped in ${where} (offset ${at}): rejected: ${caught.slice(0, 90)}`);
  }
  await checkIntegrity(bytes);
  console.log("mcap flip OK");
  process.exit(0);
}

// The stream reader: every record, every chunk CRC.
const { records, done } = streamRecords(bytes);
const truncated = flags.includes("--truncated");
if (!done && !truncated) fail("the stream reader did not reach the end magic");
const channels = new Map();
const schemas = new Map();
const messages = [];
let dataEndCrc = undefined;
let offset = 8; // after the magic
for (const r of records) {
  if (r.type === "Schema") schemas.set(r.id, r);
  else if (r.type === "Channel") channels.set(r.id, r);
  else if (r.type === "Message") messages.push(r);
  else if (r.type === "DataEnd") dataEndCrc = r.dataSectionCrc;
}
void offset;
if (truncated) {
  if (messages.length === 0) fail("no complete chunk read back from the truncated file");
  console.log(`truncated file: ${messages.length} messages in complete chunks read back`);
}

// The data section's CRC: every byte from the magic to the Data End record.
if (!truncated) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const footerAt = bytes.length - 8 - (1 + 8 + 20);
  const summaryStart = Number(view.getBigUint64(footerAt + 9, true));
  const dataEndAt = summaryStart - (1 + 8 + 4);
  const crc = crc32(bytes.subarray(0, dataEndAt));
  if (dataEndCrc === undefined) fail("no Data End record");
  if (crc !== dataEndCrc) fail(`data section CRC ${crc} != Data End's ${dataEndCrc}`);
  console.log(`data section CRC ${crc.toString(16)}: matches`);

  // The indexed reader: the summary, its CRC, the chunk indexes, the statistics.
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (o, n) => bytes.subarray(Number(o), Number(o + n)),
  };
  const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  const stats = indexed.statistics;
  if (!stats) fail("no Statistics record");
  const counts = new Map();
  let n = 0;
  for await (const m of indexed.readMessages()) {
    counts.set(m.channelId, (counts.get(m.channelId) ?? 0) + 1);
    ++n;
  }
  if (BigInt(n) !== stats.messageCount) fail(`statistics say ${stats.messageCount}, read ${n}`);
  for (const [id, c] of stats.channelMessageCounts) {
    if (BigInt(counts.get(id) ?? 0) !== c) fail(`channel ${id}: statistics ${c}, read ${counts.get(id)}`);
  }
  if (n !== messages.length) fail(`indexed reader ${n} messages, stream reader ${messages.length}`);
  if (indexed.chunkIndexes.length !== stats.chunkCount) fail("chunk indexes != chunk count");
  for (const [id, ch] of indexed.channelsById) {
    if (!indexed.schemasById.get(ch.schemaId)) fail(`channel ${id} ${ch.topic}: no schema`);
  }
  console.log(
    `indexed reader: ${n} messages on ${indexed.channelsById.size} channels in ` +
      `${stats.chunkCount} chunks, statistics equal`,
  );
}

// Decoders from the channels' own schemas.
const topic = (name) => [...channels.values()].find((c) => c.topic === name);
const rosReader = (channel) => {
  const schema = schemas.get(channel.schemaId);
  if (schema.encoding !== "ros2msg") fail(`${channel.topic}: schema encoding ${schema.encoding}`);
  return new MessageReader(parseMsgDef(new TextDecoder().decode(schema.data), { ros2: true }));
};
const byChannel = (c) => messages.filter((m) => m.channelId === c.id);

// The CSV log of the same run.
const csv = readFileSync(csvFile, "utf8").trim().split("\n");
const header = csv[0].split(",");
const rows = csv.slice(1).map((l) => l.split(","));
const col = (name) => {
  const i = header.indexOf(name);
  if (i < 0) fail(`CSV: no column ${name}`);
  return i;
};

const js = topic("/joint_states");
if (!js) fail("no /joint_states");
const jsReader = rosReader(js);
const jsMessages = byChannel(js);
if (!truncated && jsMessages.length !== rows.length) {
  fail(`/joint_states: ${jsMessages.length} messages, the CSV ${rows.length} rows`);
}
// The timeline: the wall clock when the run started plus machine time (not 1970, whether the run
// was real time or faster): the first message within the last hour, then the CSV's t apart.
const t0 = jsMessages.length > 0 ? jsMessages[0].logTime : 0n;
const ageS = Date.now() / 1e3 - Number(t0) / 1e9;
const startText = new Date(Number(t0 / 1000000n)).toISOString();
if (!(ageS >= -5 && ageS < 3600)) fail(`the recording starts ${startText}, not at the run's wall clock`);
console.log(`timeline starts ${startText} (${ageS.toFixed(1)} s ago)`);
let worst = 0;
const dof = header.filter((h) => /^q\d+$/.test(h)).length;
jsMessages.forEach((m, k) => {
  const msg = jsReader.readMessage(m.data);
  if (msg.name.length !== msg.position.length) fail("/joint_states: names and positions differ");
  const t = Number(m.logTime - t0) / 1e9;
  const rowT = Number(rows[k][col("t")]) - Number(rows[0][col("t")]);
  if (!truncated && Math.abs(t - rowT) > 1e-6) fail(`/joint_states ${k}: t ${t}, CSV ${rowT}`);
  for (let i = 0; i < dof; ++i) {
    const q = Number(rows[k][col(`q${i + 1}`)]);
    worst = Math.max(worst, Math.abs(msg.position[i] - q));
  }
});
if (worst > 1e-6) fail(`/joint_states positions differ from the CSV's q by up to ${worst}`);
console.log(`/joint_states: ${jsMessages.length} messages, ${dof} crane joints, |q - CSV| <= ${worst.toExponential(2)}`);

const twist = topic("/craneassist/tip_velocity/reference");
const twistReader = rosReader(twist);
const twistMessages = byChannel(twist);
let speedWorst = 0;
twistMessages.forEach((m, k) => {
  const v = twistReader.readMessage(m.data).twist.linear;
  const speed = Math.hypot(v.x, v.y, v.z);
  const csvSpeed = Math.hypot(...["ref_vx", "ref_vy", "ref_vz"].map((c) => Number(rows[k][col(c)])));
  speedWorst = Math.max(speedWorst, Math.abs(speed - csvSpeed));
});
if (speedWorst > 1e-5) fail(`reference twist speed differs from the CSV by ${speedWorst}`);
console.log(`/craneassist/tip_velocity/reference: ${twistMessages.length} messages, |v| as the CSV (<= ${speedWorst.toExponential(2)})`);

const tf = topic("/tf");
const tfMsg = rosReader(tf).readMessage(byChannel(tf)[0].data);
console.log(`/tf: ${tfMsg.transforms.length} transforms (${tfMsg.transforms.map((t) => t.child_frame_id).join(", ")})`);

const rd = topic("/robot_description");
const urdf = rosReader(rd).readMessage(byChannel(rd)[0].data).data;
if (!urdf.includes("<robot")) fail("/robot_description is not a URDF");
for (const t of tfMsg.transforms) {
  if (!urdf.includes(`"${t.child_frame_id}"`)) fail(`/tf frame ${t.child_frame_id} not in the URDF`);
}

// JSON channels against their schemas.
const ajv = new Ajv2020({ strict: false, allErrors: true });
let jsonChecked = 0;
for (const c of channels.values()) {
  if (c.messageEncoding !== "json") continue;
  const schema = schemas.get(c.schemaId);
  if (schema.encoding !== "jsonschema") fail(`${c.topic}: schema encoding ${schema.encoding}`);
  const parsed = JSON.parse(new TextDecoder().decode(schema.data));
  const problems = viewerSchemaProblems(parsed);
  if (problems.length > 0) fail(`${c.topic}: a Foxglove-class viewer rejects its schema: ${problems}`);
  const validate = ajv.compile(nanAsNull(parsed));
  for (const m of byChannel(c)) {
    const value = JSON.parse(new TextDecoder().decode(m.data));
    if (!validate(value)) fail(`${c.topic}: ${ajv.errorsText(validate.errors)}`);
    ++jsonChecked;
  }
}
console.log(`JSON channels: schemas a viewer reads, ${jsonChecked} messages valid against them`);
console.log(truncated ? "mcap truncated OK" : "mcap OK");
