// The anim viewer: draws the frames of one run (window.ANIM, filled by the scripts under
// viewer/) with three.js. y is up. The page's address may end in `#frame=N` (or `last`),
// `&color=FIELD`, `&pause` and `&bare` (no controls; what screenshots use).
import * as THREE from "three";
import { OrbitControls } from "three/orbit";

const A = window.ANIM;
const hash = new URLSearchParams(location.hash.slice(1));
if (hash.has("bare")) document.body.classList.add("bare");
const $ = (id) => document.getElementById(id);
const status = (text) => { $("status").textContent = text; };
const ctx = A.ctx || {};
const list = (A.list && A.list.frames) || [];
const props = ctx.props || [];

// ---------------------------------------------------------------- colour scales
const VIRIDIS = [[68, 1, 84], [72, 40, 120], [62, 74, 137], [49, 104, 142], [38, 130, 142],
  [31, 158, 137], [53, 183, 121], [109, 205, 89], [180, 222, 44], [253, 231, 37]];
function viridis(s, out, at) {
  const x = Math.min(Math.max(s, 0), 1) * (VIRIDIS.length - 1), i = Math.min(Math.floor(x), VIRIDIS.length - 2), f = x - i;
  for (let c = 0; c < 3; c++) out[at + c] = (VIRIDIS[i][c] * (1 - f) + VIRIDIS[i + 1][c] * f) / 255;
}
// The colours above are sRGB, as the previews draw them; three.js treats vertex colours as linear
// and converts its output to sRGB, so vertex colours are written through this.
function linear(out, at) {
  for (let c = at; c < at + 3; c++) {
    const v = out[c];
    out[c] = v <= 0.04045 ? v / 12.92 : Math.pow((v + 0.055) / 1.055, 2.4);
  }
}
// The previews' categorical palette (Tableau 10).
const PALETTE = [[0x4e, 0x79, 0xa7], [0xf2, 0x8e, 0x2b], [0x59, 0xa1, 0x4f], [0xe1, 0x57, 0x59], [0x76, 0xb7, 0xb2],
  [0xed, 0xc9, 0x48], [0xb0, 0x7a, 0xa1], [0xff, 0x9d, 0xa7], [0x9c, 0x75, 0x5f], [0xba, 0xb0, 0xac]].map((c) => c.map((x) => x / 255));
const BODY = [0.85, 0.45, 0.25];

// ---------------------------------------------------------------- the scene
const view = $("view");
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f4f6);
scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8a90, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
scene.add(sun);

const frameOf = (i) => A.frames.get(Number(/f(\d+)\.js$/.exec(list[i][1])[1]));
const haveImage = !!ctx.image;
const triangles = ctx.triangles && ctx.triangles.length ? ctx.triangles : boundary(ctx.tetrahedra || []);
const lines = ctx.lines || [];
const pins = ctx.pins || [];

// The triangles of a tetrahedral mesh's boundary (the faces of one tetrahedron only).
function boundary(tets) {
  const seen = new Map();
  for (const [a, b, c, d] of tets) {
    for (const f of [[a, c, b], [a, b, d], [a, d, c], [b, c, d]]) {
      const key = [...f].sort((x, y) => x - y).join(",");
      if (seen.has(key)) seen.delete(key); else seen.set(key, f);
    }
  }
  return [...seen.values()];
}

