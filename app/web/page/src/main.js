// The page of `craneassist sim --web` (docs/web.md): the crane in 3-D from the streamed joint
// frames, gauges and live plots of the run, and a virtual joystick that is a gamepad to the
// simulator (the same mapping and safety rules as a physical pad).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { Plot } from './plot.js';
import { Stick } from './stick.js';

const $ = (id) => document.getElementById(id);
const token = new URLSearchParams(location.search).get('token') || '';

// What the tests and the curious read (window.craneassist).
const probe = {
  frames: 0,          // frame messages received
  drawn: 0,           // animation frames drawn with new data
  last: null,         // the latest frame message
  command: 'none',    // 'available', 'view', 'yours', 'refused'
  link: 'connecting',
  rate_hz: 0,         // frames per second received, over the last second
  latency_ms: [],     // stick move -> first drawn frame whose command moved
  sent: 0,            // stick states sent
  shown: null,        // the frame the gauges show
  avail_arrow: null,  // the available-speed arrow: { length, dir } (null: hidden)
  grapple: null,      // the drawn grapple: { at, tip, swing } in the crane frame (null: none hangs)
  swing_max: 0,       // the largest swing drawn, deg
};
window.craneassist = probe;

// ---------------------------------------------------------------------------------------------
// The 3-D view.
const view = $('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x15181c);
const camera = new THREE.PerspectiveCamera(45, 1, 0.05, 200);
camera.position.set(6, 5, 9);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(3, 1, 0);
controls.update();
// Drawn when something changed (new data, the camera turned, the window resized), not at the
// display's rate: software WebGL on a busy machine must not starve the stick's messages.
let needsRender = true;
controls.addEventListener('change', () => { needsRender = true; });
scene.add(new THREE.HemisphereLight(0xdde8ff, 0x303030, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(5, 10, 6);
scene.add(sun);
const grid = new THREE.GridHelper(20, 20, 0x3a434d, 0x262c33);
scene.add(grid);
scene.add(new THREE.AxesHelper(0.6));

const steel = new THREE.MeshStandardMaterial({ color: 0xd9a021, metalness: 0.3, roughness: 0.6 });
const dark = new THREE.MeshStandardMaterial({ color: 0x3b4148, metalness: 0.4, roughness: 0.5 });
const unitCylinder = new THREE.CylinderGeometry(1, 1, 1, 20);
const unitBox = new THREE.BoxGeometry(1, 1, 1);

// A mesh stretched between two points (a unit shape along y, scaled and turned).
function place(mesh, a, b, width) {
  const d = new THREE.Vector3().subVectors(b, a);
  const len = Math.max(d.length(), 1e-6);
  mesh.position.copy(a).addScaledVector(d, 0.5);
  mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), d.divideScalar(len));
  mesh.scale.set(width, len, width);
}

// The crane's own frame: the view's on a fixed base; on a wheeled base (sim --drive) placed by
// the frame's base.root_r, base.root_p (drawBase).
const craneRoot = new THREE.Group();
craneRoot.matrixAutoUpdate = false;
scene.add(craneRoot);

const links = [];        // pillar, booms, telescope
const cylinders = [];    // hydraulic cylinders, one per drawn cylinder
const trail = { points: [], max: 900 };
const trailGeometry = new THREE.BufferGeometry();
trailGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(trail.max * 3), 3));
const trailLine = new THREE.Line(trailGeometry, new THREE.LineBasicMaterial({ color: 0x4a9be8 }));
scene.add(trailLine);
const cmdArrow = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 0.01, 0x4caf7a);
const refArrow = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 0.01, 0xe0a030);
// The speed the hydraulics allow along the stick (the flow polytope's reach), on the same scale
// as the command: drawn first and without depth, so the command's arrow shows over it.
const availArrow = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 0.01, 0xb8c2cc);
for (const part of [availArrow.line, availArrow.cone]) {
  part.material.depthWrite = false;
  part.renderOrder = -1;
}
craneRoot.add(cmdArrow, refArrow, availArrow);
const arrowLength = (speed) => 0.3 + 2 * speed;  // 0.5 m/s: 1.3 m
// The last stick direction, along which the available speed is (before any: forward, as the
// controller takes it).
const stickDir = new THREE.Vector3(1, 0, 0);
const tipMarker = new THREE.Mesh(new THREE.SphereGeometry(0.07, 16, 12), dark);
craneRoot.add(tipMarker);
// The hanging grapple (docs/sway.md): its link from the tip and the grapple, where the frame
// says its centre of mass hangs.
const grappleLink = new THREE.Mesh(unitCylinder, dark);
const grappleBody = new THREE.Mesh(unitBox, new THREE.MeshStandardMaterial({ color: 0xc98a2e, metalness: 0.4, roughness: 0.5 }));
grappleLink.visible = grappleBody.visible = false;
craneRoot.add(grappleLink, grappleBody);

