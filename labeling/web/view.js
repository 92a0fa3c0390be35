// The page of `meshvis view`: the model with orbit controls and its labels as an overlay.
//
// Each time the view changes, the page renders the part-ID buffer on the GPU (every part in
// one flat colour, part i as the 24-bit number i + 1, into an off-screen render target),
// reads it back and posts it with the camera to the meshvis server, which lays the labels
// out coherently with the previous frame.  Between answers every anchor is re-projected
// each frame from its 3D point, the label follows it, and boxes glide to their new places.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

// the longest side of the ID buffer (pixels): the layout's cost grows with its area
const MAX_ID_SIDE = 512;
// the fraction of the way to its new place a box moves per animation frame
const GLIDE = 0.3;
// label style (the server measures the boxes with the same font)
const FONT = '"DejaVu Sans", Verdana, Arial, sans-serif';
const SVG_NS = 'http://www.w3.org/2000/svg';

const stage = document.getElementById('stage');
const overlay = document.getElementById('labels');
const status = document.getElementById('status');
const viewer = Math.random().toString(36).slice(2);

const info = await (await fetch('scene.json')).json();
// more parts than two bytes can number: send the RGBA read-out as it is
const wide = info.parts.length >= 65535;
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1); // one canvas pixel per CSS pixel: the overlay's coordinates
stage.appendChild(renderer.domElement);