// Bounds of everything drawn over the whole run: points of every loaded frame and the props.
function runBounds() {
  const box = new THREE.Box3();
  const p = new THREE.Vector3();
  for (let i = 0; i < list.length; i++) {
    const f = frameOf(i);
    if (!f) continue;
    const x = f.parts.points.values;
    for (let k = 0; k < x.length; k += 3) box.expandByPoint(p.set(x[k], x[k + 1], x[k + 2]));
  }
  const moving = [];
  for (let i = 0; i < list.length; i++) { const f = frameOf(i); if (f) moving.push(...f.props); }
  for (const prop of props.concat(moving)) {
    const [kind, v] = Object.entries(prop)[0];
    if (kind === "Sphere") { box.expandByPoint(p.fromArray(v.center).addScalar(v.radius)); box.expandByPoint(p.fromArray(v.center).addScalar(-v.radius)); }
    if (kind === "Cuboid" || kind === "Tank") { box.expandByPoint(p.fromArray(v.lo)); box.expandByPoint(p.fromArray(v.hi)); }
    if (kind === "Capsule") { box.expandByPoint(p.fromArray(v.a)); box.expandByPoint(p.fromArray(v.b)); }
    if (kind === "Attractor" || kind === "Anchor") box.expandByPoint(p.fromArray(v.at));
  }
  for (const m of ctx.mesh_props || []) for (const q of m.positions) box.expandByPoint(p.fromArray(q));
  if (haveImage) {
    const g = ctx.image;
    box.expandByPoint(p.fromArray(g.origin));
    box.expandByPoint(p.set(g.origin[0] + g.dims[0] * g.spacing, g.origin[1] + g.dims[1] * g.spacing, g.origin[2] + (g.dim === 3 ? g.dims[2] * g.spacing : 0)));
  }
  if (box.isEmpty()) box.set(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
  return box;
}

// A 2D scene lies in the plane z = 0 (a 2D solver, a system drawn in the plane).
function isFlat(box) {
  if (haveImage) return ctx.image.dim === 2;
  return (ctx.point_dim || 3) < 3 || box.max.z - box.min.z <= 1e-9 * Math.max(1, box.getSize(new THREE.Vector3()).length());
}

let camera, controls, flat = false, extent = 1, plane = null;
// An orthographic view of a 2D scene whose extent `plane` fills 90% of the picture.
function fitPlane(aspect) {
  const half = Math.max(plane.x / aspect, plane.y) * 0.55 + 1e-6 * extent;
  camera.left = -half * aspect; camera.right = half * aspect; camera.top = half; camera.bottom = -half;
  camera.updateProjectionMatrix();
}
function frameCamera() {
  const box = runBounds();
  flat = isFlat(box);
  const centre = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3());
  extent = Math.max(size.length(), 1e-6);
  const aspect = view.clientWidth / Math.max(view.clientHeight, 1);
  if (controls) controls.dispose();
  if (flat) {
    plane = size;
    camera = new THREE.OrthographicCamera(-1, 1, 1, -1, -10 * extent, 10 * extent);
    fitPlane(aspect);
    camera.position.set(centre.x, centre.y, centre.z + extent);
  } else {
    camera = new THREE.PerspectiveCamera(35, aspect, extent * 1e-3, extent * 100);
    const dir = new THREE.Vector3(0.55, 0.42, 1.0).normalize();
    const distance = (0.5 * extent) / Math.sin((35 * Math.PI) / 360) * 1.02;
    camera.position.copy(centre).addScaledVector(dir, distance);
  }
  camera.lookAt(centre);
  controls = new OrbitControls(camera, renderer.domElement);
  controls.target.copy(centre);
  controls.enableRotate = !flat;
  controls.update();
  controls.addEventListener("change", render);
  sun.position.copy(centre).add(new THREE.Vector3(0.4, 1.0, 0.6).multiplyScalar(extent));
  sun.target.position.copy(centre);
  scene.add(sun.target);
  return box;
}