function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  needsRender = true;
}
window.addEventListener('resize', resize);

const vec = (p) => new THREE.Vector3(p[0], p[1], p[2]);
const pressureColor = new THREE.Color();

function drawCrane(frame) {
  if (!frame.points) return;
  const pts = frame.points.map(vec);
  // Links between consecutive joint frames that are apart (DH frames can coincide).
  let k = 0;
  for (let i = 0; i + 1 < pts.length; ++i) {
    if (pts[i].distanceTo(pts[i + 1]) < 1e-3) continue;
    if (!links[k]) {
      links[k] = new THREE.Mesh(k === 0 ? unitCylinder : unitBox, k === 0 ? dark : steel);
      craneRoot.add(links[k]);
    }
    place(links[k], pts[i], pts[i + 1], k === 0 ? 0.16 : 0.14 - 0.02 * Math.min(k, 3));
    ++k;
  }
  for (const c of frame.cylinders || []) {
    let m = cylinders[c.joint];
    if (!m) {
      m = cylinders[c.joint] = new THREE.Mesh(unitCylinder,
        new THREE.MeshStandardMaterial({ color: 0x4a9be8, metalness: 0.6, roughness: 0.3 }));
      craneRoot.add(m);
    }
    place(m, vec(c.a), vec(c.b), crane ? Math.max(0.03, crane.cylinders[c.joint].bore_m * 0.6) : 0.05);
    const p = frame.p_load ? frame.p_load[c.joint] : 0;
    const x = crane && p !== null ? Math.min(Math.abs(p) / crane.pump.max_pressure_pa, 1) : 0;
    pressureColor.setHSL(0.62 * (1 - x), 0.75, 0.5);
    m.material.color.copy(pressureColor);
  }
  const tip = vec(frame.tip);
  tipMarker.position.copy(tip);
  const g = frame.grapple;
  grappleLink.visible = grappleBody.visible = !!(g && g.at.every((x) => x !== null));
  probe.grapple = null;
  if (grappleLink.visible) {
    const at = vec(g.at);
    place(grappleLink, tip, at, 0.04);
    // The grapple's body hangs along the link, centred where its centre of mass is.
    const d = at.clone().sub(tip);
    place(grappleBody, at.clone().addScaledVector(d, -0.35), at.clone().addScaledVector(d, 0.35), 0.3);
    probe.grapple = { at: g.at, tip: frame.tip, swing: g.swing };
    probe.swing_max = Math.max(probe.swing_max, g.swing || 0);
  }
  trail.points.push(tip.clone().applyMatrix4(craneRoot.matrix));  // the trail on the ground
  if (trail.points.length > trail.max) trail.points.shift();
  const pos = trailGeometry.attributes.position;
  trail.points.forEach((p, i) => pos.setXYZ(i, p.x, p.y, p.z));
  pos.needsUpdate = true;
  trailGeometry.setDrawRange(0, trail.points.length);
  for (const [arrow, v] of [[cmdArrow, frame.cmd], [refArrow, frame.ref]]) {
    const d = vec(v);
    const speed = d.length();
    arrow.visible = speed > 1e-3;
    if (arrow.visible) {
      arrow.position.copy(tip);
      arrow.setDirection(d.divideScalar(speed));
      arrow.setLength(arrowLength(speed), 0.15, 0.08);
    }
  }
  if (frame.cmd.every((x) => x !== null) && norm(frame.cmd) > 1e-3) stickDir.copy(vec(frame.cmd)).normalize();
  availArrow.visible = frame.avail > 1e-3;
  probe.avail_arrow = null;
  if (availArrow.visible) {
    availArrow.position.copy(tip);
    availArrow.setDirection(stickDir);
    availArrow.setLength(arrowLength(frame.avail), 0.15, 0.08);
    probe.avail_arrow = { length: arrowLength(frame.avail), dir: stickDir.toArray() };
  }
}

