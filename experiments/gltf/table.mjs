// paper-tables/gltf.md: glTF scenes packed by `meshcodec pack` beside the same scenes coded by
// glTF-Transform's Draco (`gltf-transform draco`) and gltfpack (`gltfpack -cc`) at the same
// quantization (positions 12 bits, uvs 12, normals 10, colours 8), every file checked by
// glTF-Validator; then in headless Chromium the time to the first frame and to the full model
// at 5 and 25 Mbit/s (web/bench/gltf.mjs). Run by experiments/gltf.sh, which builds and installs
// what this needs.
//
// Scenes: glTF versions of the shared meshes (`meshcodec convert`), and the public scenes of
// experiments/gltf/samples.tsv, taken from $GLTF_SAMPLES (a folder holding the files by name)
// or downloaded from their repository at the named commit, each checked against its sha256.
import { createHash } from "node:crypto";
import { execFileSync, spawnSync } from "node:child_process";
import { existsSync, mkdirSync, readFileSync, statSync, writeFileSync } from "node:fs";
import { basename, dirname, join, relative, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import validator from "gltf-validator";

const here = dirname(fileURLToPath(import.meta.url));
const root = resolve(here, "../..");
const work = join(root, "target/gltf-experiment");
const meshcodec = join(root, "target/release/meshcodec");
const bin = (tool) => join(here, "node_modules/.bin", tool);
const SHARED = ["spot", "bunny-10k-textured", "airplane-colored", "bunny"];
const RATES = { "5 Mbit/s": 625_000, "25 Mbit/s": 3_125_000 };
const ROUNDS = Number(process.env.GLTF_ROUNDS ?? 3);
mkdirSync(work, { recursive: true });
const run = (command, args) => execFileSync(command, args, { stdio: ["ignore", "pipe", "pipe"] }).toString();

/** The public scenes, each file found or fetched and checked; name → {path, source}. */
async function samples() {
  const rows = readFileSync(join(here, "samples.tsv"), "utf8")
    .split("\n")
    .filter((l) => l && !l.startsWith("#"))
    .map((l) => l.split("\t"));
  const dir = join(work, "samples");
  mkdirSync(dir, { recursive: true });
  const scenes = {};
  for (const [scene, file, repo, commit, path, sha256] of rows) {
    const target = join(dir, file);
    const local = process.env.GLTF_SAMPLES && join(process.env.GLTF_SAMPLES, file);
    let bytes = existsSync(target) ? readFileSync(target) : local && existsSync(local) ? readFileSync(local) : null;
    const url = `https://raw.githubusercontent.com/${repo}/${commit}/${path}`;
    if (!bytes) {
      process.stderr.write(`fetching ${url}\n`);
      try {
        const response = await fetch(url);
        if (!response.ok) throw new Error(`HTTP ${response.status}`);
        bytes = Buffer.from(await response.arrayBuffer());
      } catch (e) {
        throw new Error(`${file}: cannot fetch ${url} (${e.cause?.code ?? e.message}); put the file in $GLTF_SAMPLES or ${dir}`);
      }
    }
    const got = createHash("sha256").update(bytes).digest("hex");
    if (got !== sha256) throw new Error(`${file}: sha256 ${got}, the manifest says ${sha256}`);
    writeFileSync(target, bytes);
    if (!scenes[scene] || /\.(glb|gltf)$/.test(file)) {
      scenes[scene] = { path: /\.(glb|gltf)$/.test(file) ? target : scenes[scene]?.path, source: `${repo}@${commit.slice(0, 8)}:${dirname(path)}` };
    }
  }
  return scenes;
}

/** glTF-Validator's errors and warnings on a GLB (external files beside it). */
async function validate(path) {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(path)), {
    uri: path,
    externalResourceFunction: (uri) => Promise.resolve(new Uint8Array(readFileSync(join(dirname(path), decodeURIComponent(uri))))),
  });
  return report.issues.numErrors;
}