// ---------------------------------------------------------------- the context
// A solid prop (sphere, capsule, box) as a mesh; null for any other prop.
function solid(kind, v) {
  if (kind === "Sphere") {
    const m = new THREE.Mesh(new THREE.SphereGeometry(v.radius, 48, 24), grey);
    m.position.fromArray(v.center);
    return m;
  }
  if (kind === "Capsule") {
    const a = new THREE.Vector3().fromArray(v.a), b = new THREE.Vector3().fromArray(v.b);
    const m = new THREE.Mesh(new THREE.CapsuleGeometry(v.radius, a.distanceTo(b), 8, 24), grey);
    m.position.copy(a).add(b).multiplyScalar(0.5);
    m.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), b.clone().sub(a).normalize());
    return m;
  }
  if (kind === "Cuboid") {
    const lo = new THREE.Vector3().fromArray(v.lo), hi = new THREE.Vector3().fromArray(v.hi);
    const s = hi.clone().sub(lo).max(new THREE.Vector3(1e-4, 1e-4, 1e-4).multiplyScalar(extent));
    const m = new THREE.Mesh(new THREE.BoxGeometry(s.x, s.y, s.z), grey);
    m.position.copy(lo).add(hi).multiplyScalar(0.5);
    return m;
  }
  return null;
}
// The props that move with the scene, redrawn at each frame shown.
const movingProps = new THREE.Group();
scene.add(movingProps);
function showMoving(f) {
  for (const m of movingProps.children) m.geometry.dispose();
  movingProps.clear();
  for (const prop of f.props || []) {
    const [kind, v] = Object.entries(prop)[0];
    const m = solid(kind, v);
    if (m) movingProps.add(m);
  }
}
const grey = new THREE.MeshStandardMaterial({ color: 0x9a9aa2, roughness: 0.8 });
const wall = new THREE.MeshStandardMaterial({ color: 0x6a8caf, transparent: true, opacity: 0.12, side: THREE.DoubleSide, depthWrite: false });
const edge = new THREE.LineBasicMaterial({ color: 0x4a6a8a });
let anchors = [];
function addContext(box) {
  const size = box.getSize(new THREE.Vector3()), centre = box.getCenter(new THREE.Vector3());
  for (const prop of props) {
    const [kind, v] = Object.entries(prop)[0];
    if (kind === "Ground" && !flat) {
      const span = 3 * Math.max(size.x, size.z, 1e-3);
      const grid = new THREE.GridHelper(span, 30, 0xb0b0b8, 0xd0d0d6);
      grid.position.set(centre.x, v.height, centre.z);
      scene.add(grid);
      const floor = new THREE.Mesh(new THREE.PlaneGeometry(span, span), new THREE.MeshStandardMaterial({ color: 0xe4e4e8 }));
      floor.rotation.x = -Math.PI / 2;
      floor.position.set(centre.x, v.height - 1e-4 * span, centre.z);
      scene.add(floor);
    } else if (kind === "Ground") {
      const g = new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(box.min.x - size.x, v.height, 0), new THREE.Vector3(box.max.x + size.x, v.height, 0)]);
      scene.add(new THREE.Line(g, edge));
    } else if (kind === "Sphere" || kind === "Capsule" || kind === "Cuboid") {
      scene.add(solid(kind, v));
    } else if (kind === "Tank") {
      const [lo, hi] = [v.lo, v.hi];
      if (flat || hi[2] - lo[2] <= 0) {
        const z = lo[2];
        const pts = [[lo[0], hi[1]], [lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]]].map(([x, y]) => new THREE.Vector3(x, y, z));
        scene.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), edge));
      } else {
        const s = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        const c = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
        const shell = new THREE.BoxGeometry(...s);
        const walls = new THREE.Mesh(shell, wall);
        walls.position.copy(c);
        scene.add(walls);
        const lines = new THREE.LineSegments(new THREE.EdgesGeometry(shell), edge);
        lines.position.copy(c);
        scene.add(lines);
      }
    } else if (kind === "Attractor") {
      const m = new THREE.Mesh(new THREE.SphereGeometry(0.04 * extent, 24, 12), new THREE.MeshBasicMaterial({ color: 0xf2b600 }));
      m.position.fromArray(v.at);
      scene.add(m);
    } else if (kind === "Anchor") {
      const m = new THREE.Mesh(new THREE.BoxGeometry(0.03 * extent, 0.12 * extent, 0.03 * extent), new THREE.MeshBasicMaterial({ color: 0x555555 }));
      m.position.fromArray(v.at);
      scene.add(m);
      const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints([m.position.clone(), m.position.clone()]), new THREE.LineBasicMaterial({ color: 0x555555 }));
      scene.add(line);
      anchors.push({ line, point: v.point, at: m.position.clone() });
    }
  }
  for (const mesh of ctx.mesh_props || []) {
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.Float32BufferAttribute(mesh.positions.flat(), 3));
    g.setIndex(mesh.triangles.flat());
    g.computeVertexNormals();
    scene.add(new THREE.Mesh(g, grey));
  }
}

