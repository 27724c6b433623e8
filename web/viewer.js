// hiveslam live view: draws what /events pushes (see src/viz/web/view_stream.hpp).
'use strict';

const palette = [0x4fc3f7, 0xffb74d, 0x81c784, 0xe57373, 0xba68c8, 0xfff176, 0x4db6ac, 0xf06292];

const canvas = document.getElementById('scene');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setClearColor(0x15171c);
const scene = new THREE.Scene();
// The map frame is a camera's: x right, y down, z forward. Turned half a turn about x, y points up.
const world = new THREE.Group();
world.rotation.x = Math.PI;
scene.add(world);
world.updateMatrixWorld();  // fit() maps points through it before the first frame is drawn
const camera = new THREE.PerspectiveCamera(60, 1, 0.01, 1000);
camera.position.set(0, 2, -4);
const controls = new THREE.OrbitControls(camera, canvas);
controls.enableDamping = true;
// The view fits the map as it grows until the user moves it.
let userMoved = false;
controls.addEventListener('start', () => { userMoved = true; });

let markerScale = 1;
const nodes = new Map();  // name -> {points, frusta, covisibility, loops, path, pathCount, camera, fitted}

function nodeObjects(name) {
  if (nodes.has(name)) return nodes.get(name);
  const o = { pathXyz: new Float32Array(3 * 1024), pathCount: 0 };
  o.path = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0xff5252 }));
  o.path.geometry.setAttribute('position', new THREE.BufferAttribute(o.pathXyz, 3));
  o.path.geometry.setDrawRange(0, 0);
  o.path.frustumCulled = false;
  world.add(o.path);
  o.camera = cameraMarker();
  o.camera.visible = false;
  world.add(o.camera);
  nodes.set(name, o);
  return o;
}

function cameraMarker() {
  const s = 0.1, w = s, h = 0.75 * s, d = 0.8 * s;
  const c = [[-w, -h, d], [w, -h, d], [w, h, d], [-w, h, d]];
  const v = [];
  for (let i = 0; i < 4; i++) v.push(0, 0, 0, ...c[i], ...c[i], ...c[(i + 1) % 4]);
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(v, 3));
  const m = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: 0xffffff }));
  m.matrixAutoUpdate = false;
  return m;
}

function decode(b64, Type) {
  const bin = atob(b64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return new Type(bytes.buffer);
}

function replace(o, key, object) {
  if (o[key]) { world.remove(o[key]); o[key].geometry.dispose(); }
  o[key] = object;
  if (object) world.add(object);
}

function lines(b64, color, opacity) {
  const xyz = decode(b64, Float32Array);
  if (xyz.length === 0) return null;
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
  return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color, transparent: opacity < 1, opacity }));
}

