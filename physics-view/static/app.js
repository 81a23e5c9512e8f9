// physics-view page: polls the viewer's JSON API at display rate and draws the chosen plane
// with three.js (3D planes) or a 2D canvas in pixel space (GUI planes). What it shows is also
// written into data- attributes of #view (plane, kind, tick, body count, bodies with their
// poses, meshes drawn, joints drawn) so a headless browser can check the page through the DOM.
// Joints are drawn as lines between their anchors (dashed and faded once broken). With
// `physics-view --replay FILE` a timeline drives the replay plane (play, pause, step, jump to
// a tick, speed) and the recorded rays of the current tick are drawn; the timeline's state
// goes into data-replay-* attributes, and each rendered frame of the replay plane into a
// coarse grid of its pixels' luminance with the bodies' screen positions.
import * as THREE from '/static/three.module.min.js';

const $ = (id) => document.getElementById(id);
const view = $('view');
const glCanvas = $('gl');
const canvas2d = $('c2d');
const params = new URLSearchParams(location.search);
let selected = params.has('plane') ? Number(params.get('plane')) : null;
let allowControl = false;
let snapshot = null;
let selectedSlot = null;
let frames = 0;
let drawnSelection = null;
let replayPlane = null; // the plane of --replay, when replaying
let sliding = false; // the timeline's slider is being dragged

const COLORS = {
  awake: 0xe0894a, sleeping: 0x5b79c9, anchored: 0x8a8f98, controller: 0x3cc47c,
  contact: 0xff3b6b, selected: 0xffe066, ray: 0x4cc9f0, joint: 0xc77dff,
};
const css = (c) => '#' + c.toString(16).padStart(6, '0');

async function getJSON(url, options) {
  const r = await fetch(url, options);
  const body = await r.json().catch(() => ({ error: r.statusText }));
  if (!r.ok) throw new Error(body.error || r.statusText);
  return body;
}