// ---------------------------------------------------------------- the bodies
let body = null, links = null, marks = null, image = null, colors = null, material = null;
const up = new THREE.Vector3(0, 1, 0), tmpA = new THREE.Vector3(), tmpB = new THREE.Vector3(), tmpM = new THREE.Matrix4(), tmpQ = new THREE.Quaternion(), tmpS = new THREE.Vector3();
function pointRadius() {
  return ctx.point_radius > 0 ? ctx.point_radius : 0.006 * extent;
}
function disc() {
  const c = document.createElement("canvas");
  c.width = c.height = 64;
  const g = c.getContext("2d");
  const grad = g.createRadialGradient(26, 26, 4, 32, 32, 31);
  grad.addColorStop(0, "#ffffff"); grad.addColorStop(0.75, "#d8d8d8"); grad.addColorStop(1, "#9a9a9a");
  g.fillStyle = grad; g.beginPath(); g.arc(32, 32, 31, 0, 2 * Math.PI); g.fill();
  return new THREE.CanvasTexture(c);
}
function buildBodies(first) {
  const n = first ? first.n : 0;
  if (haveImage) {
    const g = ctx.image;
    if (g.dim === 2) {
      const data = new Uint8Array(4 * g.dims[0] * g.dims[1]);
      const tex = new THREE.DataTexture(data, g.dims[0], g.dims[1], THREE.RGBAFormat);
      tex.colorSpace = THREE.SRGBColorSpace; // the bytes are sRGB viridis, as in the previews
      tex.magFilter = THREE.LinearFilter;
      const m = new THREE.Mesh(new THREE.PlaneGeometry(g.dims[0] * g.spacing, g.dims[1] * g.spacing), new THREE.MeshBasicMaterial({ map: tex }));
      m.position.set(g.origin[0] + (g.dims[0] * g.spacing) / 2, g.origin[1] + (g.dims[1] * g.spacing) / 2, g.origin[2]);
      scene.add(m);
      image = { tex, data };
    } else {
      const geo = new THREE.BufferGeometry();
      const cells = g.dims[0] * g.dims[1] * g.dims[2];
      geo.setAttribute("position", new THREE.BufferAttribute(new Float32Array(3 * cells), 3));
      geo.setAttribute("color", new THREE.BufferAttribute(new Float32Array(3 * cells), 3));
      const pts = new THREE.Points(geo, new THREE.PointsMaterial({ size: 1.2 * g.spacing, vertexColors: true, transparent: true, opacity: 0.35, depthWrite: false }));
      scene.add(pts);
      image = { points: pts };
    }
    return;
  }
  colors = new Float32Array(3 * n);
  if (triangles.length) {
    const geo = new THREE.BufferGeometry();
    geo.setAttribute("position", new THREE.BufferAttribute(new Float32Array(3 * n), 3));
    geo.setAttribute("color", new THREE.BufferAttribute(colors, 3));
    geo.setIndex(triangles.flat());
    material = new THREE.MeshStandardMaterial({ vertexColors: true, side: THREE.DoubleSide, roughness: 0.7, flatShading: false });
    body = new THREE.Mesh(geo, material);
    scene.add(body);
  } else if (lines.length) {
    const r = Math.max(0.004 * extent, Math.min(pointRadius(), 0.02 * extent)) * 0.6;
    links = new THREE.InstancedMesh(new THREE.CylinderGeometry(r, r, 1, 10, 1), new THREE.MeshStandardMaterial({ color: 0x4a5a6a }), lines.length);
    scene.add(links);
    const joints = new THREE.InstancedMesh(new THREE.SphereGeometry(1.6 * r, 12, 8), new THREE.MeshStandardMaterial({ color: 0xffffff }), n);
    body = joints;
    scene.add(joints);
  } else {
    const geo = new THREE.BufferGeometry();
    geo.setAttribute("position", new THREE.BufferAttribute(new Float32Array(3 * n), 3));
    geo.setAttribute("color", new THREE.BufferAttribute(colors, 3));
    material = new THREE.PointsMaterial({ size: 2 * pointRadius(), vertexColors: true, map: disc(), alphaTest: 0.5 });
    body = new THREE.Points(geo, material);
    scene.add(body);
  }
  if (pins.length) {
    marks = new THREE.InstancedMesh(new THREE.SphereGeometry(Math.max(pointRadius(), 0.008 * extent) * 1.5, 12, 8), new THREE.MeshBasicMaterial({ color: 0xd02020 }), pins.length);
    scene.add(marks);
  }
}