const view = new THREE.Scene();
view.background = new THREE.Color(0xffffff);
view.add(new THREE.HemisphereLight(0xffffff, 0x606060, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
view.add(sun);

const center = new THREE.Vector3().fromArray(info.camera.target);
const camera = new THREE.PerspectiveCamera(info.camera.fov, 1, info.radius / 100, info.radius * 100);
camera.up.fromArray(info.camera.up);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.copy(center);

// the model as it is in the file (or converted to glTF by the server)
const gltf = await new GLTFLoader().loadAsync('model.glb');
view.add(gltf.scene);

// the ID scene: the server's triangles with a part id per vertex
const idScene = new THREE.Scene();
idScene.background = new THREE.Color(0x000000);
idScene.add(await idMesh());
const idTarget = new THREE.WebGLRenderTarget(8, 8, { depthBuffer: true });
let idPixels = new Uint8Array(0);
let idPacked = new Uint16Array(0);

async function idMesh() {
  const buf = await (await fetch('idmesh.bin')).arrayBuffer();
  const [nv, nf] = new Uint32Array(buf, 0, 2);
  const verts = new Float32Array(buf, 8, nv * 3);
  const faces = new Uint32Array(buf, 8 + nv * 12, nf * 3);
  const part = new Uint32Array(buf, 8 + nv * 12 + nf * 12, nf);
  const pos = new Float32Array(nf * 9);
  const pid = new Float32Array(nf * 3);
  for (let f = 0; f < nf; f++) {
    for (let c = 0; c < 3; c++) {
      const v = faces[3 * f + c];
      pos.set(verts.subarray(3 * v, 3 * v + 3), 9 * f + 3 * c);
      pid[3 * f + c] = part[f];
    }
  }
  const geom = new THREE.BufferGeometry();
  geom.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  geom.setAttribute('partId', new THREE.BufferAttribute(pid, 1));
  const mat = new THREE.ShaderMaterial({
    glslVersion: THREE.GLSL3,
    side: THREE.DoubleSide,
    vertexShader: `in float partId; flat out float vId;
      void main() { vId = partId; gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0); }`,
    fragmentShader: `flat in float vId; out highp vec4 partColour;
      void main() {
        float id = vId + 1.0;
        partColour = vec4(mod(id, 256.0), mod(floor(id / 256.0), 256.0), floor(id / 65536.0), 255.0) / 255.0;
      }`,
  });
  return new THREE.Mesh(geom, mat);
}

// fit the model's bounding sphere into both fields of view, from the server's direction
function fitCamera() {
  const w = stage.clientWidth, h = stage.clientHeight;
  const aspect = w / h;
  const half = THREE.MathUtils.degToRad(info.camera.fov) / 2;
  const narrow = aspect < 1 ? Math.atan(Math.tan(half) * aspect) : half;
  const dir = new THREE.Vector3().fromArray(info.camera.position).sub(center).normalize();
  camera.position.copy(center).addScaledVector(dir, (info.fitMargin * info.radius) / Math.sin(narrow));
  controls.update();
}

function resize() {
  const w = stage.clientWidth, h = stage.clientHeight;
  renderer.setSize(w, h);
  overlay.setAttribute('width', w);
  overlay.setAttribute('height', h);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  dirty = true;
  resized = true;
}

// ------------------------------------------------------------------ frames to the server
let dirty = true, inFlight = false, resized = true, seq = 0;
const state = { labels: new Map(), scale: 1, fontSize: 11, boxHeight: 16, layoutMs: 0 };
const stats = { received: [], answers: [], sent: 0, errors: 0, timing: [] };
controls.addEventListener('change', () => { dirty = true; });

function renderIds() {
  const w = stage.clientWidth, h = stage.clientHeight;
  const k = Math.min(1, MAX_ID_SIDE / Math.max(w, h));
  const iw = Math.max(8, Math.round(w * k)), ih = Math.max(8, Math.round(h * k));
  idTarget.setSize(iw, ih);
  if (idPixels.length !== iw * ih * 4) idPixels = new Uint8Array(iw * ih * 4);
  renderer.setRenderTarget(idTarget);
  renderer.render(idScene, camera);
  renderer.readRenderTargetPixels(idTarget, 0, 0, iw, ih, idPixels);
  renderer.setRenderTarget(null);
  // two bytes a pixel (part + 1, 0 = background) instead of four: half the data to send
  if (idPacked.length !== iw * ih) idPacked = new Uint16Array(iw * ih);
  for (let i = 0, j = 0; i < idPacked.length; i++, j += 4) idPacked[i] = idPixels[j] | (idPixels[j + 1] << 8);
  return [iw, ih];
}

async function requestLayout() {
  dirty = false;
  inFlight = true;
  const t0 = performance.now();
  const [iw, ih] = renderIds();
  const t1 = performance.now();
  const header = {
    viewer, seq: ++seq, width: iw, height: ih, format: wide ? 'rgba' : 'u16',
    camera: {
      position: camera.position.toArray(), target: controls.target.toArray(),
      up: camera.up.toArray(), fov: camera.fov,
    },
  };
  const sentCamera = camera.matrixWorld.clone();
  stats.sent++;
  try {
    const res = await fetch('layout', {
      method: 'POST', body: wide ? idPixels : idPacked, headers: { 'X-Meshvis-Frame': JSON.stringify(header) },
    });
    const answer = await res.json();
    if (!res.ok) throw new Error(answer.error);
    accept(answer, iw);
    stats.timing.push({ ids: t1 - t0, answer: performance.now() - t1, layout: answer.layoutMs, server: answer.serverMs });
    if (stats.timing.length > 200) stats.timing.shift();
  } catch (err) {
    stats.errors++;
    status.textContent = `error: ${err.message}`;
  } finally {
    inFlight = false;
    if (!camera.matrixWorld.equals(sentCamera)) dirty = true;
  }
}

function accept(answer, iw) {
  const now = performance.now();
  stats.answers.push(now);
  stats.received.push({ seq: answer.seq, t: now, width: answer.width, height: answer.height,
    layoutMs: answer.layoutMs, labels: answer.labels.map(l => ({ part: l.part, box: l.box, side: l.side,
      leader: l.leader, anchor3d: l.anchor3d })) });
  if (stats.received.length > 500) stats.received.shift();
  state.scale = stage.clientWidth / iw;
  state.fontSize = answer.fontSize;
  state.boxHeight = answer.boxHeight;
  state.layoutMs = answer.layoutMs;
  const seen = new Set();
  for (const l of answer.labels) {
    seen.add(l.part);
    const old = state.labels.get(l.part);
    const entry = old || { node: makeLabel(l.text), shown: null };
    entry.text = l.text;
    entry.anchor = l.anchor;
    entry.point = l.anchor3d.every(x => x !== null) ? new THREE.Vector3().fromArray(l.anchor3d) : null;
    entry.leader = l.leader;
    entry.box = l.box;
    state.labels.set(l.part, entry);
  }
  for (const [part, entry] of state.labels) {
    if (!seen.has(part)) { entry.node.remove(); state.labels.delete(part); }
  }
}

// ------------------------------------------------------------------ the overlay
function makeLabel(text) {
  const g = document.createElementNS(SVG_NS, 'g');
  g.innerHTML = '<polyline fill="none" stroke="#1e1e1e" stroke-width="1"/>' +
    '<circle r="2.2" fill="#c81e1e" stroke="#fff" stroke-width="0.8"/>' +
    '<rect fill="#fff" fill-opacity="0.9" stroke="#6e6e6e" stroke-width="0.6"/>' +
    `<text font-family='${FONT}' fill="#141414"></text>`;
  g.querySelector('text').textContent = text;
  overlay.appendChild(g);
  return g;
}

const tmp = new THREE.Vector3();
function project(p) {
  tmp.copy(p).project(camera);
  return [(tmp.x + 1) / 2 * stage.clientWidth, (1 - tmp.y) / 2 * stage.clientHeight];
}

function drawLabels() {
  const s = state.scale;
  for (const entry of state.labels.values()) {
    const a0 = [entry.anchor[0] * s, entry.anchor[1] * s];
    // the anchor's surface point where the camera sees it now; the label moves with it
    const a = entry.point ? project(entry.point) : a0;
    const dx = a[0] - a0[0], dy = a[1] - a0[1];
    const target = [entry.box[0] * s + dx, entry.box[1] * s + dy];
    if (!entry.shown) entry.shown = target.slice();
    entry.shown[0] += (target[0] - entry.shown[0]) * GLIDE;
    entry.shown[1] += (target[1] - entry.shown[1]) * GLIDE;
    const gx = entry.shown[0] - target[0], gy = entry.shown[1] - target[1];
    const pts = entry.leader.map(([x, y], i) => {
      if (i === 0) return a;
      const last = i === entry.leader.length - 1;
      return [x * s + dx + (last ? gx : 0), y * s + dy + (last ? gy : 0)];
    });
    const [line, dot, rect, text] = entry.node.children;
    line.setAttribute('points', pts.map(p => p.join(',')).join(' '));
    dot.setAttribute('cx', a[0]);
    dot.setAttribute('cy', a[1]);
    const w = (entry.box[2] - entry.box[0]) * s, h = (entry.box[3] - entry.box[1]) * s;
    rect.setAttribute('x', entry.shown[0]);
    rect.setAttribute('y', entry.shown[1]);
    rect.setAttribute('width', w);
    rect.setAttribute('height', h);
    const fs = state.fontSize * s;
    text.setAttribute('font-size', fs);
    text.setAttribute('x', entry.shown[0] + 3 * s);
    text.setAttribute('y', entry.shown[1] + h / 2 + 0.35 * fs);
    text.setAttribute('textLength', Math.max(1, w - 6 * s));
    text.setAttribute('lengthAdjust', 'spacingAndGlyphs');
  }
}

function showStatus() {
  const now = performance.now();
  while (stats.answers.length && now - stats.answers[0] > 1000) stats.answers.shift();
  status.textContent = `${state.labels.size} labels · layout ${state.layoutMs.toFixed(1)} ms · ` +
    `${stats.answers.length} updates/s`;
}

// ------------------------------------------------------------------ the loop
// the display is drawn again only when the camera moved or the window changed size
let drawn = null;
function animate() {
  controls.update();
  if (!drawn || !drawn.equals(camera.matrixWorld) || resized) {
    sun.position.copy(camera.position);
    renderer.render(view, camera);
    drawn = camera.matrixWorld.clone();
    resized = false;
  }
  if (dirty && !inFlight) requestLayout();
  drawLabels();
  showStatus();
  requestAnimationFrame(animate);
}

// turn the camera about the model's up axis (tests and recordings turn the model with it)
function turn(degrees) {
  const q = new THREE.Quaternion().setFromAxisAngle(camera.up.clone().normalize(), THREE.MathUtils.degToRad(degrees));
  camera.position.sub(controls.target).applyQuaternion(q).add(controls.target);
  controls.update();
  dirty = true;
}

window.addEventListener('resize', resize);
resize();
fitCamera();
window.meshvisView = { stats, turn, idle: () => !dirty && !inFlight, labels: () => state.labels.size };
animate();
