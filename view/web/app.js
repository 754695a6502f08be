// frep view's page: polls /api/state, draws the mesh of the last successful `frep mesh` (glTF,
// Z-up), shows the error frep printed (file:line:column) in place, and slices from /api/slice.
// The body's data-status, data-generation and data-drawn attributes say what is on screen
// (the browser test waits on them).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { toCreasedNormals } from 'three/addons/utils/BufferGeometryUtils.js';

const $ = (id) => document.getElementById(id);
const canvas = $('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setClearColor(0x1e2228);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(35, 1, 0.001, 1e6);
camera.up.set(0, 0, 1);  // the model's axes: z up, as frep render
scene.add(camera);
const hemisphere = new THREE.HemisphereLight(0xffffff, 0x303030, 1.6);
hemisphere.position.set(0, 0, 1);
scene.add(hemisphere);
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(1, 1, 2);  // attached to the camera: the lit side faces the viewer
camera.add(sun);
const controls = new OrbitControls(camera, canvas);
controls.addEventListener('change', draw);

let model = null;       // the group of the drawn mesh
let frame = null;       // the -b box, drawn as lines
let slicePlane = null;  // the outline of the slice's plane
let bounds = null;      // [xmin, ymin, zmin, xmax, ymax, zmax]
let meshGeneration = 0, stateGeneration = -1, loading = false;

function draw() { renderer.render(scene, camera); }

function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  renderer.setSize(w, h, false);
  renderer.setPixelRatio(window.devicePixelRatio);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  draw();
}
window.addEventListener('resize', resize);

// The camera looks at the box from frep render's default direction (azimuth -60, elevation 25)
// and stays there: an edit that grows the solid shows it bigger.
function fitBox(b) {
  const box = new THREE.Box3(new THREE.Vector3(b[0], b[1], b[2]), new THREE.Vector3(b[3], b[4], b[5]));
  frame = new THREE.Box3Helper(box, 0x59616b);
  scene.add(frame);
  const centre = box.getCenter(new THREE.Vector3());
  const radius = box.getSize(new THREE.Vector3()).length() / 2;
  const az = THREE.MathUtils.degToRad(-60), el = THREE.MathUtils.degToRad(25);
  const dir = new THREE.Vector3(Math.cos(el) * Math.cos(az), Math.cos(el) * Math.sin(az), Math.sin(el));
  const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2));
  camera.position.copy(centre).addScaledVector(dir, distance);
  controls.target.copy(centre);
  controls.update();
}

function showMesh(gltf, generation) {
  if (model) scene.remove(model);
  model = gltf.scene;
  model.traverse((o) => {
    if (!o.isMesh) return;
    const coloured = !!o.geometry.attributes.color;  // s[1..3] of the model
    // Smooth within 30 degrees, creased beyond: the simplifier keeps sharp edges, whose
    // vertices' normals would otherwise shade them as one smooth surface.
    o.geometry = toCreasedNormals(o.geometry, Math.PI / 6);
    o.material = new THREE.MeshLambertMaterial({
      color: coloured ? 0xffffff : 0xcc9e61, vertexColors: coloured, side: THREE.DoubleSide });
  });
  scene.add(model);
  draw();
  meshGeneration = generation;
  document.body.dataset.drawn = generation;
}

async function loadMesh(generation) {
  loading = true;
  try {
    const response = await fetch('/api/mesh');
    const drawn = Number(response.headers.get('X-Generation'));
    const data = await response.arrayBuffer();
    const gltf = await new GLTFLoader().parseAsync(data, '');
    showMesh(gltf, drawn || generation);
  } catch (e) {
    showError('the page could not draw the mesh: ' + e);
  } finally {
    loading = false;
  }
}

function showError(text) {
  $('error').hidden = !text;
  $('error').textContent = text || '';
}

function showState(s) {
  document.body.dataset.status = s.status;
  document.body.dataset.generation = s.generation;
  $('model').textContent = s.model;
  $('status').textContent = s.status === 'computing' ? 'computing (save ' + s.generation + ')' : s.status;
  $('status').className = 'badge ' + s.status;
  showError(s.status === 'error' ? s.message : '');
  $('report').textContent = s.report;
  $('log').textContent = s.command + '\n\n' + s.log;
  $('reportJson').textContent = s.report_json ? JSON.stringify(s.report_json, null, 1) : '';
  const interrupted = s.interrupted ? ', ' + s.interrupted + ' run(s) interrupted by newer saves' : '';
  $('timing').textContent = s.seconds ? s.seconds.toFixed(2) + ' s' + interrupted : interrupted;
  if (!bounds) {
    bounds = s.bounds;
    fitBox(bounds);
    setSliceRange();
    resize();
  }
  if (s.mesh_generation !== meshGeneration && !loading) loadMesh(s.mesh_generation);
  if (s.generation !== stateGeneration && s.status !== 'computing') {
    stateGeneration = s.generation;
    requestSlice();
  }
}

async function poll() {
  try {
    const response = await fetch('/api/state');
    showState(await response.json());
  } catch (e) {
    $('status').textContent = 'frep view is not running';
    $('status').className = 'badge error';
  }
  setTimeout(poll, 300);
}

// Slices: frep slice of the current file on the plane normal to the chosen axis.
function axisIndex() { return 'xyz'.indexOf($('axis').value); }

function setSliceRange() {
  const a = axisIndex();
  $('at').min = bounds[a];
  $('at').max = bounds[a + 3];
  $('at').value = (bounds[a] + bounds[a + 3]) / 2;
}

function showSlicePlane(at) {
  if (slicePlane) scene.remove(slicePlane);
  const a = axisIndex(), u = (a + 1) % 3, v = (a + 2) % 3;
  const corners = [[0, 0], [1, 0], [1, 1], [0, 1]].map(([i, j]) => {
    const p = [0, 0, 0];
    p[a] = at;
    p[u] = bounds[u + 3 * i];
    p[v] = bounds[v + 3 * j];
    return new THREE.Vector3(...p);
  });
  slicePlane = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(corners),
                                  new THREE.LineBasicMaterial({ color: 0x4aa3ff }));
  scene.add(slicePlane);
  draw();
}

let sliceTimer = null, sliceRequests = 0;
function requestSlice() {
  clearTimeout(sliceTimer);
  sliceTimer = setTimeout(async () => {
    const at = Number($('at').value), request = ++sliceRequests;
    $('atValue').textContent = $('axis').value + ' = ' + at.toPrecision(4);
    showSlicePlane(at);
    const response = await fetch(`/api/slice?axis=${$('axis').value}&at=${at}&res=256`);
    const body = response.ok ? await response.blob() : await response.text();
    if (request !== sliceRequests) return;  // a later request was made: its answer is shown
    $('sliceError').hidden = response.ok;
    if (response.ok) {
      const old = $('slice').src;
      $('slice').src = URL.createObjectURL(body);
      if (old) URL.revokeObjectURL(old);
    } else {
      $('sliceError').textContent = body;
    }
  }, 120);
}
$('at').addEventListener('input', requestSlice);
$('axis').addEventListener('change', () => { setSliceRange(); requestSlice(); });

resize();
poll();
