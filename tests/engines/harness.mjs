// Shared pieces of the engine checks: a localhost static server, the headless Chromium launch,
// and the report's expected lights. The network is closed on CI, so every byte the page needs
// (engine modules, the glTF and its buffers, Babylon's area-light tables) comes from here.

import { createServer } from "node:http";
import { createReadStream, existsSync, mkdtempSync, readFileSync, rmSync, statSync } from "node:fs";
import { tmpdir } from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";

export const HERE = path.dirname(fileURLToPath(import.meta.url));
const NODE_MODULES = path.join(HERE, "node_modules");
const INSTALL_HINT = "run `npm ci --prefix tests/engines` from the repository root";
const CHROMIUM_HINT = "install it with `apt-get install -y chromium` (Debian's package, /usr/bin/chromium)";

/** Stops with a message (exit 2 = the harness could not run, 1 = a check failed). */
export function fail(message, code = 1) {
  console.error(`engine check FAILED: ${message}`);
  process.exit(code);
}

/** Parses `--name value` pairs; every name in `required` must be present. */
export function parseArgs(argv, required, optional = []) {
  const known = new Set([...required, ...optional]);
  const out = {};
  for (let i = 0; i < argv.length; i += 2) {
    const key = argv[i]?.replace(/^--/, "");
    if (!argv[i]?.startsWith("--") || !known.has(key) || argv[i + 1] === undefined) {
      fail(`bad argument ${JSON.stringify(argv[i])}; expected ${[...known].map((k) => `--${k} VALUE`).join(" ")}`, 2);
    }
    out[key] = argv[i + 1];
  }
  for (const key of required) {
    if (out[key] === undefined) fail(`missing --${key}`, 2);
  }
  return out;
}

/** Imports an npm package of this folder, or stops naming the install command. */
export async function requirePackage(specifier) {
  try {
    return await import(specifier);
  } catch (e) {
    fail(`cannot load the npm package ${specifier} (${e.code ?? e.message}): ${INSTALL_HINT}`, 2);
  }
}

/** Checks that a file of an npm package is installed (the page loads it over HTTP). */
export function requireModuleFile(relative) {
  if (!existsSync(path.join(NODE_MODULES, relative))) {
    fail(`node_modules/${relative} is missing: ${INSTALL_HINT}`, 2);
  }
}

const MIME = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".mjs": "text/javascript; charset=utf-8",
  ".json": "application/json",
  ".gltf": "model/gltf+json",
  ".glb": "model/gltf-binary",
  ".bin": "application/octet-stream",
  ".png": "image/png",
  ".jpg": "image/jpeg",
  ".ktx2": "image/ktx2",
  ".wasm": "application/wasm",
};

/**
 * Serves `mounts` ({ "/prefix/": directory }) and `blobs` ({ "/path": Buffer }) on 127.0.0.1
 * at a free port. Paths that leave their mount are refused. Every request is logged, so a
 * failing run shows what the page asked for. Any origin may read the files (CORS), so that a
 * page served elsewhere (the three.js example's own server) can load a scene from here.
 */
export async function startServer(mounts, blobs = {}) {
  const requests = [];
  const server = createServer((req, res) => {
    const url = new URL(req.url, "http://localhost");
    const pathname = decodeURIComponent(url.pathname);
    const blob = blobs[pathname];
    if (blob) {
      requests.push({ path: pathname, status: 200 });
      res.writeHead(200, { "content-type": MIME[path.extname(pathname)] ?? "application/octet-stream" });
      res.end(blob);
      return;
    }
    for (const [prefix, dir] of Object.entries(mounts)) {
      if (!pathname.startsWith(prefix)) continue;
      const file = path.resolve(dir, "." + pathname.slice(prefix.length - 1));
      const inside = file === path.resolve(dir) || file.startsWith(path.resolve(dir) + path.sep);
      if (inside && existsSync(file) && statSync(file).isFile()) {
        requests.push({ path: pathname, status: 200 });
        res.writeHead(200, {
          "content-type": MIME[path.extname(file)] ?? "application/octet-stream",
          "access-control-allow-origin": "*",
        });
        createReadStream(file).pipe(res);
        return;
      }
    }
    requests.push({ path: pathname, status: 404 });
    res.writeHead(404).end("not found");
  });
  await new Promise((resolve) => server.listen(0, "127.0.0.1", resolve));
  const origin = `http://127.0.0.1:${server.address().port}`;
  return { origin, requests, close: () => new Promise((resolve) => server.close(resolve)) };
}