// The wheeled base (sim --drive, docs/mobile.md#live): the chassis and wheels as boxes the
// server places, the crane's frame on it. Without a base the crane's frame is the view's.
const chassisMaterial = new THREE.MeshStandardMaterial({ color: 0x5d7a3a, metalness: 0.2, roughness: 0.7 });
const baseBoxes = [];
const baseTrail = { points: [], max: 3000 };
const baseTrailGeometry = new THREE.BufferGeometry();
baseTrailGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(baseTrail.max * 3), 3));
scene.add(new THREE.Line(baseTrailGeometry, new THREE.LineBasicMaterial({ color: 0x8fbf5a })));

function drawBase(frame) {
  const b = frame.base;
  baseBoxes.forEach((m) => { m.visible = false; });
  if (!b || !b.root_r) {
    craneRoot.matrix.identity();
    return;
  }
  const r = b.root_r, p = b.root_p;
  craneRoot.matrix.set(r[0], r[1], r[2], p[0], r[3], r[4], r[5], p[1], r[6], r[7], r[8], p[2], 0, 0, 0, 1);
  b.boxes.forEach((box, i) => {
    let m = baseBoxes[i];
    if (!m) {
      m = baseBoxes[i] = new THREE.Mesh(unitBox, box.kind === 'wheel' ? dark : chassisMaterial);
      m.matrixAutoUpdate = false;
      scene.add(m);
    }
    const q = box.r, c = box.p, s = box.size;
    m.matrix.set(q[0] * s[0], q[1] * s[1], q[2] * s[2], c[0], q[3] * s[0], q[4] * s[1], q[5] * s[2], c[1],
      q[6] * s[0], q[7] * s[1], q[8] * s[2], c[2], 0, 0, 0, 1);
    m.visible = true;
  });
  const centre = vec(b.boxes[0].p);
  const last = baseTrail.points[baseTrail.points.length - 1];
  if (!last || last.distanceTo(centre) > 0.05) {
    baseTrail.points.push(centre);
    if (baseTrail.points.length > baseTrail.max) baseTrail.points.shift();
    const pos = baseTrailGeometry.attributes.position;
    baseTrail.points.forEach((v, i) => pos.setXYZ(i, v.x, 0.01, v.z));
    pos.needsUpdate = true;
    baseTrailGeometry.setDrawRange(0, baseTrail.points.length);
  }
}

function showBase(f) {
  const b = f.base;
  $('base-panel').hidden = !b;
  if (!b) return;
  const pumpFlow = b.flow_sum + (b.shared_pump ? f.pump.flow : 0);
  gauge('drive', pumpFlow, b.flow_max,
    `${fmt(pumpFlow * 6e4, 1)} / ${fmt(b.flow_max * 6e4, 0)} L/min${b.shared_pump ? ' (motors + crane)' : ''}`);
  $('base-pose').textContent =
    `x ${fmt(b.pose[0])} y ${fmt(b.pose[1])} m · ${fmt(b.pose[2] * 180 / Math.PI, 0)}° · ${fmt(b.velocity[0])} m/s`;
}

// ---------------------------------------------------------------------------------------------
// Gauges and plots.
let crane = null;
const plotPump = new Plot($('plot-pump'), [
  { label: 'power / limit', color: '#e0a030' },
  { label: 'flow / limit', color: '#4a9be8' },
], { min: 0, max: 1.1, limitLine: 1 });
const plotSpeed = new Plot($('plot-speed'), [
  { label: 'tip speed m/s', color: '#4caf7a' },
  { label: 'command m/s', color: '#8a939c' },
  { label: 'scale', color: '#c070e0' },
], { min: 0, max: 1.2 });

