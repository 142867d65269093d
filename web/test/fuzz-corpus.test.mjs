// The fuzz corpus through the WebAssembly package: every input of the stream decoders' targets
// (fuzz/seeds, fuzz/regressions and fuzz/corpus.tar.xz), made into the stream its target
// decodes, either decodes or ends in an Error with the library's one-line message: never a trap,
// never a hang. Run by tests/run.sh after `bash web/build.sh`:   node --test web/test/
import { test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { existsSync, mkdtempSync, readdirSync, readFileSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { fileURLToPath } from "node:url";

import init, { decode, ProgressiveDecoder } from "../pkg/meshcodec.js";

const root = fileURLToPath(new URL("../../", import.meta.url));
await init({ module_or_path: readFileSync(join(root, "web/pkg/meshcodec_bg.wasm")) });

const MAGIC = [0x4d, 0x73, 0x68, 0x43]; // "MshC"
// What comes before a target's input (fuzz/src/lib.rs): magic, format version, and for the
// per-codec targets the codec id and its syntax.
const VERSION = 6;
const PREFIX = {
  decode_raw: [...MAGIC, VERSION, 0, 1],
  decode_emc_paper: [...MAGIC, VERSION, 1, 1],
  decode_pm: [...MAGIC, VERSION, 2, 1],
  decode_pm_reordered: [...MAGIC, VERSION, 3, 1],
  decode_emc: [...MAGIC, VERSION, 4, 1],
  decode_came_paper: [...MAGIC, VERSION, 5, 1],
  decode_came: [...MAGIC, VERSION, 6, 6],
  decode_appearance: [...MAGIC, VERSION],
  decode_pm_wedges: [...MAGIC, VERSION],
};

function inputs(folder) {
  const found = [];
  for (const target of Object.keys(PREFIX)) {
    const dir = join(folder, target);
    if (!existsSync(dir)) continue;
    for (const file of readdirSync(dir)) found.push([target, join(dir, file)]);
  }
  return found;
}

function decodesOrRefuses(bytes, what) {
  const attempts = [
    () => decode(bytes),
    () => decode(bytes, 1),
    () => {
      const decoder = new ProgressiveDecoder();
      try {
        decoder.push(bytes.subarray(0, bytes.length >> 1));
        decoder.push(bytes.subarray(bytes.length >> 1));
      } finally {
        decoder.free();
      }
    },
  ];
  let refused = 0;
  for (const attempt of attempts) {
    try {
      attempt();
    } catch (e) {
      assert.ok(e instanceof Error, `${what}: threw ${e}`);
      assert.ok(!(e instanceof WebAssembly.RuntimeError), `${what}: the module trapped: ${e.stack}`);
      assert.ok(e.message.length > 0 && !e.message.includes("\n"), `${what}: ${e.message}`);
      refused++;
    }
  }
  return refused;
}

test("every input of the fuzz corpus decodes or ends in an Error", () => {
  const scratch = mkdtempSync(join(tmpdir(), "meshcodec-corpus-"));
  try {
    execFileSync("tar", ["xJf", join(root, "fuzz/corpus.tar.xz"), "-C", scratch]);
    const all = [
      ...inputs(join(root, "fuzz/seeds")),
      ...inputs(join(root, "fuzz/regressions")),
      ...inputs(join(scratch, "corpus")),
    ];
    assert.ok(all.length > 500, `only ${all.length} inputs`);
    let refused = 0;
    for (const [target, file] of all) {
      const body = readFileSync(file);
      const bytes = new Uint8Array(PREFIX[target].length + body.length);
      bytes.set(PREFIX[target]);
      bytes.set(body, PREFIX[target].length);
      refused += decodesOrRefuses(bytes, `${target}/${file.split("/").pop()}`);
    }
    assert.ok(refused > all.length, `only ${refused} refusals over ${all.length} inputs`);
  } finally {
    rmSync(scratch, { recursive: true, force: true });
  }
});
