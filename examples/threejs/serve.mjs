// Serves this folder (the page, the plugin, node_modules/three and the fitted scene) at
// http://127.0.0.1:8000/ , for `npm start`. A browser loads ES modules and glTF buffers only
// over HTTP, not from file:// URLs. `PORT=8080 npm start` picks another port (0: any free one).

import { createReadStream, statSync } from "node:fs";
import { createServer } from "node:http";
import path from "node:path";
import { fileURLToPath } from "node:url";

const ROOT = path.dirname(fileURLToPath(import.meta.url));
// A browser insists on the type of the page and of its ES modules only; GLTFLoader reads the
// scene's files (.gltf, .bin, images) whatever type they come with.
const TYPES = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".json": "application/json",
};

const server = createServer((req, res) => {
  let pathname;
  try {
    pathname = decodeURIComponent(new URL(req.url, "http://localhost").pathname);
  } catch {
    return res.writeHead(400).end("bad request");
  }
  let file = path.join(ROOT, pathname);
  if (pathname.endsWith("/")) file = path.join(file, "index.html");
  // path.join resolves "..": anything that ends up outside this folder is not served.
  const stat = file.startsWith(ROOT + path.sep) ? statSync(file, { throwIfNoEntry: false }) : undefined;
  if (!stat?.isFile()) return res.writeHead(404).end(`not found: ${pathname}`);
  res.writeHead(200, { "content-type": TYPES[path.extname(file)] ?? "application/octet-stream" });
  createReadStream(file).pipe(res);
});

const port = Number(process.env.PORT ?? 8000);
if (!Number.isInteger(port) || port < 0 || port > 65535) {
  console.error(`PORT must be a whole number from 0 to 65535, not ${JSON.stringify(process.env.PORT)}`);
  process.exit(1);
}
server.on("error", (e) => {
  console.error(`cannot serve on port ${port}: ${e.message} (choose another with PORT=8080 npm start)`);
  process.exit(1);
});
server.listen(port, "127.0.0.1", () => {
  console.log(`serving ${ROOT}\nopen http://127.0.0.1:${server.address().port}/`);
});