// ---------------------------------------------------------------- 3D (three.js)
let renderer = null;
try {
  renderer = new THREE.WebGLRenderer({ canvas: glCanvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  view.dataset.renderer = 'webgl';
} catch (e) {
  view.dataset.renderer = 'none';
  view.dataset.renderError = String(e);
}
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x15181d);
const camera = new THREE.PerspectiveCamera(50, 1, 0.05, 100000);
camera.position.set(12, 10, 18);
const controls = new THREE.OrbitControls(camera, glCanvas);
controls.enableDamping = true;
// Frames are drawn only when something changed (a new tick, the camera moved): an idle page
// costs nothing.
let dirty = true;
controls.addEventListener('change', () => { dirty = true; });
scene.add(new THREE.HemisphereLight(0xdfe8ff, 0x30343a, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(30, 60, 20);
scene.add(sun);
const grid = new THREE.GridHelper(200, 200, 0x39404b, 0x252a32);
scene.add(grid);
const bodyGroup = new THREE.Group();
scene.add(bodyGroup);
const overlayGroup = new THREE.Group();
scene.add(overlayGroup);
const meshes = new Map(); // "slot:generation" -> mesh
let fittedPlane = null;

function wedgeGeometry(x, y, z) {
  // Cross-section in YZ: (-y/2,-z/2), (-y/2,+z/2), (+y/2,+z/2), extruded over x.
  const hx = x / 2, hy = y / 2, hz = z / 2;
  const v = [
    [-hx, -hy, -hz], [-hx, -hy, hz], [-hx, hy, hz],
    [hx, -hy, -hz], [hx, -hy, hz], [hx, hy, hz],
  ];
  const faces = [
    [0, 2, 1], [3, 4, 5], // the two triangular sides
    [0, 1, 4], [0, 4, 3], // bottom
    [1, 2, 5], [1, 5, 4], // back
    [0, 3, 5], [0, 5, 2], // slope
  ];
  const pos = [];
  for (const f of faces) for (const i of f) pos.push(...v[i]);
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
  g.computeVertexNormals();
  return g;
}

function geometryFor(b) {
  const [x, y, z] = b.size;
  switch (b.shape) {
    case 'Cube': return new THREE.BoxGeometry(x, y, z);
    case 'Sphere': return new THREE.SphereGeometry(Math.min(x, y, z) / 2, 28, 18);
    case 'Cylinder': {
      const r = Math.min(x, z) / 2;
      return new THREE.CylinderGeometry(r, r, y, 28);
    }
    case 'Capsule': {
      const r = Math.min(x, z) / 2;
      return new THREE.CapsuleGeometry(r, Math.max(y - 2 * r, 0), 8, 20);
    }
    case 'Wedge': return wedgeGeometry(x, y, z);
    default: return new THREE.BoxGeometry(x, y, z); // meshes, maps, unknown: their Size box
  }
}

function dispose(m) {
  bodyGroup.remove(m);
  m.traverse((o) => { o.geometry?.dispose(); o.material?.dispose(); });
}

function colorOf(b) {
  if (b.slot === selectedSlot) return COLORS.selected;
  if (b.controller) return COLORS.controller;
  if (b.anchored) return COLORS.anchored;
  if (b.sleeping) return COLORS.sleeping;
  return COLORS.awake;
}

function draw3d(s) {
  const seen = new Set();
  for (const b of s.bodies) {
    const key = b.slot + ':' + b.generation;
    const geoKey = b.shape + ':' + b.size.join(',');
    seen.add(key);
    let m = meshes.get(key);
    if (m && m.userData.geoKey !== geoKey) {
      dispose(m);
      m = null;
    }
    if (!m) {
      const wire = b.shape === 'Mesh' || b.shape === 'TriMesh' || b.shape === 'Unknown';
      m = new THREE.Mesh(geometryFor(b), new THREE.MeshStandardMaterial({
        roughness: 0.75, metalness: 0.05, wireframe: wire,
        side: b.shape === 'Wedge' ? THREE.DoubleSide : THREE.FrontSide,
        transparent: b.controller, opacity: b.controller ? 0.55 : 1,
      }));
      m.userData.geoKey = geoKey;
      if (!wire) {
        // Dark edges keep neighbouring parts of one colour (anchored grey) apart.
        const edges = new THREE.LineSegments(new THREE.EdgesGeometry(m.geometry, 25),
          new THREE.LineBasicMaterial({ color: 0x101317, transparent: true, opacity: 0.6 }));
        edges.raycast = () => {};
        m.add(edges);
      }
      bodyGroup.add(m);
      meshes.set(key, m);
    }
    m.userData.slot = b.slot;
    m.position.set(b.position[0], b.position[1], b.position[2]);
    m.quaternion.set(b.rotation[0], b.rotation[1], b.rotation[2], b.rotation[3]);
    m.material.color.setHex(colorOf(b));
  }
  for (const [key, m] of meshes) {
    if (!seen.has(key)) {
      dispose(m);
      meshes.delete(key);
    }
  }
  drawOverlays3d(s);
  // A replay keeps the framing of its first tick, whatever tick the page opens at.
  if (fittedPlane !== s.id) fitCamera(s.fit && s.fit.length ? { ...s, bodies: s.fit } : s);
  view.dataset.meshes = String(bodyGroup.children.length);
}

function sceneScale(s) {
  let r = 1;
  for (const b of s.bodies) r = Math.max(r, Math.min(Math.max(...b.size), 50));
  return r;
}

function drawOverlays3d(s) {
  for (const o of [...overlayGroup.children]) {
    overlayGroup.remove(o);
    o.geometry?.dispose();
  }
  const len = sceneScale(s) * 0.25;
  if ($('show-contacts').checked && s.contacts.length) {
    const pts = [], lines = [];
    for (const c of s.contacts) {
      pts.push(...c.position);
      lines.push(...c.position, ...c.position.map((v, i) => v + c.normal[i] * len));
    }
    const pg = new THREE.BufferGeometry();
    pg.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
    overlayGroup.add(new THREE.Points(pg, new THREE.PointsMaterial({ color: COLORS.contact, size: 6, sizeAttenuation: false, depthTest: false })));
    const lg = new THREE.BufferGeometry();
    lg.setAttribute('position', new THREE.Float32BufferAttribute(lines, 3));
    overlayGroup.add(new THREE.LineSegments(lg, new THREE.LineBasicMaterial({ color: COLORS.contact, depthTest: false })));
  }
  if ($('show-rays').checked && s.rays && s.rays.length) {
    const pts = [];
    for (const r of s.rays) pts.push(...r.from, ...r.to);
    const rg = new THREE.BufferGeometry();
    rg.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
    overlayGroup.add(new THREE.LineSegments(rg, new THREE.LineBasicMaterial({ color: COLORS.ray, depthTest: false })));
  }
  drawJoints3d(s, len);
  if ($('show-controllers').checked) {
    for (const c of s.controllers) {
      const k = c.controller || {};
      if (k.radius) {
        const g = new THREE.CapsuleGeometry(k.radius, 2 * k.half_height, 4, 12);
        const cap = new THREE.LineSegments(new THREE.WireframeGeometry(g),
          new THREE.LineBasicMaterial({ color: c.on_ground ? COLORS.controller : 0xffd166 }));
        g.dispose();
        cap.position.set(...c.position);
        overlayGroup.add(cap);
      }
      const v = new THREE.Vector3(...c.velocity);
      if (v.length() > 1e-3) {
        overlayGroup.add(new THREE.ArrowHelper(v.clone().normalize(), new THREE.Vector3(...c.position),
          Math.min(v.length() * 0.25, len * 4), COLORS.controller));
      }
    }
  }
}

// Each joint as a line from A's anchor to B's (or to its world point), over the bodies; a
// broken joint dashed and faded. data-joints: the joints drawn; data-joints-broken: of them
// broken; data-joint-lines: each drawn joint's slot, ends and state.
function drawJoints3d(s, len) {
  const joints = $('show-joints').checked && s.joints ? s.joints : [];
  const whole = [], broken = [], ends = [];
  for (const j of joints) {
    (j.broken ? broken : whole).push(...j.from, ...j.to);
    ends.push(...j.from, ...j.to);
  }
  const lines = (pts, material) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
    const l = new THREE.LineSegments(g, material);
    l.computeLineDistances();
    l.renderOrder = 2;
    overlayGroup.add(l);
  };
  if (whole.length) {
    lines(whole, new THREE.LineBasicMaterial({ color: COLORS.joint, depthTest: false }));
  }
  if (broken.length) {
    lines(broken, new THREE.LineDashedMaterial({
      color: COLORS.joint, dashSize: len * 0.15, gapSize: len * 0.1,
      transparent: true, opacity: 0.4, depthTest: false,
    }));
  }
  if (ends.length) {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(ends, 3));
    overlayGroup.add(new THREE.Points(g, new THREE.PointsMaterial({
      color: COLORS.joint, size: 5, sizeAttenuation: false, depthTest: false,
    })));
  }
  view.dataset.joints = String(joints.length);
  view.dataset.jointsBroken = String(broken.length / 6);
  view.dataset.jointLines = JSON.stringify(joints.map((j) => ({
    slot: j.slot, kind: j.kind, a: j.a, b: j.b, from: j.from, to: j.to, broken: j.broken,
  })));
}

function fitCamera(s) {
  // Frame most bodies: around the median position, out to the 90th percentile of the
  // distances (a body falling off the world must not shrink everything else to a dot), and
  // ignoring floors far larger than the rest (over 8x the median size) for the size.
  const med = (xs) => { const v = [...xs].sort((a, b) => a - b); return v.length ? v[Math.floor(v.length / 2)] : 0; };
  const bodies = s.bodies.length ? s.bodies : [{ position: [0, 0, 0], size: [10, 10, 10] }];
  const centre = new THREE.Vector3(...[0, 1, 2].map((i) => med(bodies.map((b) => b.position[i]))));
  const medianSize = med(bodies.map((b) => Math.max(...b.size)));
  const reach = bodies
    .filter((b) => Math.max(...b.size) <= 8 * medianSize)
    .map((b) => centre.distanceTo(new THREE.Vector3(...b.position)) + Math.max(...b.size) / 2)
    .sort((a, b) => a - b);
  const radius = Math.max(reach.length ? reach[Math.floor((reach.length - 1) * 0.9)] : 5, 2);
  const d = radius / Math.sin((camera.fov * Math.PI) / 360) * 1.05;
  camera.position.copy(centre).add(new THREE.Vector3(0.55, 0.45, 0.7).normalize().multiplyScalar(d));
  camera.near = Math.max(d / 1000, 0.01);
  camera.far = d * 100;
  camera.updateProjectionMatrix();
  controls.target.copy(centre);
  controls.update();
  const floorY = Math.min(...bodies.map((b) => b.position[1] - b.size[1] / 2));
  grid.position.y = Math.max(Math.min(0, floorY), centre.y - 4 * radius);
  fittedPlane = s.id;
}

const raycaster = new THREE.Raycaster();
glCanvas.addEventListener('click', (ev) => {
  const r = glCanvas.getBoundingClientRect();
  const p = new THREE.Vector2(((ev.clientX - r.left) / r.width) * 2 - 1, -((ev.clientY - r.top) / r.height) * 2 + 1);
  raycaster.setFromCamera(p, camera);
  const hit = raycaster.intersectObjects(bodyGroup.children, false)[0];
  selectBody(hit ? hit.object.userData.slot : null);
});

// ---------------------------------------------------------------- 2D (GUI planes, pixels)
let view2d = { scale: 1, ox: 0, oy: 0 };

function draw2d(s) {
  const ctx = canvas2d.getContext('2d');
  const w = canvas2d.clientWidth, h = canvas2d.clientHeight;
  const dpr = window.devicePixelRatio || 1;
  if (canvas2d.width !== Math.round(w * dpr) || canvas2d.height !== Math.round(h * dpr)) {
    canvas2d.width = Math.round(w * dpr);
    canvas2d.height = Math.round(h * dpr);
  }
  // Fit the bodies' boxes (pixel space, +Y down) into the canvas.
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  for (const b of s.bodies) {
    const r = Math.hypot(b.size[0], b.size[1]) / 2;
    x0 = Math.min(x0, b.position[0] - r); x1 = Math.max(x1, b.position[0] + r);
    y0 = Math.min(y0, b.position[1] - r); y1 = Math.max(y1, b.position[1] + r);
  }
  if (!isFinite(x0)) { x0 = 0; y0 = 0; x1 = 800; y1 = 600; }
  const scale = Math.min(w / (x1 - x0 + 40), h / (y1 - y0 + 40));
  view2d = { scale, ox: (w - (x1 - x0) * scale) / 2 - x0 * scale, oy: (h - (y1 - y0) * scale) / 2 - y0 * scale };
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.fillStyle = '#15181d';
  ctx.fillRect(0, 0, w, h);
  ctx.setTransform(dpr * scale, 0, 0, dpr * scale, dpr * view2d.ox, dpr * view2d.oy);
  const bodies = [...s.bodies].sort((a, b) => (a.z_index || 0) - (b.z_index || 0));
  for (const b of bodies) {
    const [sx, sy] = b.size;
    const angle = 2 * Math.atan2(b.rotation[2], b.rotation[3]); // about +Z, clockwise on screen
    ctx.save();
    ctx.translate(b.position[0], b.position[1]);
    ctx.rotate(angle);
    ctx.fillStyle = css(colorOf(b));
    ctx.strokeStyle = '#0b0d10';
    ctx.lineWidth = 1 / scale;
    ctx.beginPath();
    if (b.shape === 'Circle') ctx.arc(0, 0, Math.min(sx, sy) / 2, 0, 2 * Math.PI);
    else if (b.shape === 'Triangle') { ctx.moveTo(0, -sy / 2); ctx.lineTo(sx / 2, sy / 2); ctx.lineTo(-sx / 2, sy / 2); ctx.closePath(); }
    else ctx.rect(-sx / 2, -sy / 2, sx, sy);
    ctx.fill();
    ctx.stroke();
    ctx.restore();
  }
  if ($('show-controllers').checked) {
    ctx.strokeStyle = css(COLORS.controller);
    ctx.lineWidth = 2 / scale;
    for (const c of s.controllers) {
      const wp = (c.controller && c.controller.waypoints) || [];
      if (!wp.length) continue;
      ctx.beginPath();
      ctx.moveTo(c.position[0], c.position[1]);
      for (const p of wp.slice(c.controller.next_waypoint || 0)) ctx.lineTo(p[0], p[1]);
      ctx.stroke();
    }
  }
  view.dataset.meshes = String(s.bodies.length);
  view.dataset.joints = '0';
  view.dataset.jointsBroken = '0';
  view.dataset.jointLines = '[]';
}

canvas2d.addEventListener('click', (ev) => {
  if (!snapshot) return;
  const r = canvas2d.getBoundingClientRect();
  const x = (ev.clientX - r.left - view2d.ox) / view2d.scale;
  const y = (ev.clientY - r.top - view2d.oy) / view2d.scale;
  let best = null;
  for (const b of snapshot.bodies) {
    if (Math.abs(x - b.position[0]) <= b.size[0] / 2 && Math.abs(y - b.position[1]) <= b.size[1] / 2) {
      if (!best || (b.z_index || 0) >= (best.z_index || 0)) best = b;
    }
  }
  selectBody(best ? best.slot : null);
});

// ---------------------------------------------------------------- page state
async function selectBody(slot) {
  selectedSlot = slot;
  dirty = true;
  if (slot === null || selected === null) { $('props').textContent = 'click a body'; return; }
  try {
    const info = await getJSON(`/api/plane/${selected}/body/${slot}`);
    $('props').textContent = JSON.stringify(info, null, 1);
  } catch (e) {
    $('props').textContent = String(e.message || e);
  }
}

function fmt(v, digits = 3) {
  return typeof v === 'number' ? (Number.isInteger(v) ? String(v) : v.toPrecision(digits)) : String(v);
}

function applySnapshot(s) {
  if (!snapshot || snapshot.id !== s.id || snapshot.tick !== s.tick ||
      snapshot.bodies.length !== s.bodies.length || drawnSelection !== selectedSlot ||
      JSON.stringify(snapshot.joints) !== JSON.stringify(s.joints)) dirty = true;
  drawnSelection = selectedSlot;
  snapshot = s;
  const gui = s.kind === 'Gui2d';
  glCanvas.hidden = gui;
  canvas2d.hidden = !gui;
  if (gui) draw2d(s); else draw3d(s);
  $('figures').innerHTML =
    `plane ${s.id} · ${s.kind} · tick ${s.tick} · t ${fmt(s.sim_time)} s<br>` +
    `bodies ${s.body_count} · ${s.tick_rate > 0 ? fmt(s.tick_rate) + ' Hz' : 'manual'} · ${s.enabled ? 'enabled' : 'paused'}<br>` +
    `step ${fmt(s.step_time_us)} µs · penetration ${fmt(s.max_penetration)}<br>` +
    `contact pairs ${s.contact_pairs} · joints ${s.joint_count || 0} · joint error ${fmt(s.max_joint_error)}`;
  view.dataset.plane = String(s.id);
  view.dataset.kind = s.kind;
  view.dataset.tick = String(s.tick);
  view.dataset.bodyCount = String(s.bodies.length);
  view.dataset.contacts = String(s.contacts.length);
  view.dataset.controllers = String(s.controllers.length);
  view.dataset.bodies = JSON.stringify(s.bodies.map((b) => ({
    slot: b.slot, generation: b.generation, shape: b.shape, size: b.size,
    position: b.position, rotation: b.rotation, sleeping: b.sleeping, anchored: b.anchored,
  })));
  showReplay(s);
  view.dataset.frames = String(++frames);
  view.dataset.ready = '1';
}

// ---------------------------------------------------------------- replay timeline
function showReplay(s) {
  const r = s.replay;
  const attrs = ['replayTick', 'replayFirst', 'replayLast', 'replayPlaying', 'replaySpeed',
    'replayDiverged', 'replayRays', 'replayAtEnd'];
  if (!r) {
    for (const a of attrs) delete view.dataset[a];
    return;
  }
  $('replay-now').textContent = `tick ${r.tick} of ${r.first}–${r.last} · ${r.playing ? 'playing' : 'paused'}` +
    ` · ${r.speed}× of ${fmt(r.rate_hz)} Hz${r.at_end ? ' · end' : ''}`;
  const slider = $('replay-slider');
  slider.min = String(r.first);
  slider.max = String(r.last);
  if (!sliding) slider.value = String(r.tick);
  const input = $('replay-tick');
  input.min = String(r.first);
  input.max = String(r.last);
  if (document.activeElement !== input) input.value = String(r.tick);
  const speed = $('replay-speed');
  if (speed.options.length !== r.speeds.length) {
    speed.innerHTML = r.speeds.map((v) => `<option value="${v}">${v}×</option>`).join('');
  }
  if (document.activeElement !== speed) speed.value = String(r.speed);
  $('replay-diverged').textContent = r.diverged || r.error || '';
  view.dataset.replayTick = String(r.tick);
  view.dataset.replayFirst = String(r.first);
  view.dataset.replayLast = String(r.last);
  view.dataset.replayPlaying = String(r.playing);
  view.dataset.replaySpeed = String(r.speed);
  view.dataset.replayAtEnd = String(r.at_end);
  view.dataset.replayDiverged = r.diverged || '';
  view.dataset.replayRays = JSON.stringify(s.rays || []);
}

async function replayAct(body) {
  try {
    const r = await getJSON('/api/replay', {
      method: 'POST', headers: { 'content-type': 'application/json' }, body: JSON.stringify(body),
    });
    $('replay-diverged').textContent = r.diverged || '';
  } catch (e) {
    $('replay-diverged').textContent = String(e.message || e);
  }
}

for (const b of document.querySelectorAll('#replay button[data-replay]')) {
  b.addEventListener('click', () => {
    const action = b.dataset.replay;
    replayAct(action === 'seek' ? { action, tick: Number($('replay-tick').value) } : { action });
  });
}
$('replay-tick').addEventListener('keydown', (ev) => {
  if (ev.key === 'Enter') replayAct({ action: 'seek', tick: Number($('replay-tick').value) });
});
$('replay-slider').addEventListener('input', () => {
  sliding = true;
  $('replay-tick').value = $('replay-slider').value;
});
$('replay-slider').addEventListener('change', async () => {
  await replayAct({ action: 'seek', tick: Number($('replay-slider').value) });
  sliding = false;
});
$('replay-speed').addEventListener('change', () => {
  replayAct({ action: 'speed', speed: Number($('replay-speed').value) });
});

// What a rendered frame of the replay plane shows, for a headless browser to compare two
// ticks: a GRID_W x GRID_H downscale of the canvas (RGB, six hex digits per cell, rows from
// the top) and each body's centre and radius on screen (fractions of the canvas: x right,
// y down, r of its height).
const GRID_W = 64, GRID_H = 40;
const probe = document.createElement('canvas');
probe.width = GRID_W;
probe.height = GRID_H;
function sampleFrame(s) {
  const ctx = probe.getContext('2d', { willReadFrequently: true });
  ctx.imageSmoothingEnabled = true;
  ctx.imageSmoothingQuality = 'high';
  ctx.drawImage(glCanvas, 0, 0, GRID_W, GRID_H);
  const d = ctx.getImageData(0, 0, GRID_W, GRID_H).data;
  let hex = '';
  for (let i = 0; i < d.length; i += 4) {
    for (let c = 0; c < 3; c++) hex += d[i + c].toString(16).padStart(2, '0');
  }
  const up = new THREE.Vector3(0, 1, 0).applyQuaternion(camera.quaternion);
  const screen = s.bodies.map((b) => {
    const centre = new THREE.Vector3(...b.position);
    const p = centre.clone().project(camera);
    // The bounding sphere's top, seen from the camera.
    const half = Math.hypot(...b.size) / 2;
    const top = centre.clone().addScaledVector(up, half).project(camera);
    return { slot: b.slot, x: (p.x + 1) / 2, y: (1 - p.y) / 2, r: Math.abs(top.y - p.y) / 2 };
  });
  view.dataset.grid = `${GRID_W}x${GRID_H}:${hex}`;
  view.dataset.screen = JSON.stringify(screen);
  view.dataset.frameTick = String(s.tick);
}

async function refreshPlanes() {
  try {
    const info = await getJSON('/api/info');
    $('domain').textContent = info.domain;
    allowControl = info.allow_control;
    $('status').textContent = info.connected ? `daemon pid ${info.daemon_pid}` : `no daemon: ${info.error || ''}`;
    $('status').className = info.connected ? '' : 'bad';
    const rp = info.replay ? info.replay.plane : null;
    $('replay').hidden = !info.replay;
    if (info.replay) $('replay-file').textContent = info.replay.file;
    if (rp !== null && rp !== replayPlane) {
      // The replay plane is shown unless the page was opened on another one.
      if (selected === null || selected === replayPlane) selected = rp;
      replayPlane = rp;
      // `?tick=T` opens the replay at tick T (a link to the moment a bug happened).
      if (params.has('tick')) await replayAct({ action: 'seek', tick: Number(params.get('tick')) });
    }
    const planes = await getJSON('/api/planes');
    if (selected === null && planes.length) selected = planes[0].id;
    const rows = planes.map((p) =>
      `<tr data-plane-id="${p.id}" data-kind="${p.kind}" data-body-count="${p.body_count}" class="${p.id === selected ? 'selected' : ''}">` +
      `<td>${p.id}</td><td>${p.kind}${p.replay ? ' (replay)' : ''}</td><td>${p.body_count}</td>` +
      `<td>${p.tick_rate > 0 ? fmt(p.tick_rate) : 'manual'}</td><td>${fmt(p.step_time_us)}</td></tr>`).join('');
    const body = document.querySelector('#planes tbody');
    body.innerHTML = rows;
    view.dataset.planeCount = String(planes.length);
    for (const tr of body.querySelectorAll('tr')) {
      tr.addEventListener('click', () => {
        selected = Number(tr.dataset.planeId);
        selectedSlot = null;
        history.replaceState(null, '', `?plane=${selected}`);
        refreshPlanes();
      });
    }
    for (const b of document.querySelectorAll('#controls button')) {
      b.disabled = !allowControl || selected === null;
    }
    // A snapshot is a read: offered for any plane, controls or not.
    $('download').href = selected === null ? '#' : `/api/plane/${selected}/snapshot`;
    $('control-note').textContent = allowControl ? '' : 'read-only (start physics-view with --allow-control)';
  } catch (e) {
    $('status').textContent = String(e.message || e);
    $('status').className = 'bad';
  }
}

for (const b of document.querySelectorAll('#controls button')) {
  b.addEventListener('click', async () => {
    try {
      const r = await getJSON(`/api/plane/${selected}/${b.dataset.action}`, { method: 'POST' });
      $('control-note').textContent = `${b.dataset.action}: tick ${r.tick}`;
    } catch (e) {
      $('control-note').textContent = String(e.message || e);
    }
  });
}

// ---------------------------------------------------------------- plots
function plot(canvasEl, xs, ys) {
  const ctx = canvasEl.getContext('2d');
  const w = canvasEl.clientWidth, h = canvasEl.clientHeight, dpr = window.devicePixelRatio || 1;
  canvasEl.width = Math.round(w * dpr);
  canvasEl.height = Math.round(h * dpr);
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, w, h);
  ctx.fillStyle = '#8c96a5';
  ctx.font = '11px system-ui, sans-serif';
  let max = 0;
  for (const y of ys) max = Math.max(max, y);
  const last = ys.length ? ys[ys.length - 1] : 0;
  ctx.fillText(`${canvasEl.dataset.title}: ${fmt(last)} (max ${fmt(max)})`, 6, 13);
  if (xs.length < 2) return;
  const x0 = xs[0], x1 = xs[xs.length - 1] || x0 + 1, top = 20, bottom = h - 6;
  ctx.strokeStyle = '#e0894a';
  ctx.lineWidth = 1.2;
  ctx.beginPath();
  for (let i = 0; i < xs.length; i++) {
    const x = 4 + ((xs[i] - x0) / Math.max(x1 - x0, 1e-9)) * (w - 8);
    const y = bottom - (max > 0 ? ys[i] / max : 0) * (bottom - top);
    if (i === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y);
  }
  ctx.stroke();
}