/** Triangles of a GLB's meshes as drawn once (indices / 3 over every primitive). */
function triangles(path) {
  const bytes = readFileSync(path);
  const json = JSON.parse(bytes.subarray(20, 20 + bytes.readUInt32LE(12)).toString("utf8"));
  let count = 0;
  for (const mesh of json.meshes ?? []) {
    for (const p of mesh.primitives) {
      if ((p.mode ?? 4) !== 4) continue;
      const e = p.extensions?.MESHCODEC_progressive;
      count += e ? e.levels.at(-1).faces : (json.accessors[p.indices ?? p.attributes.POSITION].count / 3);
    }
  }
  return count;
}

const size = (path) => statSync(path).size;
const scenes = {};
for (const name of SHARED) {
  const path = join(work, `${name}.glb`);
  run(meshcodec, ["convert", name, path]);
  scenes[name] = { path, source: `../shared/meshes (${name}), \`meshcodec convert\`` };
}
Object.assign(scenes, await samples());

const rows = [];
const plan = { rates: Object.values(RATES), rounds: ROUNDS, scenes: [] };
const warm = {};
{
  // The small scene each way loads before the clock starts.
  const torus = join(root, "fuzz/seeds/read_gltf/torus.glb");
  warm.meshcodec = join(work, "warm-meshcodec.glb");
  run(meshcodec, ["pack", "--external", torus, warm.meshcodec]);
  warm.draco = join(work, "warm-draco.glb");
  run(bin("gltf-transform"), ["draco", torus, warm.draco]);
  warm.meshopt = join(work, "warm-meshopt.glb");
  run(bin("gltfpack"), ["-i", torus, "-o", warm.meshopt, "-cc"]);
}
const url = (path) => "/" + relative(root, path);
for (const [name, { path, source }] of Object.entries(scenes)) {
  process.stderr.write(`${name}\n`);
  const ours = join(work, `${name}.meshcodec.glb`);
  const packing = spawnSync(meshcodec, ["pack", path, ours], { encoding: "utf8" });
  if (packing.status !== 0) throw new Error(`meshcodec pack ${path}: ${packing.stderr}`);
  const external = join(work, `${name}.meshcodec-external.glb`);
  run(meshcodec, ["pack", "--external", path, external]);
  const draco = join(work, `${name}.draco.glb`);
  run(bin("gltf-transform"), ["draco", path, draco, "--quantize-position", "12", "--quantize-texcoord", "12",
    "--quantize-normal", "10", "--quantize-color", "8"]);
  const meshopt = join(work, `${name}.gltfpack.glb`);
  run(bin("gltfpack"), ["-i", path, "-o", meshopt, "-cc", "-kv", "-vp", "12", "-vt", "12", "-vn", "10"]);
  const input = path.endsWith(".gltf")
    ? size(path) + readFileSync(join(here, "samples.tsv"), "utf8").split("\n").filter((l) => l.startsWith(name + "\t") && !l.includes(".gltf\t")).reduce((s, l) => s + size(join(dirname(path), l.split("\t")[1])), 0)
    : size(path);
  const kept = (packing.stderr.match(/kept as it is/g) ?? []).length;
  rows.push({
    name, source, input, faces: triangles(ours), kept,
    ours: size(ours), draco: size(draco), meshopt: size(meshopt),
    errors: { input: await validate(path), ours: await validate(ours), external: await validate(external), draco: await validate(draco), meshopt: await validate(meshopt) },
  });
  plan.scenes.push({
    name,
    ways: {
      meshcodec: { url: url(external), warm: url(warm.meshcodec) },
      draco: { url: url(draco), warm: url(warm.draco) },
      meshopt: { url: url(meshopt), warm: url(warm.meshopt) },
    },
  });
}
writeFileSync(join(work, "plan.json"), JSON.stringify(plan, null, 1));
process.stderr.write(`streaming in Chromium (${ROUNDS} rounds)\n`);
const timings = run("node", [join(root, "web/bench/gltf.mjs"), join(work, "plan.json")])
  .trim().split("\n").map((l) => JSON.parse(l));
const timing = (scene, way, rate) => timings.find((t) => t.scene === scene && t.way === way && t.rate === rate);

