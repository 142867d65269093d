// The WebAssembly decoder's time in headless Chromium (Debian's, through playwright-core), on
// the main thread of a page served by web/serve.mjs, best of N, as one JSON line.
//   bash web/build.sh && bash tests/chromium.sh && node web/bench/browser.mjs STREAM.mc [N]
import { relative, resolve, sep } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";
import { serve } from "../serve.mjs";

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
const { server, port } = await serve({ root });
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
try {
  const page = await browser.newPage();
  await page.goto(`http://127.0.0.1:${port}/web/viewer/index.html`);
  const report = await page.evaluate(
    async ({ url, repeats }) => {
      const { default: init, decode } = await import("/web/pkg/meshcodec.js");
      await init({ module_or_path: "/web/pkg/meshcodec_bg.wasm" });
      const bytes = new Uint8Array(await (await fetch(url)).arrayBuffer());
      let best = Infinity;
      let mesh;
      for (let i = 0; i < repeats; i++) {
        const started = performance.now();
        mesh = decode(bytes);
        best = Math.min(best, (performance.now() - started) / 1000);
      }
      return { decode_seconds: best, vertices: mesh.vertices, triangles: mesh.triangles, bytes: bytes.length };
    },
    { url: `/${path.split(sep).join("/")}`, repeats: Number(repeats) },
  );
  console.log(JSON.stringify({ stream, browser: browser.version(), ...report }));
} finally {
  await browser.close();
  server.close();
}
