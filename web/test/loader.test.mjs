// MeshcodecLoader in headless Chromium, as a three.js user drives it: workers up to the limit set
// (streams loaded together decoded side by side), the .wasm taken from the decoder path set, an
// AbortSignal that stops a load in flight (its reason at onError, no level after it), arguments
// checked, and faults as MeshcodecErrors with their codes. Run by tests/run.sh:
//   node --test web/test/
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdirSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";

import { launchChromium } from "../chromium.mjs";
import { serve } from "../serve.mjs";
import { native, root } from "./native.mjs";

const scratch = join(root, "target/web-test/loader");
let browser;
let server;
let page;

before(async () => {
  mkdirSync(scratch, { recursive: true });
  execFileSync(native, ["encode", "--codec", "emc", "bunny", join(scratch, "bunny.mc")], { stdio: "pipe" });
  const bytes = readFileSync(join(scratch, "bunny.mc"));
  const damaged = Buffer.from(bytes);
  for (let at = 2000; at < 6000; at += 13) damaged[at] ^= 0x5a;
  writeFileSync(join(scratch, "damaged.mc"), damaged);
  // 200 KB/s: bunny's 68 KB take about a third of a second, long enough to abort in flight.
  server = await serve({ root, rate: 200_000 });
  browser = await launchChromium();
  page = await browser.newPage();
  await page.goto(`http://127.0.0.1:${server.port}/web/test/loader.html`);
  await page.waitForFunction(() => window.ready === true);
});

after(async () => {
  await browser?.close();
  server?.server.close();
});

/** Loads `urls` at once with a fresh loader configured by `setup`; each load's outcome. */
function loadAll(urls, setup) {
  return page.evaluate(
    async ([urls, setup]) => {
      const loader = new window.MeshcodecLoader();
      if (setup.limit) loader.setWorkerLimit(setup.limit);
      if (setup.path) loader.setDecoderPath(setup.path);
      const outcomes = await Promise.all(
        urls.map(
          (url) =>
            new Promise((resolve) => {
              const levels = [];
              loader.load(
                url,
                (g) => resolve({ ok: true, levels, faces: g.index.count / 3 }),
                undefined,
                (e) => resolve({ ok: false, levels, name: e.name, code: e.code, message: e.message, isMeshcodec: e instanceof window.MeshcodecError }),
                (g, f) => levels.push(f.level),
              );
            }),
        ),
      );
      const workers = loader.workers.length;
      loader.dispose();
      return { outcomes, workers };
    },
    [urls, setup],
  );
}

const bunny = "/target/web-test/loader/bunny.mc";

test("streams loaded together share the workers up to the limit", async () => {
  const { outcomes, workers } = await loadAll([bunny, bunny, bunny], { limit: 2 });
  assert.equal(workers, 2);
  for (const o of outcomes) {
    assert.ok(o.ok, o.message);
    assert.deepEqual(o.levels, [...o.levels].sort((a, b) => a - b));
    assert.ok(o.faces > 60000);
  }
  assert.equal((await loadAll([bunny, bunny], { limit: 1 })).workers, 1);
});

test("the .wasm comes from the decoder path: the package's folder works, a wrong one is a network error", async () => {
  const [good] = (await loadAll([bunny], { path: "/web/pkg/" })).outcomes;
  assert.ok(good.ok, good.message);
  const [bad] = (await loadAll([bunny], { path: "/nowhere/" })).outcomes;
  assert.ok(!bad.ok && bad.isMeshcodec && bad.code === "network", JSON.stringify(bad));
});

test("an AbortSignal stops a load in flight: its reason at onError, no level after it", async () => {
  const result = await page.evaluate(async (url) => {
    const loader = new window.MeshcodecLoader();
    const controller = new AbortController();
    const levels = [];
    let levelsAtAbort = -1;
    const error = await new Promise((resolve) => {
      loader.load(url, () => resolve(null), undefined, resolve, {
        signal: controller.signal,
        onLevel: (g, f) => {
          levels.push(f.level);
          if (levels.length === 2) {
            levelsAtAbort = levels.length;
            controller.abort();
          }
        },
      });
    });
    // Whatever the worker had in flight is dropped.
    await new Promise((r) => setTimeout(r, 800));
    const pending = loader.pending.size;
    // An already aborted signal: refused before any fetch.
    const early = await loader.loadAsync(url, undefined, { signal: AbortSignal.abort() }).catch((e) => e.name);
    loader.dispose();
    return { name: error?.name, levels, levelsAtAbort, pending, early };
  }, bunny);
  assert.equal(result.name, "AbortError");
  assert.equal(result.levels.length, result.levelsAtAbort);
  assert.equal(result.pending, 0);
  assert.equal(result.early, "AbortError");
});

test("bad arguments are TypeErrors and RangeErrors naming them", async () => {
  const said = await page.evaluate(() => {
    const loader = new window.MeshcodecLoader();
    const attempt = (f) => {
      try {
        f();
        return "accepted";
      } catch (e) {
        return `${e.name}: ${e.message}`;
      }
    };
    return [
      attempt(() => loader.setWorkerLimit(0)),
      attempt(() => loader.setWorkerLimit(1.5)),
      attempt(() => loader.setWorkerLimit("2")),
      attempt(() => loader.setDecoderPath(3)),
      attempt(() => loader.load(42)),
      attempt(() => loader.load("x.mc", undefined, undefined, undefined, { signal: "stop" })),
      attempt(() => loader.load("x.mc", undefined, undefined, undefined, { onlevel: () => {} })),
      attempt(() => loader.parse("bytes")),
    ];
  });
  assert.deepEqual(
    said.map((s) => s.split(":")[0] + ":" + s.split(":")[1]),
    [
      "RangeError: limit",
      "RangeError: limit",
      "TypeError: limit",
      "TypeError: path",
      "TypeError: url",
      "TypeError: signal",
      "TypeError: options",
      "TypeError: buffer",
    ],
  );
});

test("a damaged stream ends in a MeshcodecError coded corrupt, after the levels before the damage", async () => {
  const [o] = (await loadAll(["/target/web-test/loader/damaged.mc"], {})).outcomes;
  assert.ok(!o.ok);
  assert.equal(o.name, "MeshcodecError");
  assert.equal(o.code, "corrupt", o.message);
  assert.ok(o.isMeshcodec);
  assert.ok(o.levels.length > 0, "levels before the damage are shown");
});