function gauge(name, value, limit, text) {
  const f = limit > 0 && value !== null ? Math.min(Math.max(value / limit, 0), 1) : 0;
  const bar = $(name + '-bar');
  bar.style.width = (100 * f).toFixed(1) + '%';
  bar.className = 'fill' + (f >= 0.98 ? ' full' : f >= 0.85 ? ' high' : '');
  $(name + '-text').textContent = text;
}

function cylinderGauges() {
  const box = $('cylinders');
  box.innerHTML = '';
  crane.joints.forEach((j, i) => {
    const name = crane.cylinders[i] ? crane.cylinders[i].name : j.name;
    box.insertAdjacentHTML('beforeend',
      `<div class="gauge"><div class="row"><span>${name}</span><span id="cyl${i}-text">-</span></div>` +
      `<div class="bar"><div id="cyl${i}-bar" class="fill"></div></div></div>`);
  });
}

const norm = (v) => Math.hypot(v[0], v[1], v[2]);
const fmt = (v, d = 2) => (v === null || v === undefined ? '-' : v.toFixed(d));
// The flow polytope's measure in its dimension's unit: a solid's volume, a flat one's area (a
// planar arm, a singular pose).
function polytopeText(p) {
  const sig = (v) => (v === null ? '-' : String(Number(v.toPrecision(4))));
  if (p.dim === 3) return `volume ${sig(p.volume)} m³/s³`;
  if (p.dim === 2) return `area ${sig(p.area)} m²/s² (flat)`;
  return `dimension ${p.dim}: no motion across it`;
}

// "All values": every field of the frame's field table (crane.json's "fields": name, unit, group,
// meaning), a row per field, filled while the list is open.
let fieldCells = null;
function showFields(f) {
  if (!crane || !crane.fields || !f.fields || !$('all-values').open) return;
  const table = $('fields-table');
  if (fieldCells === null) {
    fieldCells = new Map();
    for (const d of crane.fields) {
      const tr = document.createElement('tr');
      tr.title = d.meaning;
      const name = document.createElement('td');
      name.textContent = `${d.group}.${d.name}`;
      const value = document.createElement('td');
      const unit = document.createElement('td');
      unit.textContent = d.unit;
      tr.append(name, value, unit);
      table.append(tr);
      fieldCells.set(`${d.group}.${d.name}`, value);
    }
  }
  const show = (v) => (v === null ? '-' : typeof v === 'number' ? (Number.isInteger(v) ? String(v) : v.toPrecision(4))
    : Array.isArray(v) ? v.map(show).join(' ') : typeof v === 'object' ? Object.values(v).map(show).join(' ')
    : String(v));
  for (const [group, values] of Object.entries(f.fields)) {
    for (const [name, v] of Object.entries(values)) {
      const cell = fieldCells.get(`${group}.${name}`);
      if (cell) cell.textContent = show(v);
    }
  }
}