// ---------------------------------------------------------------- colouring
const options = [];
function colourOptions(first) {
  options.length = 0;
  options.push({ label: "none", name: null });
  if (!first) return;
  for (const [name, part] of Object.entries(first.parts)) {
    if (name === "points") continue;
    const categorical = /material/.test(name);
    const label = part.comps === 1 ? name : name === "velocity" ? "speed" : `|${name}|`;
    options.push({ label, name, comps: part.comps, categorical, range: part.range || null });
  }
  // The range of each option over every loaded frame.
  for (const o of options) {
    if (!o.name || o.range) continue;
    let lo = Infinity, hi = -Infinity;
    for (let i = 0; i < list.length; i++) {
      const f = frameOf(i);
      if (!f || !f.parts[o.name]) continue;
      const v = f.parts[o.name].values;
      for (let k = 0; k < v.length; k += o.comps) {
        const s = scalar(v, k, o.comps);
        if (s < lo) lo = s;
        if (s > hi) hi = s;
      }
    }
    o.range = lo <= hi ? [lo, hi > lo ? hi : lo + 1] : [0, 1];
  }
}
function scalar(v, k, comps) {
  if (comps === 1) return v[k];
  let s = 0;
  for (let c = 0; c < comps; c++) s += v[k + c] * v[k + c];
  return Math.sqrt(s);
}
function paint(f, o, out) {
  const n = out.length / 3;
  if (!o || !o.name || !f.parts[o.name]) {
    for (let i = 0; i < n; i++) { out.set(BODY, 3 * i); linear(out, 3 * i); }
    return;
  }
  const v = f.parts[o.name].values, [lo, hi] = o.range;
  for (let i = 0; i < n; i++) {
    const s = scalar(v, i * o.comps, o.comps);
    if (o.categorical) out.set(PALETTE[Math.abs(Math.round(s)) % PALETTE.length], 3 * i);
    else viridis((s - lo) / (hi - lo), out, 3 * i);
    linear(out, 3 * i);
  }
}
function legend(o) {
  const el = $("legend");
  el.innerHTML = "";
  if (!o || !o.name || o.categorical) { if (o && o.categorical) el.textContent = `${o.label}: one colour each`; return; }
  const c = document.createElement("canvas");
  c.width = 160; c.height = 10;
  const g = c.getContext("2d"), px = [0, 0, 0];
  for (let x = 0; x < 160; x++) { viridis(x / 159, px, 0); g.fillStyle = `rgb(${px.map((q) => Math.round(255 * q)).join(",")})`; g.fillRect(x, 0, 1, 10); }
  el.textContent = `${o.label}: ${o.range[0].toPrecision(3)} to ${o.range[1].toPrecision(3)}`;
  el.appendChild(c);
}