/**
 * Launches Debian's Chromium headless through playwright-core (no browser download), with a
 * new empty profile, software WebGL (SwiftShader: there is no GPU), and every request that
 * leaves `origins` (one or a list) aborted and recorded, so a hidden CDN dependency fails the
 * check instead of hanging on the closed network.
 */
export async function launchBrowser(origins) {
  const { chromium } = await requirePackage("playwright-core");
  const executablePath = process.env.STREAKLIGHT_CHROMIUM ?? "/usr/bin/chromium";
  if (!existsSync(executablePath)) fail(`no Chromium at ${executablePath}: ${CHROMIUM_HINT}`, 2);
  const profile = mkdtempSync(path.join(tmpdir(), "streaklight-chromium-"));
  let context;
  try {
    context = await chromium.launchPersistentContext(profile, {
      executablePath,
      headless: true,
      viewport: { width: 800, height: 800 },
      args: [
        "--no-sandbox", // we run as root on CI
        "--disable-gpu",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--ignore-gpu-blocklist",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
      ],
    });
  } catch (e) {
    rmSync(profile, { recursive: true, force: true });
    fail(`cannot start Chromium at ${executablePath} (${e.message.split("\n")[0]}): ${CHROMIUM_HINT}`, 2);
  }
  const blocked = [];
  await context.route("**/*", (route) => {
    const url = route.request().url();
    const local = [origins].flat().some((origin) => url.startsWith(origin + "/"));
    if (local || url.startsWith("data:") || url.startsWith("blob:")) {
      return route.continue();
    }
    blocked.push(url);
    return route.abort("blockedbyclient");
  });
  return {
    context,
    blocked,
    close: async () => {
      await context.close();
      rmSync(profile, { recursive: true, force: true });
    },
  };
}

/** Opens `url` in a new page; console errors and page errors are collected. */
export async function openPage(browser, url) {
  const page = await browser.context.newPage();
  const log = [];
  const verbose = !!process.env.STREAKLIGHT_ENGINES_VERBOSE;
  const note = (line) => {
    log.push(line);
    if (verbose) console.error(`${(performance.now() / 1000).toFixed(1)} s ${line}`);
  };
  page.on("console", (m) => note(`[${m.type()}] ${m.text()}`));
  page.on("pageerror", (e) => note(`[pageerror] ${e.message}`));
  // The console's "Failed to load resource" does not say which: name it.
  page.on("response", (r) => r.status() >= 400 && note(`[error] HTTP ${r.status()} for ${r.url()}`));
  await page.goto(url);
  return { page, log };
}

// ---------------------------------------------------------------- the report's lights

/**
 * The lights a report promises, in the glTF's (right-handed, metres) world frame:
 * { name, nodeIndex, lightIndex, center, u, v, width, height, normal, radiance, nitsScale }.
 * `normal` is the direction of emission (towards the water): the report's plane normal.
 * `center` is where an engine puts the light: its node's translation, which the report gives
 * as `node_translation` (the fitted rectangle's `center` moved `settings.light_offset` along
 * `normal`, off its wall); checked here to be exactly that.
 */
export function expectedLights(reportPath) {
  let report;
  try {
    report = JSON.parse(readFileSync(reportPath, "utf8"));
  } catch (e) {
    fail(`cannot read the report ${reportPath}: ${e.message}`, 2);
  }
  const nitsScale = report.settings?.nits_scale ?? 1;
  const offset = report.settings?.light_offset ?? 0;
  if (!Array.isArray(report.lights)) fail(`${reportPath} has no "lights" array`, 2);
  return {
    report,
    lights: report.lights
      .filter((l) => l.node_index !== null && l.node_index !== undefined)
      .map((l) => {
        const normal = l.plane?.normal ?? cross(l.v_axis, l.u_axis);
        const node = l.node_translation ?? l.center;
        const moved = sub(node, l.center);
        if (norm(sub(moved, scale(normal, offset))) > 1e-9 * Math.max(1, norm(l.center))) {
          fail(`${reportPath}: light ${l.name}'s node_translation ${fmt(node)} is not its centre moved ${offset} m along its normal`, 2);
        }
        return {
          name: l.name,
          nodeIndex: l.node_index,
          lightIndex: l.light_index,
          center: node,
          u: l.u_axis,
          v: l.v_axis,
          width: l.width,
          height: l.height,
          normal,
          radiance: l.radiance,
          nitsScale,
        };
      }),
  };
}

// ---------------------------------------------------------------- small vector helpers

export const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
export const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
export const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
export const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
export const norm = (a) => Math.sqrt(dot(a, a));
export const unit = (a) => scale(a, 1 / norm(a));
export const fmt = (a) => `(${a.map((x) => x.toPrecision(6)).join(", ")})`;