function showFrame(f) {
  showFields(f);
  $('t').textContent = fmt(f.t, 1);
  $('tip').textContent = f.tip.map((v) => fmt(v)).join(' ');
  $('speed').textContent = fmt(norm(f.tip_v));
  const st = $('run-status');
  st.textContent = f.status;
  st.className = 'pill ' + (f.status === 'running' ? 'ok' : f.status === 'stopping' ? 'warn' : 'bad');
  $('stop-reason').textContent = f.stop_reason;
  $('input').textContent = `${f.input} · deadman ${f.deadman ? 'on' : 'off'}`;
  if (crane) {
    const p = crane.pump;
    gauge('power', f.pump.power, p.max_power_w, `${fmt(f.pump.power / 1e3, 1)} / ${fmt(p.max_power_w / 1e3, 1)} kW`);
    gauge('flow', f.pump.flow, p.max_flow_m3s, `${fmt(f.pump.flow * 6e4, 1)} / ${fmt(p.max_flow_m3s * 6e4, 0)} L/min`);
    gauge('pressure', f.pump.pressure, p.max_pressure_pa, `${fmt(f.pump.pressure / 1e5, 0)} / ${fmt(p.max_pressure_pa / 1e5, 0)} bar`);
    f.p_load.forEach((v, i) => gauge('cyl' + i, v === null ? null : Math.abs(v), p.max_pressure_pa,
      v === null ? '-' : `${fmt(v / 1e5, 0)} bar`));
    plotPump.push(f.t, [f.pump.power / p.max_power_w, f.pump.flow / p.max_flow_m3s]);
  }
  const lim = $('limit');
  lim.textContent = f.limit || 'none';
  lim.className = 'pill' + (f.limit && f.limit !== 'none' ? ' warn' : '');
  $('scale').textContent = fmt(f.scale);
  $('sdot').textContent = `${fmt(f.sdot)} m/s`;
  // The stick's speed against what the hydraulics allow along it (null: no valid input).
  const stick = f.cmd.every((x) => x !== null) ? norm(f.cmd) : null;
  gauge('avail', stick, f.avail, `${fmt(stick)} / ${fmt(f.avail)} m/s`);
  $('avail-resolved').textContent = `${fmt(f.avail_resolved)} m/s`;
  $('polytope').textContent = polytopeText(f.polytope);
  // The crane scale and the load moment against the chart (docs/loads.md).
  if (f.load) {
    const l = f.load;
    const truth = l.truth === null || l.truth === undefined ? '' : ` (simulated ${fmt(l.truth, 0)} kg)`;
    $('scale-load').textContent =
      `${fmt(l.estimate, 0)} kg ${l.converged ? 'weighed' : 'weighing: rated load assumed'}${truth}`;
    if (l.rated > 0) {
      gauge('moment', l.ratio, 1.0, `${fmt(l.ratio * 100, 0)} % of ${fmt(l.rated, 0)} kg` +
        (l.overload ? ' · OVERLOAD' : l.warning ? ' · WARNING' : ''));
      $('moment-bar').className = 'fill' + (l.overload ? ' full' : l.warning ? ' high' : '');
    } else {
      $('moment-text').textContent = 'no load chart';
    }
    probe.load = l;
  }
  // The grapple's swing from the vertical (docs/sway.md).
  const g = f.grapple;
  $('swing').textContent = g && g.swing !== null
    ? `${fmt(g.swing, 1)} deg (out ${fmt(g.radial, 1)}, across ${fmt(g.tangential, 1)})` : 'not measured';
  probe.shown = f;
  plotSpeed.push(f.t, [norm(f.tip_v), norm(f.cmd), f.scale]);
}

$('pause').addEventListener('click', () => {
  const paused = !plotPump.paused;
  for (const p of [plotPump, plotSpeed]) p.setPaused(paused);
  $('pause').textContent = paused ? 'resume' : 'pause';
  $('scroll').disabled = !paused;
  $('scroll').value = 1000;
});
$('scroll').addEventListener('input', (e) => {
  for (const p of [plotPump, plotSpeed]) p.setScroll(Number(e.target.value) / 1000);
});

// ---------------------------------------------------------------------------------------------
// The virtual joystick: two sticks, a deadman, or a gamepad through the Gamepad API.
const left = new Stick($('stick-left'));
const right = new Stick($('stick-right'));
const deadmanButton = $('deadman');
let deadman = false;
const setDeadman = (on) => {
  deadman = on;
  deadmanButton.classList.toggle('held', on);
  deadmanButton.textContent = on ? 'ON' : 'hold';
};
deadmanButton.addEventListener('pointerdown', (e) => { deadmanButton.setPointerCapture(e.pointerId); setDeadman(true); });
for (const ev of ['pointerup', 'pointercancel', 'lostpointercapture']) {
  deadmanButton.addEventListener(ev, () => setDeadman(false));
}
// Tests: window.craneassist.stick('left', x, y), .deadman(true)
probe.stick = (which, x, y) => (which === 'left' ? left : right).set(x, y);
probe.deadman = setDeadman;