const kb = (n) => (n / 1000).toFixed(1);
const lines = [
  "# glTF scenes: `meshcodec pack` beside Draco and meshoptimizer",
  "",
  "Made by `bash experiments/gltf.sh` (experiments/gltf/table.mjs); every number below is measured in that run.",
  "",
  "Each scene packed three ways at the same quantization (positions 12 bits, texture coordinates 12, normals 10, colours 8):",
  "",
  "- **meshcodec**: `meshcodec pack IN OUT.glb` (defaults: `emc`, each primitive's appearance with every level, a fallback of about 2% of the faces in its accessors);",
  "- **Draco**: `gltf-transform draco IN OUT.glb --quantize-position 12 --quantize-texcoord 12 --quantize-normal 10 --quantize-color 8` (@gltf-transform/cli 4.5.1, edgebreaker);",
  "- **gltfpack**: `gltfpack -i IN -o OUT.glb -cc -kv -vp 12 -vt 12 -vn 10` (gltfpack 1.3.0, EXT_meshopt_compression; `-kv` keeps the attributes no material reads, such as the uvs and normals of spot's and bunny-10k-textured's untextured glTF, which gltfpack otherwise drops).",
  "",
  "Sizes are whole GLB files (scene, images, everything), in kB (1000 bytes). Errors: glTF-Validator 2.0.0-dev.3.10 on each file (meshcodec's with the streams inside and with `--external`).",
  "",
  "| scene | source | triangles | kept primitives | input kB | meshcodec kB | Draco kB | gltfpack kB | meshcodec / Draco | validator errors (input; ours, ours external, Draco, gltfpack) |",
  "|---|---|---:|---:|---:|---:|---:|---:|---:|---|",
];
for (const r of rows) {
  lines.push(`| ${r.name} | ${r.source} | ${r.faces.toLocaleString("en")} | ${r.kept} | ${kb(r.input)} | ${kb(r.ours)} | ${kb(r.draco)} | ${kb(r.meshopt)} | ${(r.ours / r.draco).toFixed(2)} | ${r.errors.input}; ${r.errors.ours}, ${r.errors.external}, ${r.errors.draco}, ${r.errors.meshopt} |`);
}
lines.push(
  "",
  "Kept primitives: what `pack` passes through as it found them (skinned or morphed ones, points, lines, attributes the codecs do not carry such as TANGENT; `pack` lists each with its reason); Draco and gltfpack compress them. A file's validator errors that the input already had (CesiumMan's weights) are the input's.",
  "",
  "## Streaming in the browser",
  "",
  `Headless Chromium (swiftshader), three.js's GLTFLoader; the scene served over one link of the given rate (\`web/serve.mjs\`: scenes, buffers, images and streams share it; code and decoders come at once, as for a returning visitor); each decoder loaded and running before the clock starts; a fresh page each load, the three ways alternated round by round, the median of ${ROUNDS} rounds (\`node web/bench/gltf.mjs\`). meshcodec: the \`--external\` GLB with the plugin (web/gltf-plugin.js): the scene with its fallbacks, then each stream fetched by a Range request and refined level by level. First frame: the scene drawn once; full: drawn with every primitive's last level (for Draco and gltfpack the two are the same).`,
  "",
  "| scene | rate | meshcodec first frame ms (triangles) | meshcodec full ms | Draco full ms | gltfpack full ms | ours first / Draco full | ours full / Draco full |",
  "|---|---|---:|---:|---:|---:|---:|---:|",
);
for (const r of rows) {
  for (const [label, rate] of Object.entries(RATES)) {
    const ours = timing(r.name, "meshcodec", rate);
    const draco = timing(r.name, "draco", rate);
    const meshopt = timing(r.name, "meshopt", rate);
    lines.push(`| ${r.name} | ${label} | ${ours.first_ms.toFixed(0)} (${ours.first_faces.toLocaleString("en")}) | ${ours.full_ms.toFixed(0)} | ${draco.full_ms.toFixed(0)} | ${meshopt.full_ms.toFixed(0)} | ${(ours.first_ms / draco.full_ms).toFixed(2)} | ${(ours.full_ms / draco.full_ms).toFixed(2)} |`);
  }
}
writeFileSync(join(root, "paper-tables/gltf.md"), lines.join("\n") + "\n");
writeFileSync(join(root, "results/gltf.json"), JSON.stringify({ sizes: rows, timings }, null, 1) + "\n");
process.stderr.write("wrote paper-tables/gltf.md and results/gltf.json\n");
