// A static server for the viewer and its streams, on loopback: serves the repository's files
// (web/ with its node_modules, and any stream under the repository), honours HTTP Range
// requests (a CAME client asks for units by byte range) and counts the bytes it sends for each
// path (what a test reads to tell how much of a stream a view needed).
//
//   node web/serve.mjs [STREAM.mc] [--port 8080] [--rate BYTES_A_SECOND]   # prints the viewer's address
import { createReadStream, readFileSync, statSync } from "node:fs";
import { createServer } from "node:http";
import { extname, join, normalize, relative, resolve, sep } from "node:path";
import { fileURLToPath } from "node:url";

const TYPES = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".mjs": "text/javascript; charset=utf-8",
  ".json": "application/json",
  ".wasm": "application/wasm",
  ".css": "text/css",
  ".png": "image/png",
};

/** Files sent over the slow link when a rate is given: streams and the scenes, buffers, images
 * and Draco files they are compared with. Code and the decoders' wasm come at once (a returning
 * visitor has them cached). */
const THROTTLED = new Set([".mc", ".glb", ".gltf", ".bin", ".drc", ".png", ".jpg", ".jpeg", ".ktx2", ".webp"]);

/** One link of `rate` bytes a second that every throttled response shares, as one network
 * connection does: 20 times a second a twentieth of the rate, split evenly among the responses
 * still sending (what one leaves unused goes to the others). */
function slowLink(rate) {
  const sending = new Set();
  let ticking = false;
  const tick = () => {
    let budget = Math.max(1, Math.floor(rate / 20));
    while (budget > 0 && sending.size > 0) {
      const share = Math.max(1, Math.floor(budget / sending.size));
      for (const s of [...sending]) {
        const chunk = s.bytes.subarray(s.at, s.at + Math.min(share, budget));
        s.at += chunk.length;
        budget -= chunk.length;
        s.count(chunk);
        s.response.write(chunk);
        if (s.at >= s.bytes.length) {
          sending.delete(s);
          s.response.end();
        }
        if (budget <= 0) break;
      }
    }
    ticking = sending.size > 0;
    if (ticking) setTimeout(tick, 50);
  };
  return {
    send(bytes, response, count) {
      if (bytes.length === 0) return response.end();
      const s = { bytes, at: 0, response, count };
      sending.add(s);
      response.on("close", () => sending.delete(s));
      if (!ticking) {
        ticking = true;
        tick();
      }
    },
  };
}

/** Serves `root` on 127.0.0.1:`port` (0: any free port), streams, scenes and their files at
 * `rate` bytes a second when given (one link they share, so that levels arrive one after
 * another, as over a slow network); resolves to
 * {server, port, sent, requests}: `sent` the bytes sent a path, `requests` each request as
 * {path, start, end (inclusive), status} in the order they came. */
export function serve({ root, port = 0, rate = 0 }) {
  root = resolve(root);
  const sent = new Map();
  const requests = [];
  const link = slowLink(rate);
  const server = createServer((request, response) => {
    const path = decodeURIComponent(new URL(request.url, "http://localhost").pathname);
    const file = normalize(join(root, path));
    if (file !== root && !file.startsWith(root + sep)) {
      response.writeHead(403).end();
      return;
    }
    let stat;
    try {
      stat = statSync(file);
    } catch {
      response.writeHead(404).end();
      return;
    }
    if (!stat.isFile()) {
      response.writeHead(404).end();
      return;
    }
    const headers = {
      "Content-Type": TYPES[extname(file)] ?? "application/octet-stream",
      "Accept-Ranges": "bytes",
      "Cache-Control": "no-store",
    };
    let start = 0;
    let end = stat.size - 1;
    const range = /^bytes=(\d*)-(\d*)$/.exec(request.headers.range ?? "");
    if (range && (range[1] || range[2])) {
      if (range[1]) {
        start = Number(range[1]);
        if (range[2]) end = Math.min(end, Number(range[2]));
      } else {
        start = Math.max(0, stat.size - Number(range[2]));
      }
      if (start > end || start >= stat.size) {
        response.writeHead(416, { "Content-Range": `bytes */${stat.size}` }).end();
        return;
      }
      headers["Content-Range"] = `bytes ${start}-${end}/${stat.size}`;
    }
    headers["Content-Length"] = String(end - start + 1);
    requests.push({ path, start, end, status: range && headers["Content-Range"] ? 206 : 200 });
    response.writeHead(range && headers["Content-Range"] ? 206 : 200, headers);
    if (request.method === "HEAD") {
      response.end();
      return;
    }
    const count = (chunk) => sent.set(path, (sent.get(path) ?? 0) + chunk.length);
    if (rate > 0 && THROTTLED.has(extname(file))) {
      link.send(readFileSync(file).subarray(start, end + 1), response, count);
      return;
    }
    const stream = createReadStream(file, { start, end });
    stream.on("data", count);
    stream.pipe(response);
  });
  return new Promise((done) => {
    server.listen(port, "127.0.0.1", () => done({ server, port: server.address().port, sent, requests }));
  });
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const root = resolve(fileURLToPath(new URL("..", import.meta.url)));
  const args = process.argv.slice(2);
  const at = args.indexOf("--port");
  const port = at >= 0 ? Number(args.splice(at, 2)[1]) : 8080;
  const rated = args.indexOf("--rate");
  const rate = rated >= 0 ? Number(args.splice(rated, 2)[1]) : 0;
  const { port: bound } = await serve({ root, port, rate });
  const viewer = `http://127.0.0.1:${bound}/web/viewer/index.html`;
  const stream = args[0];
  if (stream) {
    const path = relative(root, resolve(stream));
    if (path.startsWith("..")) {
      console.error(`${stream}: not under ${root} (the server serves the repository)`);
      process.exit(2);
    }
    console.log(`open ${viewer}?src=/${path.split(sep).join("/")}`);
  } else {
    console.log(`open ${viewer} and drop a stream on it`);
  }
}