// ---------------------------------------------------------------- showing a frame
let current = 0, shown = null;
function show(i) {
  current = Math.max(0, Math.min(i, list.length - 1));
  const f = frameOf(current);
  $("slider").value = String(current);
  if (!f) { status(`frame ${current} is still loading`); return; }
  showMoving(f);
  const o = options[Number($("color").value) || 0];
  $("time").textContent = `t = ${f.t.toFixed(3)} s  (${current + 1}/${list.length})`;
  if (image) {
    const part = Object.values(f.parts).find((p) => p.cells);
    if (part) showImage(part, o && o.name ? o : { range: part.range });
  } else if (body) {
    const x = f.parts.points.values;
    if (links) {
      for (let k = 0; k < f.n; k++) { tmpM.makeTranslation(x[3 * k], x[3 * k + 1], x[3 * k + 2]); body.setMatrixAt(k, tmpM); }
      body.instanceMatrix.needsUpdate = true;
      lines.forEach(([a, b], k) => {
        tmpA.fromArray(x, 3 * a); tmpB.fromArray(x, 3 * b);
        const d = tmpB.clone().sub(tmpA), len = d.length();
        tmpQ.setFromUnitVectors(up, len > 0 ? d.divideScalar(len) : up);
        tmpM.compose(tmpA.add(tmpB).multiplyScalar(0.5), tmpQ, tmpS.set(1, Math.max(len, 1e-9), 1));
        links.setMatrixAt(k, tmpM);
      });
      links.instanceMatrix.needsUpdate = true;
      body.computeBoundingSphere();
      links.computeBoundingSphere();
    } else {
      const pos = body.geometry.attributes.position;
      pos.array.set(x.subarray(0, pos.array.length));
      pos.needsUpdate = true;
      paint(f, o, colors);
      body.geometry.attributes.color.needsUpdate = true;
      if (triangles.length) body.geometry.computeVertexNormals();
      body.geometry.computeBoundingSphere();
    }
    if (marks) {
      pins.forEach((p, k) => { tmpM.makeTranslation(x[3 * p], x[3 * p + 1], x[3 * p + 2]); marks.setMatrixAt(k, tmpM); });
      marks.instanceMatrix.needsUpdate = true;
      marks.computeBoundingSphere();
    }
    for (const a of anchors) {
      const g = a.line.geometry.attributes.position;
      g.setXYZ(1, x[3 * a.point], x[3 * a.point + 1], x[3 * a.point + 2]);
      g.needsUpdate = true;
    }
  }
  shown = f;
  render();
}
function showImage(part, o) {
  const g = ctx.image, [lo, hi] = o.range || part.range, v = part.values;
  const scale = hi > lo ? 1 / (hi - lo) : 1;
  if (image.tex) {
    const rgb = [0, 0, 0];
    for (let c = 0; c < v.length; c++) {
      viridis((v[c] - lo) * scale, rgb, 0);
      image.data[4 * c] = 255 * rgb[0]; image.data[4 * c + 1] = 255 * rgb[1]; image.data[4 * c + 2] = 255 * rgb[2]; image.data[4 * c + 3] = 255;
    }
    image.tex.needsUpdate = true;
  } else {
    const pos = image.points.geometry.attributes.position, col = image.points.geometry.attributes.color;
    let m = 0;
    for (let z = 0; z < g.dims[2]; z++) for (let y = 0; y < g.dims[1]; y++) for (let x = 0; x < g.dims[0]; x++) {
      const c = x + g.dims[0] * (y + g.dims[1] * z), s = (v[c] - lo) * scale;
      if (s < 0.05) continue;
      pos.setXYZ(m, g.origin[0] + (x + 0.5) * g.spacing, g.origin[1] + (y + 0.5) * g.spacing, g.origin[2] + (z + 0.5) * g.spacing);
      viridis(s, col.array, 3 * m);
      linear(col.array, 3 * m);
      m++;
    }
    image.points.geometry.setDrawRange(0, m);
    pos.needsUpdate = true; col.needsUpdate = true;
    image.points.geometry.computeBoundingSphere();
  }
}
function render() {
  if (!camera) return;
  // An orthographic camera draws points at their size in pixels: keep them their size in metres.
  if (flat && body && body.isPoints) body.material.size = (2 * pointRadius() * renderer.domElement.height * camera.zoom) / (camera.top - camera.bottom) / renderer.getPixelRatio();
  renderer.render(scene, camera);
}
function resize() {
  const w = view.clientWidth, h = Math.max(view.clientHeight, 1);
  renderer.setSize(w, h);
  if (camera && camera.isPerspectiveCamera) { camera.aspect = w / h; camera.updateProjectionMatrix(); }
  if (camera && camera.isOrthographicCamera) fitPlane(w / h);
  render();
}

