// The viewer: opens the stream named by ?src= (or a file dropped on the page), shows each level
// as it arrives with a progress bar and a line of figures, and orbits around the mesh. Its state
// is window.viewer.state (for people and for tests: the level shown, its figures, errors).
// A `came` stream named by ?src= is refined to the camera as it moves, its meta-nodes fetched by
// Range requests (?view=levels downloads it level by level instead); the figures then say the
// faces, the bytes read and the adaptation time.
// A glTF scene (.glb or .gltf; `meshcodec pack` makes progressive ones) is opened with three.js's
// GLTFLoader and the meshcodec plugin (gltf-plugin.js): the scene at once with each packed
// primitive's coarse fallback, then each primitive refined level by level; ?plugin=off opens it
// with the stock loader alone, as a viewer that has never heard of the extension would.
import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { MeshcodecLoader } from "../loader.js";
import { MeshcodecGLTFPlugin } from "../gltf-plugin.js";

const canvas = document.getElementById("view");
const fill = document.getElementById("fill");
const figures = document.getElementById("figures");
const errorLine = document.getElementById("error");
const source = document.getElementById("source");

const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x1d2127);
const camera = new THREE.PerspectiveCamera(40, 1, 0.001, 1000);
const controls = new OrbitControls(camera, canvas);
scene.add(new THREE.HemisphereLight(0xffffff, 0x44474f, 1.6));
const light = new THREE.DirectionalLight(0xffffff, 1.8);
camera.add(light);
light.position.set(0.5, 0.8, 1);
scene.add(camera);
const material = new THREE.MeshStandardMaterial({ color: 0xc9c2b6, roughness: 0.75, flatShading: false });

/** A checker texture, 16 squares a side of the uv square: shows the uvs, their seams and their
 * stretch. */
function checker() {
  const canvas = document.createElement("canvas");
  canvas.width = canvas.height = 512;
  const context = canvas.getContext("2d");
  for (let i = 0; i < 16; i++) {
    for (let j = 0; j < 16; j++) {
      context.fillStyle = (i + j) % 2 ? "#e9e4da" : "#5f6f86";
      context.fillRect(i * 32, j * 32, 32, 32);
    }
  }
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.SRGBColorSpace;
  texture.wrapS = texture.wrapT = THREE.RepeatWrapping;
  texture.anisotropy = 4;
  return texture;
}
const checkerTexture = checker();

/** The materials for a level: the checker through its uvs, its colours, one material a group
 * (a hue each) where it has several. */
function materialsFor(geometry, level) {
  const appearance = level.appearance;
  if (!appearance) return material;
  const make = (hue) =>
    new THREE.MeshStandardMaterial({
      color: hue === undefined ? 0xffffff : new THREE.Color().setHSL(hue, 0.35, 0.75),
      roughness: 0.75,
      map: geometry.getAttribute("uv") ? checkerTexture : null,
      vertexColors: Boolean(geometry.getAttribute("color")),
      side: THREE.DoubleSide,
    });
  const names = level.materials;
  if (names.length > 1) return names.map((_, i) => make(i / names.length));
  return make();
}

const state = { status: "idle", level: 0, levels: 0, levelsSeen: [], received: 0, total: 0, faces: 0, vertices: 0, error: null, frames: 0 };
window.viewer = { state, scene, camera, mesh: null };

const loader = new MeshcodecLoader();
loader.viewDependent = new URLSearchParams(location.search).get("view") !== "levels";
let mesh = null;
let framed = false;
/** The address's camera while the controls have not moved it. */
let exactCamera = null;

function resize() {
  const { clientWidth: w, clientHeight: h } = canvas;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
}

/** The camera the address asks for (`eye`, `target`, `up` as x,y,z; `fov` in degrees), if any:
 * the view `meshcodec render` draws with the same numbers. */
function cameraFromAddress(params) {
  const vector = (name) => {
    const parts = params.get(name)?.split(",").map(Number);
    return parts?.length === 3 && parts.every(Number.isFinite) ? new THREE.Vector3(...parts) : null;
  };
  const eye = vector("eye");
  const target = vector("target");
  if (!eye || !target) return null;
  return { eye, target, up: vector("up") ?? new THREE.Vector3(0, 1, 0), fov: Number(params.get("fov")) || 50 };
}

function placeCamera({ eye, target, up, fov }) {
  const distance = eye.distanceTo(target);
  camera.fov = fov;
  camera.up.copy(up);
  camera.position.copy(eye);
  camera.near = distance / 1000;
  camera.far = distance * 100;
  camera.lookAt(target);
  camera.updateProjectionMatrix();
  controls.target.copy(target);
  controls.update();
}

/** Looks at the whole mesh from the front, a little above, once its first level is in. */
function frame(geometry) {
  const { center, radius } = geometry.boundingSphere;
  const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 1.1;
  camera.position.copy(center).add(new THREE.Vector3(0, 0.25, 1).normalize().multiplyScalar(distance));
  camera.near = distance / 100;
  camera.far = distance * 10;
  camera.updateProjectionMatrix();
  controls.target.copy(center);
  controls.update();
}