// The pad state as the simulator's gamepad mapping reads it: left_x, left_y, right_x, right_y,
// left_trigger, right_trigger; sticks report forward as negative, as real pads do.
function padState() {
  const pads = navigator.getGamepads ? [...navigator.getGamepads()].filter((g) => g && g.mapping === 'standard') : [];
  const g = pads[0];
  if (g && (g.buttons[5].pressed || g.axes.some((a) => Math.abs(a) > 0.15))) {
    return { axes: [g.axes[0], g.axes[1], g.axes[2], g.axes[3], 0, 0].map((a) => Math.max(-1, Math.min(1, a))),
      deadman: g.buttons[5].pressed, source: 'gamepad' };
  }
  return { axes: [left.x, -left.y, right.x, -right.y, 0, 0], deadman, source: 'screen' };
}

// ---------------------------------------------------------------------------------------------
// The connection: frames in, stick states out every 20 ms while this page may command.
let socket = null;
let fresh = null;
let moveStarted = null;  // when the stick left the centre, for the latency figure
let wasCentred = true;
const arrivals = [];

function setLink(state) {
  probe.link = state;
  const el = $('link');
  el.textContent = state;
  el.className = 'pill ' + (state === 'connected' ? 'ok' : state === 'connecting' ? 'warn' : 'bad');
}
function setCommand(state, why) {
  probe.command = state;
  const el = $('command');
  el.textContent = { available: 'available', view: 'view only', yours: 'yours', refused: 'refused' }[state] || state;
  el.className = 'pill ' + (state === 'yours' ? 'ok' : state === 'refused' || state === 'view' ? 'bad' : '');
  if (why) $('status').textContent = why;
}

function connect() {
  const url = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws?token=${encodeURIComponent(token)}`;
  socket = new WebSocket(url);
  setLink('connecting');
  socket.onopen = () => setLink('connected');
  socket.onclose = () => {
    setLink('disconnected');
    setCommand('none', 'The run has ended or the server went away. Reload to reconnect.');
  };
  socket.onmessage = (e) => {
    const m = JSON.parse(e.data);
    if (m.type === 'frame') {
      fresh = m;
      probe.frames += 1;
      probe.last = m;
      const now = performance.now();
      arrivals.push(now);
      while (arrivals.length && now - arrivals[0] > 1000) arrivals.shift();
      probe.rate_hz = arrivals.length;
    } else if (m.type === 'hello') {
      setCommand(m.command);
    } else if (m.type === 'command') {
      setCommand(m.state, m.why);
    }
  };
}

setInterval(() => {
  if (!socket || socket.readyState !== WebSocket.OPEN) return;
  if (probe.command !== 'available' && probe.command !== 'yours') return;  // not until hello
  if (document.visibilityState === 'hidden') return;  // a hidden page goes stale: the crane stops
  const s = padState();
  const centred = s.axes.every((a) => Math.abs(a) < 0.2);
  if (wasCentred && !centred) moveStarted = performance.now();
  wasCentred = centred;
  socket.send(JSON.stringify({ type: 'pad', axes: s.axes, deadman: s.deadman }));
  probe.sent += 1;
}, 20);

// ---------------------------------------------------------------------------------------------
function animate() {
  requestAnimationFrame(animate);
  if (fresh) {
    drawBase(fresh);
    drawCrane(fresh);
    showFrame(fresh);
    showBase(fresh);
    probe.drawn += 1;
    if (moveStarted !== null && norm(fresh.cmd) > 1e-3) {
      probe.latency_ms.push(performance.now() - moveStarted);
      moveStarted = null;
    }
    fresh = null;
    $('rate').textContent = `${probe.rate_hz} frames/s`;
    needsRender = true;
  }
  if (needsRender) {
    renderer.render(scene, camera);
    needsRender = false;
  }
  plotPump.draw();
  plotSpeed.draw();
}

fetch('crane.json').then((r) => r.json()).then((c) => {
  crane = c;
  probe.crane = c;
  $('crane-name').textContent = c.name;
  document.title = `craneassist · ${c.name}`;
  cylinderGauges();
});
resize();
connect();
animate();