// ---------------------------------------------------------------- controls
let playing = !hash.has("pause"), last = 0;
$("play").onclick = () => { playing = !playing; $("play").textContent = playing ? "pause" : "play"; };
$("slider").oninput = (e) => { playing = false; $("play").textContent = "play"; show(Number(e.target.value)); };
$("color").onchange = () => { legend(options[Number($("color").value)]); show(current); };
window.addEventListener("keydown", (e) => { if (e.code === "Space") { e.preventDefault(); $("play").click(); } });
window.addEventListener("resize", resize);
function tick(now) {
  requestAnimationFrame(tick);
  if (playing && list.length > 1 && now - last > 33) { last = now; show((current + 1) % list.length); }
}

// ---------------------------------------------------------------- loading
function load(src) {
  return new Promise((ok, fail) => {
    const s = document.createElement("script");
    s.src = src; s.onload = ok; s.onerror = () => fail(new Error(src));
    document.head.appendChild(s);
  });
}
async function main() {
  if (!A.ctx || !A.list) { status("viewer/context.js or viewer/index.js is missing beside this page"); return; }
  if (!list.length) { status("the run wrote no frames yet"); return; }
  $("slider").max = String(list.length - 1);
  for (let i = 0; i < list.length; i++) {
    try { await load(`viewer/${list[i][1]}`); } catch (e) { status(`cannot load ${e.message}`); }
    if (i % 20 === 0) status(`loading ${i + 1}/${list.length}`);
  }
  status("");
  const box = frameCamera();
  addContext(box);
  const first = frameOf(0);
  buildBodies(first);
  colourOptions(first);
  const select = $("color");
  options.forEach((o, k) => select.add(new Option(o.label, String(k))));
  const asked = hash.get("color");
  let pick = asked ? options.findIndex((o) => o.label === asked || o.name === asked) : -1;
  // Materials by default where there are several; one material shows nothing.
  const several = (o) => { const v = first && first.parts[o.name] ? first.parts[o.name].values : []; return v.some((x) => x !== v[0]); };
  if (pick < 0) pick = options.findIndex((o) => o.categorical && several(o));
  if (pick < 0 && !triangles.length && !lines.length) pick = options.findIndex((o) => o.name === "velocity");
  if (pick < 0 && haveImage) pick = options.findIndex((o) => o.range && o.name);
  select.value = String(Math.max(pick, 0));
  legend(options[Math.max(pick, 0)]);
  resize();
  const f = hash.get("frame");
  show(f === "last" ? list.length - 1 : Number(f) || 0);
  if (hash.has("frame")) { playing = false; $("play").textContent = "play"; }
  document.body.dataset.ready = "1";
  requestAnimationFrame(tick);
}
main();
