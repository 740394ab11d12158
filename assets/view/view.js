// swimlab's live view: the frames of `frames` (Server-Sent Events, one JSON frame each) drawn in
// 3D with three.js, the recorders' columns as line plots. Lengths are shown in micrometres.
import * as THREE from "three";
import { OrbitControls } from "three/addons/OrbitControls.js";

window.swimlabViewStarted = true;

const UM = 1e6; // metres to micrometres
const COLORS = { 1: new THREE.Color(0xd9480f), 2: new THREE.Color(0x1c5fd4) };
// Above this many swimmers the arrows are not drawn and the spheres are coarser.
const ARROW_LIMIT = 20000;
const FINE_LIMIT = 10000;
// Points kept per plotted column, and the most columns plotted.
const HISTORY = 2000;
const MAX_PLOTS = 8;

const host = document.getElementById("scene");
const renderer = new THREE.WebGLRenderer({ antialias: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setSize(host.clientWidth, host.clientHeight);
renderer.setClearColor(0xf7f7f4);
host.appendChild(renderer.domElement);

const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(45, host.clientWidth / host.clientHeight, 0.01, 1e6);
camera.up.set(0, 0, 1);
camera.position.set(30, -40, 25);
const controls = new OrbitControls(camera, renderer.domElement);
controls.enableDamping = false;
scene.add(new THREE.AmbientLight(0xffffff, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.4);
sun.position.set(1, -1, 2);
scene.add(sun);

const dummy = new THREE.Object3D();
const up = new THREE.Vector3(0, 1, 0);
let spheres = null;   // InstancedMesh of the spheres
let shafts = null;    // InstancedMesh of the arrows' shafts
let heads = null;     // InstancedMesh of the arrows' heads
let fine = true;
let outline = null;   // the box's edges or the wall's plane
let outlineKey = "";
let fitted = false;
let latest = null;    // the newest frame not yet drawn
let shown = null;     // the frame drawn

function capacityFor(n) {
  let c = 64;
  while (c < n) c *= 2;
  return c;
}

function sphereMesh(capacity, detail) {
  const g = detail ? new THREE.SphereGeometry(1, 24, 16) : new THREE.SphereGeometry(1, 8, 6);
  const m = new THREE.InstancedMesh(g, new THREE.MeshLambertMaterial({ color: 0xffffff }), capacity);
  m.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
  m.frustumCulled = false;
  return m;
}

function arrowMeshes(capacity) {
  const material = new THREE.MeshLambertMaterial({ color: 0x333333 });
  const shaft = new THREE.CylinderGeometry(1, 1, 1, 8);
  shaft.translate(0, 0.5, 0);
  const head = new THREE.ConeGeometry(1, 1, 12);
  head.translate(0, 0.5, 0);
  const s = new THREE.InstancedMesh(shaft, material, capacity);
  const h = new THREE.InstancedMesh(head, material, capacity);
  for (const m of [s, h]) { m.instanceMatrix.setUsage(THREE.DynamicDrawUsage); m.frustumCulled = false; }
  return [s, h];
}

function dispose(m) {
  if (!m) return;
  scene.remove(m);
  m.geometry.dispose();
  m.material.dispose();
  if (m.dispose) m.dispose();
}

// The spheres of `f`, sized by radius and coloured by kind (a1 or a2).
function drawSpheres(f) {
  const list = f.spheres || [];
  const swimmers = list.length / 2;
  const wantFine = swimmers <= FINE_LIMIT;
  if (!spheres || spheres.instanceMatrix.count < list.length || wantFine !== fine) {
    dispose(spheres);
    fine = wantFine;
    spheres = sphereMesh(capacityFor(list.length), fine);
    scene.add(spheres);
  }
  for (let k = 0; k < list.length; k++) {
    const [x, y, z, r, kind] = list[k];
    dummy.position.set(x * UM, y * UM, z * UM);
    dummy.quaternion.identity();
    dummy.scale.setScalar(r * UM);
    dummy.updateMatrix();
    spheres.setMatrixAt(k, dummy.matrix);
    spheres.setColorAt(k, COLORS[kind] || COLORS[1]);
  }
  spheres.count = list.length;
  spheres.instanceMatrix.needsUpdate = true;
  if (spheres.instanceColor) spheres.instanceColor.needsUpdate = true;
}

// N as an arrow from the a1 sphere's centre out past the a2 sphere.
function drawArrows(f) {
  const list = f.spheres || [];
  const n = f.n || [];
  const count = list.length >= 2 * n.length ? n.length : 0;
  if (count === 0 || count > ARROW_LIMIT) {
    if (shafts) { shafts.count = 0; heads.count = 0; }
    return;
  }
  if (!shafts || shafts.instanceMatrix.count < count) {
    dispose(shafts); dispose(heads);
    [shafts, heads] = arrowMeshes(capacityFor(count));
    scene.add(shafts); scene.add(heads);
  }
  const dir = new THREE.Vector3();
  for (let i = 0; i < count; i++) {
    const [x1, y1, z1, a1] = list[2 * i];
    const [x2, y2, z2, a2] = list[2 * i + 1];
    dir.set(n[i][0], n[i][1], n[i][2]).normalize();
    const gap = Math.hypot(x2 - x1, y2 - y1, z2 - z1) * UM;
    const thick = 0.18 * Math.min(a1, a2) * UM;
    const shaftLength = gap + 1.3 * a2 * UM;
    dummy.position.set(x1 * UM, y1 * UM, z1 * UM);
    dummy.quaternion.setFromUnitVectors(up, dir);
    dummy.scale.set(thick, shaftLength, thick);
    dummy.updateMatrix();
    shafts.setMatrixAt(i, dummy.matrix);
    dummy.position.addScaledVector(dir, shaftLength);
    dummy.scale.set(2.5 * thick, 6 * thick, 2.5 * thick);
    dummy.updateMatrix();
    heads.setMatrixAt(i, dummy.matrix);
  }
  shafts.count = count; heads.count = count;
  shafts.instanceMatrix.needsUpdate = true; heads.instanceMatrix.needsUpdate = true;
}

// The sphere centres' bounding box, in micrometres.
function bounds(f) {
  const b = new THREE.Box3();
  const p = new THREE.Vector3();
  for (const [x, y, z, r] of f.spheres || []) {
    p.set(x * UM, y * UM, z * UM);
    b.expandByPoint(p.clone().addScalar(r * UM));
    b.expandByPoint(p.addScalar(-r * UM));
  }
  if (f.box) {
    const [sx, sy, sz] = f.box.map((s) => 0.5 * s * UM);
    b.expandByPoint(new THREE.Vector3(-sx, -sy, -sz));
    b.expandByPoint(new THREE.Vector3(sx, sy, sz));
  }
  if (b.isEmpty()) b.set(new THREE.Vector3(-5, -5, -5), new THREE.Vector3(5, 5, 5));
  return b;
}

// The periodic box's edges (centred on the origin) or the wall's plane under the spheres.
function drawOutline(f) {
  let key = "";
  if (f.box) key = "box " + f.box.join(" ");
  else if (f.wall !== null && f.wall !== undefined) {
    const b = bounds(f);
    const size = Math.max(b.max.x - b.min.x, b.max.y - b.min.y, 10) * 2;
    key = "wall " + f.wall + " " + Math.ceil(Math.log2(size));
  }
  if (key === outlineKey) return;
  if (outline) { scene.remove(outline); outline.traverse((o) => { if (o.geometry) o.geometry.dispose(); }); }
  outline = null;
  outlineKey = key;
  if (f.box) {
    const [sx, sy, sz] = f.box.map((s) => s * UM);
    const edges = new THREE.EdgesGeometry(new THREE.BoxGeometry(sx, sy, sz));
    outline = new THREE.LineSegments(edges, new THREE.LineBasicMaterial({ color: 0x555555 }));
  } else if (key) {
    const size = Math.pow(2, Number(key.split(" ")[2]));
    const b = bounds(f);
    outline = new THREE.Group();
    const plane = new THREE.Mesh(
      new THREE.PlaneGeometry(size, size),
      new THREE.MeshBasicMaterial({ color: 0x8a9a7a, transparent: true, opacity: 0.35, side: THREE.DoubleSide }));
    const grid = new THREE.GridHelper(size, 16, 0x667755, 0x99aa88);
    grid.rotation.x = Math.PI / 2;
    outline.add(plane, grid);
    outline.position.set((b.min.x + b.max.x) / 2, (b.min.y + b.max.y) / 2, f.wall * UM);
  }
  if (outline) scene.add(outline);
}

function fit(f) {
  if (!f) return;
  const b = bounds(f);
  const centre = b.getCenter(new THREE.Vector3());
  const radius = Math.max(b.getSize(new THREE.Vector3()).length() / 2, 1);
  const distance = radius / Math.sin((camera.fov * Math.PI) / 360) * 1.15;
  controls.target.copy(centre);
  camera.position.copy(centre).add(new THREE.Vector3(0.55, -0.75, 0.45).normalize().multiplyScalar(distance));
  camera.near = distance / 1000;
  camera.far = distance * 100;
  camera.updateProjectionMatrix();
  controls.update();
}

function fmt(x, digits = 4) {
  if (x === null || x === undefined) return "–";
  return Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-2 && x !== 0) ? x.toExponential(digits - 1) : x.toPrecision(digits);
}

function drawClock(f) {
  const swimmers = f.n ? f.n.length : (f.spheres ? f.spheres.length / 2 : 0);
  let text = "t = " + fmt(f.t) + " s";
  if (f.periods !== null && f.periods !== undefined) text += " · " + f.periods.toFixed(2) + " periods";
  text += " · " + f.steps + " steps · " + swimmers + " swimmers";
  if (swimmers > ARROW_LIMIT) text += " (no arrows above " + ARROW_LIMIT + ")";
  document.getElementById("time").textContent = text;
}

// ----- live plots of the recorders' columns -------------------------------------------------
const plotsHost = document.getElementById("plots");
const series = new Map(); // name -> { t: [], v: [], canvas }

function addPoints(f) {
  for (const row of f.rows || []) {
    for (const [name, value] of Object.entries(row.columns)) {
      let s = series.get(name);
      if (!s) {
        if (series.size >= MAX_PLOTS) continue;
        if (series.size === 0) {
          // The scene keeps clear of the plots.
          host.style.right = "276px";
          window.dispatchEvent(new Event("resize"));
        }
        const canvas = document.createElement("canvas");
        canvas.width = 260; canvas.height = 96;
        canvas.title = name;
        plotsHost.appendChild(canvas);
        s = { t: [], v: [], canvas };
        series.set(name, s);
      }
      if (s.t.length && row.t <= s.t[s.t.length - 1]) {
        if (row.t < s.t[s.t.length - 1]) { s.t.length = 0; s.v.length = 0; } else continue;
      }
      s.t.push(row.t); s.v.push(value);
      if (s.t.length > HISTORY) { s.t.splice(0, s.t.length - HISTORY); s.v.splice(0, s.v.length - HISTORY); }
    }
  }
}

function drawPlots() {
  for (const [name, s] of series) {
    const c = s.canvas.getContext("2d");
    const w = s.canvas.width, h = s.canvas.height, pad = 6, top = 18;
    c.clearRect(0, 0, w, h);
    c.fillStyle = "#222"; c.font = "12px system-ui, sans-serif";
    const last = s.v.length ? s.v[s.v.length - 1] : null;
    c.fillText(name + " = " + fmt(last), pad, 13);
    if (s.t.length < 2) continue;
    let vmin = Math.min(...s.v), vmax = Math.max(...s.v);
    if (vmin === vmax) { const pad = Math.abs(vmin) * 0.01 || 1; vmin -= pad; vmax += pad; }
    const t0 = s.t[0], t1 = s.t[s.t.length - 1];
    const X = (t) => pad + ((t - t0) / (t1 - t0 || 1)) * (w - 2 * pad);
    const Y = (v) => h - pad - ((v - vmin) / (vmax - vmin)) * (h - top - pad);
    c.strokeStyle = "#1c5fd4"; c.lineWidth = 1.2; c.beginPath();
    for (let k = 0; k < s.t.length; k++) { const x = X(s.t[k]), y = Y(s.v[k]); k ? c.lineTo(x, y) : c.moveTo(x, y); }
    c.stroke();
    c.fillStyle = "#777"; c.font = "10px system-ui, sans-serif";
    c.fillText(fmt(vmax, 3), w - 58, top + 8); c.fillText(fmt(vmin, 3), w - 58, h - pad);
  }
}

// ----- the stream ---------------------------------------------------------------------------
const status = document.getElementById("status");
let source = null;
// `?frames=N`: a still picture, the stream closed after N frames (e.g. for headless screenshots).
const stopAfter = Number(new URLSearchParams(location.search).get("frames")) || Infinity;
let received = 0;

function connect() {
  source = new EventSource("frames");
  source.onopen = () => { status.textContent = "live"; };
  source.onmessage = (e) => {
    let f;
    try { f = JSON.parse(e.data); } catch (err) { console.error("a frame is not JSON:", err); return; }
    latest = f;
    addPoints(f);
    received += 1;
    if (received >= stopAfter) {
      source.close();
      status.textContent = "stopped after " + received + " frames (?frames=" + stopAfter + ")";
    }
  };
  source.onerror = () => {
    // The browser reconnects by itself; a closed source is opened again. The last frame stays.
    status.textContent = "not connected (the last frame stays; retrying)";
    if (source.readyState === EventSource.CLOSED) setTimeout(connect, 2000);
  };
}

function render() {
  requestAnimationFrame(render);
  if (latest && latest !== shown) {
    shown = latest;
    drawSpheres(shown);
    drawArrows(shown);
    drawOutline(shown);
    drawClock(shown);
    drawPlots();
    if (!fitted) { fit(shown); fitted = true; }
  }
  controls.update();
  renderer.render(scene, camera);
}

window.addEventListener("resize", () => {
  camera.aspect = host.clientWidth / host.clientHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(host.clientWidth, host.clientHeight);
});
window.addEventListener("keydown", (e) => { if (e.key === "f") fit(shown); });
document.getElementById("fit").addEventListener("click", () => fit(shown));

connect();
render();