function onScene(e) {
  const m = JSON.parse(e.data);
  const o = nodeObjects(m.node);
  const xyz = decode(m.points, Float32Array);
  const labels = decode(m.labels, Uint8Array);
  const colors = new Float32Array(xyz.length);
  const c = new THREE.Color();
  for (let i = 0; i < labels.length; i++) {
    c.setHex(palette[labels[i] % palette.length]);
    colors[3 * i] = c.r; colors[3 * i + 1] = c.g; colors[3 * i + 2] = c.b;
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
  g.setAttribute('color', new THREE.BufferAttribute(colors, 3));
  replace(o, 'points', new THREE.Points(g, new THREE.PointsMaterial({ size: 3, sizeAttenuation: false, vertexColors: THREE.VertexColors })));
  replace(o, 'frusta', lines(m.frusta, 0x5c7cfa, 1));
  replace(o, 'covisibility', lines(m.covisibility, 0x43a047, 0.35));
  replace(o, 'loops', lines(m.loops, 0xff1744, 1));
  if (!userMoved && xyz.length >= 30) fit(o.points);
}

// Centre and radius of the bulk of the points: the median and the 80th percentile distance,
// so that a few far points (badly triangulated, or seen at the horizon) do not shrink the map
// to a dot.
function fit(object) {
  const xyz = object.geometry.attributes.position.array;
  const n = xyz.length / 3, stride = Math.max(1, Math.floor(n / 4000));
  const xs = [], ys = [], zs = [];
  for (let i = 0; i < n; i += stride) { xs.push(xyz[3 * i]); ys.push(xyz[3 * i + 1]); zs.push(xyz[3 * i + 2]); }
  const median = a => a.slice().sort((p, q) => p - q)[a.length >> 1];
  const c = new THREE.Vector3(median(xs), median(ys), median(zs));
  const d = xs.map((x, i) => Math.hypot(x - c.x, ys[i] - c.y, zs[i] - c.z)).sort((p, q) => p - q);
  const r = Math.max(d[Math.floor(0.8 * (d.length - 1))], 0.1);
  const centre = world.localToWorld(c);
  controls.target.copy(centre);
  camera.position.copy(centre).add(new THREE.Vector3(0, 1.2 * r, 2.0 * r));
  camera.near = r / 1000; camera.far = r * 200; camera.updateProjectionMatrix();
  markerScale = r / 8 / 0.1;  // the camera drawn an eighth of the map's radius wide
}

function onPath(e) {
  const m = JSON.parse(e.data);
  const o = nodeObjects(m.node);
  if (m.reset) o.pathCount = 0;
  const xyz = decode(m.xyz, Float32Array);
  const need = 3 * o.pathCount + xyz.length;
  if (need > o.pathXyz.length) {
    const grown = new Float32Array(Math.max(need, 2 * o.pathXyz.length));
    grown.set(o.pathXyz.subarray(0, 3 * o.pathCount));
    o.pathXyz = grown;
    o.path.geometry.setAttribute('position', new THREE.BufferAttribute(o.pathXyz, 3));
  }
  o.pathXyz.set(xyz, 3 * o.pathCount);
  o.pathCount += xyz.length / 3;
  o.path.geometry.attributes.position.needsUpdate = true;
  o.path.geometry.setDrawRange(0, o.pathCount);
}

function onCamera(e) {
  const m = JSON.parse(e.data);
  const o = nodeObjects(m.node);
  o.camera.visible = true;
  o.camera.matrix.fromArray(m.T).multiply(new THREE.Matrix4().makeScale(markerScale, markerScale, markerScale));
  o.camera.material.color.setHex(m.tracked ? 0xffffff : 0x777777);
  if (m.tracked && document.getElementById('follow').checked) {
    const p = world.localToWorld(new THREE.Vector3(m.T[12], m.T[13], m.T[14]));
    camera.position.add(p.clone().sub(controls.target));
    controls.target.copy(p);
  }
}

function onImage(e) {
  const m = JSON.parse(e.data);
  document.getElementById('camera-image').src = 'data:image/jpeg;base64,' + m.jpeg;
  document.getElementById('camera-caption').textContent = m.node + ', frame ' + m.frame;
}

const rows = [
  ['tasks', v => (v.tasks || []).join(', ')], ['peers', v => v.peers],
  ['tracked frames', v => v.frames ? v.tracked_frames + ' / ' + v.frames : '–', 'tracked'],
  ['tracking ms (median)', v => v.tracking_ms !== undefined ? v.tracking_ms.toFixed(1) : '–'],
  ['maps', v => v.maps], ['keyframes', v => v.keyframes], ['map points', v => v.map_points],
  ['loops / merges', v => v.loops + ' / ' + v.merges],
  ['CPU %', v => v.cpu_percent !== undefined ? v.cpu_percent.toFixed(0) : '–'],
  ['kbit/s in / out', v => v.kbps_in !== undefined ? v.kbps_in.toFixed(0) + ' / ' + v.kbps_out.toFixed(0) : '–'],
  ['keyframe / map msgs/s', v => v.keyframe_msgs_hz !== undefined ? v.keyframe_msgs_hz.toFixed(1) + ' / ' + v.map_msgs_hz.toFixed(1) : '–'],
];

function onPanel(e) {
  const m = JSON.parse(e.data);
  const box = document.getElementById('nodes');
  box.textContent = '';
  m.nodes.forEach((n, i) => {
    const v = n.values;
    const div = document.createElement('div');
    div.className = 'node';
    div.dataset.node = n.name;
    const h = document.createElement('h2');
    const sw = document.createElement('span');
    sw.className = 'swatch';
    sw.style.background = '#' + palette[i % palette.length].toString(16).padStart(6, '0');
    h.append(sw, document.createTextNode(n.name));
    div.append(h);
    const table = document.createElement('table');
    for (const [label, f, cls] of rows) {
      const tr = table.insertRow();
      tr.insertCell().textContent = label;
      const td = tr.insertCell();
      td.className = 'value' + (cls ? ' ' + cls : '');
      let text = '–';
      try { const x = f(v); if (x !== undefined && x !== null && x !== 'undefined / undefined') text = String(x); } catch (err) { /* a value this node does not report */ }
      td.textContent = text;
      if (cls === 'tracked') td.dataset.count = v.tracked_frames !== undefined ? v.tracked_frames : 0;
    }
    div.append(table);
    const ul = document.createElement('ul');
    ul.className = 'events';
    n.events.slice(-8).reverse().forEach(ev => {
      const li = document.createElement('li');
      li.textContent = ev.t.toFixed(1) + ' s: ' + ev.text;
      ul.append(li);
    });
    div.append(ul);
    box.append(div);
  });
}

const status = document.getElementById('connection');
const source = new EventSource('events');
// ?panels=N: stop listening after N panel updates (about N seconds). A headless browser takes
// its screenshot once the page's network is idle, and a live stream never is.
const panelsWanted = Number(new URLSearchParams(location.search).get('panels') || 0);
let panelsSeen = 0;
source.addEventListener('panel', () => {
  if (panelsWanted > 0 && ++panelsSeen >= panelsWanted) {
    source.close();
    status.textContent = 'paused after ' + panelsSeen + ' updates';
    status.className = '';
  }
});
source.onopen = () => { status.textContent = 'live'; status.className = 'live'; };
source.onerror = () => { status.textContent = 'disconnected: retrying'; status.className = 'lost'; };
source.addEventListener('scene', onScene);
source.addEventListener('path', onPath);
source.addEventListener('camera', onCamera);
source.addEventListener('image', onImage);
source.addEventListener('panel', onPanel);

document.getElementById('fit').onclick = () => {
  userMoved = false;
  for (const o of nodes.values()) if (o.points) { fit(o.points); break; }
};

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== w || canvas.height !== h) {
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
  }
}

function frame() {
  resize();
  controls.update();
  renderer.render(scene, camera);
  requestAnimationFrame(frame);
}
requestAnimationFrame(frame);
