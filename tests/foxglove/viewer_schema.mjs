// The JSON Schema that Foxglove-class viewers (Foxglove, Lichtblick) read for a channel with
// schemaEncoding "jsonschema", as their parser behaves (Lichtblick's parseJsonSchema, read for its
// behaviour; docs/foxglove.md#json-channels-in-a-viewer). A schema outside this subset makes the
// viewer drop the whole channel ("Unsupported type ... for t"), so every panel on it stays empty.
//
// The subset:
//   - the root is {"type": "object"} with "properties";
//   - each property's "type" is one string: "boolean", "number", "integer", "string" (without
//     "contentEncoding", or "base64"), "object" (the same rules inside) or "array";
//   - an array's "items" is one schema whose "type" is "boolean", "number", "integer", "string"
//     (without "contentEncoding") or "object" (the same rules inside): no arrays of arrays;
//   - a property with "oneOf" is an enumeration: every alternative a {"const": number, "title"};
//   - no type lists (["number","null"]), no "null", no missing type: rejected.
// And what a message path (a Plot panel's `/topic.field[1].x`) needs: property names that are
// identifiers ([A-Za-z_][A-Za-z0-9_]*).
//
// As a module: viewerSchemaProblems(schema) lists what a viewer would reject (empty: it reads it);
// nanAsNull(schema) is the schema with every number admitting null, for checking messages under
// craneassist's NaN rule (NaN travels as null; the schemas say "number").
// As a command (CTest foxglove_viewer_schema):
//   node viewer_schema.mjs CRANEASSIST
// checks its own rules on schemas a viewer is known to reject or read, then every group schema
// that `CRANEASSIST fields --schema GROUP` prints; prints "viewer schema OK" when all pass.
import { execFileSync } from "node:child_process";
import { fileURLToPath } from "node:url";

const kScalars = new Set(["boolean", "number", "integer", "string"]);
const kIdentifier = /^[A-Za-z_][A-Za-z0-9_]*$/;

function isPlainObject(v) {
  return v !== null && typeof v === "object" && !Array.isArray(v);
}

function checkString(s, path, problems, allowBase64) {
  if (s.contentEncoding === undefined) return;
  if (allowBase64 && s.contentEncoding === "base64") return;
  problems.push(`${path}: unsupported contentEncoding ${JSON.stringify(s.contentEncoding)}`);
}

function checkObject(schema, path, problems) {
  if (!isPlainObject(schema)) {
    problems.push(`${path}: not a schema object`);
    return;
  }
  if (schema.type !== "object") {
    problems.push(`${path}: expected "type": "object", got ${JSON.stringify(schema.type)}`);
    return;
  }
  const properties = schema.properties ?? {};
  if (!isPlainObject(properties)) {
    problems.push(`${path}: "properties" is not an object`);
    return;
  }
  for (const [name, field] of Object.entries(properties)) {
    const at = path === "" ? name : `${path}.${name}`;
    if (!kIdentifier.test(name)) problems.push(`${at}: not an identifier a message path can name`);
    if (!isPlainObject(field)) {
      problems.push(`${at}: not a schema object`);
      continue;
    }
    if (Array.isArray(field.oneOf)) {
      if (!field.oneOf.every((a) => isPlainObject(a) && typeof a.const === "number")) {
        problems.push(`${at}: oneOf alternatives must each be a number "const"`);
      }
      continue;
    }
    checkField(field, at, problems);
  }
}

function checkField(field, at, problems) {
  const type = field.type;
  if (typeof type !== "string") {
    problems.push(`${at}: unsupported type ${JSON.stringify(type)} (one string per field)`);
    return;
  }
  if (type === "object") {
    checkObject(field, at, problems);
    return;
  }
  if (type === "array") {
    const items = field.items;
    if (!isPlainObject(items)) {
      problems.push(`${at}: an array needs one "items" schema`);
      return;
    }
    if (items.type === "object") {
      checkObject(items, `${at}[]`, problems);
    } else if (typeof items.type === "string" && kScalars.has(items.type)) {
      if (items.type === "string") checkString(items, `${at}[]`, problems, false);
    } else {
      problems.push(`${at}[]: unsupported type ${JSON.stringify(items.type)} for array items`);
    }
    return;
  }
  if (!kScalars.has(type)) {
    problems.push(`${at}: unsupported type ${JSON.stringify(type)}`);
    return;
  }
  if (type === "string") checkString(field, at, problems, true);
}

export function viewerSchemaProblems(schema) {
  const problems = [];
  checkObject(schema, "", problems);
  return problems;
}