/** Looks at the box a came stream's grid spans, before any of its faces is in. */
function frameBox([low, high]) {
  const center = new THREE.Vector3(...low).add(new THREE.Vector3(...high)).multiplyScalar(0.5);
  const radius = new THREE.Vector3(...high).sub(new THREE.Vector3(...low)).length() / 2;
  frame({ boundingSphere: { center, radius } });
}

/** Asks the worker to adapt the came stream's mesh to the camera now (it adapts to the newest). */
function refineToCamera() {
  if (!mesh?.geometry?.userData.meshcodec?.came) return;
  const size = renderer.getDrawingBufferSize(new THREE.Vector2());
  // The address's camera exactly as given (`meshcodec view` takes the same numbers) until the
  // controls move it.
  const view = exactCamera
    ? { eye: exactCamera.eye.toArray(), target: exactCamera.target.toArray(), up: exactCamera.up.toArray(), fov: exactCamera.fov }
    : camera;
  loader.refine(mesh.geometry, view, size.x, size.y, { tolerance: state.tolerance, target: controls.target });
}

function showCame(f) {
  const share = f.streamBytes ? ` (${((100 * f.bytesRead) / f.streamBytes).toFixed(1)}%)` : "";
  const adapt = f.adaptMs === undefined ? "" : ` · adapted in ${f.adaptMs.toFixed(1)} ms`;
  figures.textContent =
    `${state.codec} · ${state.faces.toLocaleString()} faces · ${f.bytesRead.toLocaleString()} of ${f.streamBytes.toLocaleString()} bytes read${share}` +
    ` · ${f.unitsLoaded} of ${f.units} meta-nodes${adapt} · ${state.tolerance} px` +
    (state.came.settled ? "" : " · refining");
  fill.style.width = `${f.streamBytes ? (100 * f.bytesRead) / f.streamBytes : 0}%`;
}

function showFigures() {
  const bytes = state.total ? `${state.received.toLocaleString()} of ${state.total.toLocaleString()} bytes` : `${state.received.toLocaleString()} bytes`;
  const rate = state.meshVertices ? ` · ${((state.received * 8) / state.meshVertices).toFixed(2)} bits a vertex` : "";
  const carried = state.appearance?.length ? ` · ${state.appearance.join(", ")}` : "";
  figures.textContent = `${bytes} · level ${state.level} of ${state.levels} · ${state.faces.toLocaleString()} faces${rate}${carried}`;
  fill.style.width = `${state.total ? (100 * state.received) / state.total : 0}%`;
}

function open(request, name) {
  source.textContent = name;
  Object.assign(state, {
    status: "loading",
    level: 0,
    levels: 0,
    levelsSeen: [],
    received: 0,
    total: 0,
    faces: 0,
    vertices: 0,
    error: null,
    appearance: [],
    appearanceShown: false,
    levelsWithUvs: [],
    gltf: null,
    came: null,
    tolerance: Number(new URLSearchParams(location.search).get("tolerance")) || 1,
  });
  errorLine.textContent = "";
  framed = false;
  if (mesh) {
    scene.remove(mesh);
    mesh.geometry?.dispose();
  }
  const onProgress = ({ loaded, total }) => {
    state.received = loaded;
    state.total = total;
    showFigures();
  };
  const onLevel = (geometry, level) => {
    if (level.came) {
      const figures = level.figures;
      state.codec = level.codec;
      if (!state.came) {
        // Opened: the header, the index and the first meta-node are in.
        state.came = { opened: figures.bytesRead, settled: false, firstFrameBytes: 0, views: 0 };
        if (fixedCamera) placeCamera(fixedCamera);
        else frameBox(level.box);
        exactCamera = fixedCamera;
        framed = true;
        refineToCamera();
      } else {
        Object.assign(state.came, {
          settled: figures.settled,
          adaptMs: figures.adaptMs,
          bytesRead: figures.bytesRead,
          streamBytes: figures.streamBytes,
          unitsLoaded: figures.unitsLoaded,
          units: figures.units,
          firstFrameBytes: figures.firstFrameBytes,
          views: state.came.views + 1,
        });
        state.faces = figures.faces;
        state.vertices = figures.vertices;
        state.status = figures.settled ? "done" : "loading";
      }
      showCame(figures);
      return;
    }
    Object.assign(state, {
      level: level.level,
      levels: level.levels,
      faces: level.triangles,
      vertices: level.vertices,
      meshVertices: level.meshVertices,
      codec: level.codec,
    });
    state.levelsSeen.push(level.level);
    if (geometry.getAttribute("uv")) state.levelsWithUvs.push(level.level);
    state.appearance = level.appearance
      ? Object.keys(level.appearance).filter((k) => ["normals", "uvs", "colours", "materials"].includes(k))
      : [];
    if (level.appearance && !state.appearanceShown) {
      mesh.material = materialsFor(geometry, level);
      state.appearanceShown = true;
    }
    if (!framed) {
      if (fixedCamera) placeCamera(fixedCamera);
      else frame(geometry);
      framed = true;
    }
    showFigures();
  };
  const onLoad = () => {
    state.status = "done";
    fill.style.width = "100%";
    showFigures();
  };
  const onError = (error) => {
    state.status = "error";
    state.error = error.message;
    errorLine.textContent = error.message;
  };
  const geometry = request.url
    ? loader.load(request.url, onLoad, onProgress, onError, onLevel)
    : loader.parse(request.bytes, onLoad, onError, onLevel);
  mesh = new THREE.Mesh(geometry, material);
  window.viewer.mesh = mesh;
  scene.add(mesh);
}

