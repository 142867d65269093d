// The WebAssembly decoder's time in headless Chromium (Debian's, through playwright-core), on
// the main thread of a page served by web/serve.mjs, best of N, as one JSON line; beside it, in
// the same page, rounds alternated, Draco's wasm decoder as three.js ships it for DRACOLoader
// (examples/jsm/libs/draco) on the same mesh, encoded by npm draco3d at 12 bits, compression
// level 10 (web/bench/draco-lib.mjs).
//   bash web/build.sh && bash tests/chromium.sh && node web/bench/browser.mjs STREAM.mc [N]
import { mkdirSync, readFileSync, writeFileSync } from "node:fs";
import { basename, join, relative, resolve, sep } from "node:path";
import { fileURLToPath } from "node:url";
import draco3d from "draco3d";
import { chromium } from "playwright-core";
import init, { decode } from "../pkg/meshcodec.js";
import { serve } from "../serve.mjs";
import { dracoEncode } from "./draco-lib.mjs";

const [stream, repeats = "10"] = process.argv.slice(2);
if (!stream) {
  console.error("usage: node web/bench/browser.mjs STREAM.mc [N]");
  process.exit(2);
}
const root = resolve(fileURLToPath(new URL("../..", import.meta.url)));
const path = relative(root, resolve(stream));
if (path.startsWith("..")) {
  console.error(`${stream}: not under ${root} (the server serves the repository)`);
  process.exit(2);
}
// Draco's file of the same mesh, served beside the page.
await init({ module_or_path: readFileSync(join(root, "web/pkg/meshcodec_bg.wasm")) });
const mesh = decode(new Uint8Array(readFileSync(stream)));
const encoded = dracoEncode(await draco3d.createEncoderModule({}), mesh);
mkdirSync(join(root, "target/web-bench"), { recursive: true });
const drc = join(root, "target/web-bench", `${basename(stream, ".mc")}.drc`);
writeFileSync(drc, encoded);
const { server, port } = await serve({ root });
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
try {
  const page = await browser.newPage();
  await page.goto(`http://127.0.0.1:${port}/web/viewer/index.html`);
  await page.addScriptTag({ url: "/web/node_modules/three/examples/jsm/libs/draco/draco_wasm_wrapper.js" });
  const report = await page.evaluate(
    async ({ url, drcUrl, repeats }) => {
      const { default: init, decode } = await import("/web/pkg/meshcodec.js");
      const { dracoDecode } = await import("/web/bench/draco-lib.mjs");
      await init({ module_or_path: "/web/pkg/meshcodec_bg.wasm" });
      const wasmBinary = await (await fetch("/web/node_modules/three/examples/jsm/libs/draco/draco_decoder.wasm")).arrayBuffer();
      const draco = await new Promise((done) => {
        const module = { wasmBinary, onModuleLoaded: () => done(module) };
        globalThis.DracoDecoderModule(module);
      });
      const bytes = new Uint8Array(await (await fetch(url)).arrayBuffer());
      const encoded = new Int8Array(await (await fetch(drcUrl)).arrayBuffer());
      const time = (work) => {
        let best = Infinity;
        for (let i = 0; i < repeats; i++) {
          const started = performance.now();
          work();
          best = Math.min(best, (performance.now() - started) / 1000);
        }
        return best;
      };
      let mesh;
      let ours = Infinity;
      let theirs = Infinity;
      for (let round = 0; round < 5; round++) {
        ours = Math.min(ours, time(() => (mesh = decode(bytes))));
        theirs = Math.min(theirs, time(() => dracoDecode(draco, encoded)));
      }
      const check = dracoDecode(draco, encoded);
      if (check.indices.length !== mesh.indices.length) throw new Error("Draco's mesh has another face count");
      return {
        decode_seconds: ours,
        vertices: mesh.vertices,
        triangles: mesh.triangles,
        bytes: bytes.length,
        draco_bytes: encoded.length,
        draco_decode_seconds: theirs,
        meshcodec_over_draco: ours / theirs,
      };
    },
    { url: `/${path.split(sep).join("/")}`, drcUrl: `/${relative(root, drc).split(sep).join("/")}`, repeats: Number(repeats) },
  );
  console.log(JSON.stringify({ stream, browser: browser.version(), ...report }));
} finally {
  await browser.close();
  server.close();
}
