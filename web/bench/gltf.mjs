// Time to the first frame and to the full model of glTF scenes in headless Chromium (Debian's,
// through playwright-core), each scene coded three ways and loaded by three.js's GLTFLoader:
// meshcodec's plugin (a `meshcodec pack --external` GLB, its streams fetched by Range requests),
// DRACOLoader (a `gltf-transform draco` GLB) and MeshoptDecoder (a `gltfpack -cc` GLB), over one
// link of a given rate (web/serve.mjs), a fresh page each load, the ways alternated round by
// round; the median of the rounds. One JSON line a scene, way and rate.
//
//   node web/bench/gltf.mjs PLAN.json
//
// PLAN.json: {"rates": [bytes a second, ...], "rounds": N, "scenes": [{"name", "ways":
// {"meshcodec": {"url", "warm"}, "draco": {...}, "meshopt": {...}}}]}, each url a path under
// the repository (the server serves it), "warm" a small scene coded the same way loaded first.
import { readFileSync } from "node:fs";
import { resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { launchChromium } from "../chromium.mjs";
import { serve } from "../serve.mjs";

const [planFile] = process.argv.slice(2);
if (!planFile) {
  console.error("usage: node web/bench/gltf.mjs PLAN.json");
  process.exit(2);
}
const plan = JSON.parse(readFileSync(planFile, "utf8"));
const root = resolve(fileURLToPath(new URL("../..", import.meta.url)));
const browser = await launchChromium();
const median = (values) => {
  const sorted = [...values].sort((a, b) => a - b);
  const mid = sorted.length >> 1;
  return sorted.length % 2 ? sorted[mid] : (sorted[mid - 1] + sorted[mid]) / 2;
};
try {
  for (const rate of plan.rates) {
    const { server, port } = await serve({ root, rate });
    try {
      for (const scene of plan.scenes) {
        const runs = Object.fromEntries(Object.keys(scene.ways).map((way) => [way, []]));
        for (let round = 0; round < plan.rounds; round++) {
          for (const [way, { url, warm }] of Object.entries(scene.ways)) {
            const page = await browser.newPage({ viewport: { width: 640, height: 480 } });
            const problems = [];
            page.on("pageerror", (e) => problems.push(e.message));
            await page.goto(`http://127.0.0.1:${port}/web/bench/gltf.html`);
            const run = await page.evaluate(
              async ([way, url, warm]) => (await import("/web/bench/gltf-page.js")).load(way, url, warm),
              [way, url, warm],
            );
            if (problems.length) throw new Error(`${scene.name} ${way}: ${problems.join("; ")}`);
            runs[way].push(run);
            await page.close();
          }
        }
        for (const [way, list] of Object.entries(runs)) {
          console.log(JSON.stringify({
            scene: scene.name,
            way,
            rate,
            rounds: list.length,
            first_ms: median(list.map((r) => r.first)),
            full_ms: median(list.map((r) => r.full)),
            first_faces: list[0].firstFaces,
            faces: list[0].faces,
          }));
        }
      }
    } finally {
      server.close();
    }
  }
} finally {
  await browser.close();
}