addEventListener("resize", () => {
  resize();
  refineToCamera();
});
controls.addEventListener("start", () => {
  exactCamera = null;
});
controls.addEventListener("change", refineToCamera);
addEventListener("dragover", (e) => {
  e.preventDefault();
  document.body.classList.add("dragging");
});
addEventListener("dragleave", () => document.body.classList.remove("dragging"));
addEventListener("drop", async (e) => {
  e.preventDefault();
  document.body.classList.remove("dragging");
  const file = e.dataTransfer.files[0];
  if (!file) return;
  const bytes = await file.arrayBuffer();
  if (/\.(glb|gltf)$/i.test(file.name)) openScene({ bytes }, file.name);
  else open({ bytes }, file.name);
});

/** Triangles drawn by the scene's meshes. */
function sceneFaces(root) {
  let faces = 0;
  root.traverse((o) => {
    if (o.isMesh) faces += (o.geometry.index ? o.geometry.index.count : o.geometry.getAttribute("position").count) / 3;
  });
  return faces;
}

function showScene() {
  const g = state.gltf;
  const packed = g.packed ? ` · ${g.refined} of ${g.packed} progressive primitives refined` : "";
  figures.textContent = `${state.faces.toLocaleString()} faces · ${g.meshes} meshes${packed}` +
    (g.firstFrameMs === undefined ? "" : ` · first frame ${g.firstFrameMs.toFixed(0)} ms`) +
    (g.doneMs === undefined ? "" : ` · full ${g.doneMs.toFixed(0)} ms`);
  fill.style.width = g.packed ? `${(100 * g.refined) / g.packed}%` : "100%";
}

/** Opens a glTF scene (see the top); its state in state.gltf. */
async function openScene(request, name) {
  source.textContent = name;
  const started = performance.now();
  const usePlugin = new URLSearchParams(location.search).get("plugin") !== "off";
  Object.assign(state, { status: "loading", error: null, faces: 0, levelsSeen: [], levelsWithUvs: [] });
  state.gltf = { plugin: usePlugin, meshes: 0, packed: 0, refined: 0, levels: {}, errors: [] };
  errorLine.textContent = "";
  const gltfLoader = new GLTFLoader();
  let plugin = null;
  if (usePlugin) {
    gltfLoader.register((parser) => {
      plugin = new MeshcodecGLTFPlugin(parser, {
        loader,
        onLevel: ({ meshIndex, primitive, level, levels, mesh }) => {
          state.gltf.levels[`${meshIndex}/${primitive}`] = level;
          state.levelsSeen.push(level);
          if (mesh.geometry.getAttribute("uv")) state.levelsWithUvs.push(level);
          if (level === levels) state.gltf.refined++;
          state.faces = sceneFaces(window.viewer.scene);
          showScene();
        },
        onError: (error, where) => {
          state.gltf.errors.push(`mesh ${where.meshIndex} primitive ${where.primitive}: ${error.message}`);
          errorLine.textContent = state.gltf.errors.join("; ");
        },
      });
      return plugin;
    });
  }
  try {
    const gltf = request.url
      ? await gltfLoader.loadAsync(request.url)
      : await gltfLoader.parseAsync(request.bytes, "");
    if (mesh) scene.remove(mesh);
    mesh = gltf.scene;
    window.viewer.mesh = mesh;
    window.viewer.gltf = gltf;
    scene.add(mesh);
    const json = gltf.parser.json;
    state.gltf.meshes = json.meshes?.length ?? 0;
    state.gltf.packed = (json.meshes ?? []).flatMap((m) => m.primitives).filter((p) => usePlugin && p.extensions?.MESHCODEC_progressive).length;
    state.faces = sceneFaces(mesh);
    const box = new THREE.Box3().setFromObject(mesh);
    frame({ boundingSphere: box.getBoundingSphere(new THREE.Sphere()) });
    state.gltf.firstFrameMs = performance.now() - started;
    showScene();
    if (plugin) await plugin.done;
    state.gltf.doneMs = performance.now() - started;
    state.faces = sceneFaces(mesh);
    state.status = state.gltf.errors.length ? "error" : "done";
    state.error = state.gltf.errors[0] ?? null;
    showScene();
  } catch (error) {
    state.status = "error";
    state.error = error.message;
    errorLine.textContent = error.message;
  }
}

resize();
renderer.setAnimationLoop(() => {
  controls.update();
  renderer.render(scene, camera);
  state.frames++;
});

const params = new URLSearchParams(location.search);
const fixedCamera = cameraFromAddress(params);
const src = params.get("src");
if (src && /\.(glb|gltf)(\?|$)/i.test(src)) openScene({ url: src }, src);
else if (src) open({ url: src }, src);