async function refreshPlots() {
  if (selected === null) return;
  try {
    const h = await getJSON(`/api/plane/${selected}/history`);
    for (const key of ['step_time_us', 'max_penetration', 'contact_pairs', 'max_joint_error']) {
      plot($('plot-' + key), h.sim_time, h[key]);
    }
  } catch (e) { /* a plane that just went away */ }
}

// ---------------------------------------------------------------- loops
function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  if (renderer) renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', () => { resize(); dirty = true; });
for (const id of ['show-contacts', 'show-controllers', 'show-rays', 'show-joints']) {
  $(id).addEventListener('change', () => { drawnSelection = undefined; });
}
resize();

function render() {
  controls.update();
  if (dirty && renderer && snapshot && snapshot.kind !== 'Gui2d') {
    renderer.render(scene, camera);
    dirty = false;
    if (snapshot.replay) sampleFrame(snapshot);
  }
  requestAnimationFrame(render);
}
requestAnimationFrame(render);

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
async function poll() {
  // One request in flight at a time, at most ~30 per second: the viewer samples the newest
  // tick at display rate, never every tick.
  for (;;) {
    const started = performance.now();
    if (selected !== null) {
      try {
        applySnapshot(await getJSON(`/api/plane/${selected}`));
        view.dataset.error = '';
      } catch (e) {
        view.dataset.error = String(e.message || e);
      }
    }
    await sleep(Math.max(0, 33 - (performance.now() - started)));
  }
}

await refreshPlanes();
setInterval(refreshPlanes, 1000);
setInterval(refreshPlots, 1000);
refreshPlots();
poll();
