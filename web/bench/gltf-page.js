// What web/bench/gltf.mjs runs in its page: one glTF scene loaded with three.js's GLTFLoader and
// one way of decoding it (meshcodec's plugin, DRACOLoader, or MeshoptDecoder), its decoder ready
// before the clock starts; the times to the first frame drawn and to the full model drawn.
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { DRACOLoader } from "three/addons/loaders/DRACOLoader.js";
import { MeshoptDecoder } from "three/addons/libs/meshopt_decoder.module.js";
import { MeshcodecGLTFPlugin } from "../gltf-plugin.js";
import { MeshcodecLoader } from "../loader.js";

const renderer = new THREE.WebGLRenderer({ canvas: document.getElementById("view") });
const camera = new THREE.PerspectiveCamera(50, 4 / 3, 0.01, 1000);

/** Draws `scene` once, waiting for the GPU, framed to its bounds. */
function draw(scene) {
  const sphere = new THREE.Box3().setFromObject(scene).getBoundingSphere(new THREE.Sphere());
  camera.position.copy(sphere.center).add(new THREE.Vector3(0, 0.3, 1).multiplyScalar(sphere.radius * 2.5));
  camera.lookAt(sphere.center);
  const lit = new THREE.Scene();
  lit.add(new THREE.HemisphereLight(0xffffff, 0x444444, 3), scene);
  renderer.render(lit, camera);
  renderer.getContext().finish();
}

/** Triangles drawn by `scene`. */
function faces(scene) {
  let count = 0;
  scene.traverse((o) => {
    if (o.isMesh) count += (o.geometry.index ? o.geometry.index.count : o.geometry.getAttribute("position").count) / 3;
  });
  return count;
}

/** Loads `url` the way `kind` says ("meshcodec", "draco", "meshopt"), after loading `warmUrl`
 * (a small scene coded the same way) the same way so that the decoder is running before the
 * clock starts. */
export async function load(kind, url, warmUrl) {
  const loader = new GLTFLoader();
  let plugin = null;
  if (kind === "draco") {
    loader.setDRACOLoader(new DRACOLoader().setDecoderPath("/web/node_modules/three/examples/jsm/libs/draco/gltf/"));
  } else if (kind === "meshopt") {
    await MeshoptDecoder.ready;
    loader.setMeshoptDecoder(MeshoptDecoder);
  } else {
    const decoder = new MeshcodecLoader();
    loader.register((parser) => (plugin = new MeshcodecGLTFPlugin(parser, { loader: decoder })));
  }
  await loader.loadAsync(warmUrl);
  if (plugin) await plugin.done;
  plugin = null;
  const started = performance.now();
  const gltf = await loader.loadAsync(url);
  draw(gltf.scene);
  const first = performance.now() - started;
  const firstFaces = faces(gltf.scene);
  if (plugin) await plugin.done;
  draw(gltf.scene);
  const full = performance.now() - started;
  return { first, full, firstFaces, faces: faces(gltf.scene) };
}