// A copy of `schema` in which every {"type": "number"} also admits null.
export function nanAsNull(schema) {
  if (Array.isArray(schema)) return schema.map(nanAsNull);
  if (!isPlainObject(schema)) return schema;
  const out = {};
  for (const [k, v] of Object.entries(schema)) out[k] = nanAsNull(v);
  if (schema.type === "number") out.type = ["number", "null"];
  return out;
}

// --- the command --------------------------------------------------------------------------------

function selfTest() {
  const obj = (properties) => ({ type: "object", properties });
  const rejected = [
    [obj({ t: { type: ["number", "null"] } }), /t: unsupported type \["number","null"\]/],
    [obj({ t: { type: "null" } }), /t: unsupported type "null"/],
    [obj({ t: { description: "no type" } }), /t: unsupported type undefined/],
    [obj({ q: { type: "array", items: { type: ["number", "null"] } } }), /q\[\]: unsupported type/],
    [obj({ m: { type: "array", items: { type: "array", items: { type: "number" } } } }), /m\[\]/],
    [obj({ q: { type: "array" } }), /q: an array needs one "items"/],
    [obj({ v: { type: "object", properties: { x: { type: ["number", "null"] } } } }), /v\.x:/],
    [obj({ s: { type: "string", contentEncoding: "base32" } }), /s: unsupported contentEncoding/],
    [obj({ e: { oneOf: [{ const: "a" }] } }), /e: oneOf/],
    [obj({ "pump-flow": { type: "number" } }), /pump-flow: not an identifier/],
    [{ type: ["object"], properties: {} }, /expected "type": "object"/],
    [{ anyOf: [{ type: "object" }] }, /expected "type": "object"/],
  ];
  for (const [schema, expected] of rejected) {
    const problems = viewerSchemaProblems(schema).join("; ");
    if (!expected.test(problems)) {
      throw new Error(`self-test: ${JSON.stringify(schema)} gave "${problems}", expected ${expected}`);
    }
  }
  const read = [
    obj({}),
    obj({ t: { type: "number" }, n: { type: "integer", minimum: 0 }, b: { type: "boolean" } }),
    obj({ s: { type: "string" }, d: { type: "string", contentEncoding: "base64" } }),
    obj({ q: { type: "array", items: { type: "number" } }, v: obj({ x: { type: "number" } }) }),
    obj({ a: { type: "array", items: obj({ x: { type: "number" } }) } }),
    obj({ e: { oneOf: [{ title: "A", const: 0 }, { title: "B", const: 1 }] } }),
  ];
  for (const schema of read) {
    const problems = viewerSchemaProblems(schema);
    if (problems.length > 0) throw new Error(`self-test: ${JSON.stringify(schema)}: ${problems}`);
  }
  const relaxed = nanAsNull(obj({ q: { type: "array", items: { type: "number" } } }));
  if (JSON.stringify(relaxed.properties.q.items.type) !== '["number","null"]') {
    throw new Error("self-test: nanAsNull");
  }
  return rejected.length + read.length;
}

function main() {
  const craneassist = process.argv[2];
  if (!craneassist) {
    console.error("usage: node viewer_schema.mjs CRANEASSIST");
    process.exit(2);
  }
  const cases = selfTest();
  console.log(`self-test: ${cases} schemas judged as a viewer judges them`);
  // The group names: the --schema option's choices, from the CLI's own error.
  let groups;
  try {
    execFileSync(craneassist, ["fields", "--schema", "?"], { stdio: "pipe" });
  } catch (e) {
    const m = /\{([^}]*)\}/.exec(String(e.stderr) + String(e.stdout));
    groups = m ? m[1].split(",").map((g) => g.trim()) : [];
  }
  if (!groups || groups.length < 7) throw new Error(`could not list the groups: ${groups}`);
  let bad = 0;
  for (const g of groups) {
    const schema = JSON.parse(execFileSync(craneassist, ["fields", "--schema", g]).toString());
    const problems = viewerSchemaProblems(schema);
    const fields = Object.keys(schema.properties ?? {}).length;
    if (problems.length > 0) {
      bad += 1;
      console.log(`/craneassist/${g}: a viewer rejects it: ${problems.join("; ")}`);
    } else {
      console.log(`/craneassist/${g}: ${fields} fields, read by a viewer`);
    }
  }
  if (bad > 0) {
    console.log(`viewer schema FAIL: ${bad} of ${groups.length} group schemas`);
    process.exit(1);
  }
  console.log(`viewer schema OK: ${groups.length} group schemas`);
}

if (process.argv[1] === fileURLToPath(import.meta.url)) main();
