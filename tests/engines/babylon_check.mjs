// A real engine (Babylon.js) reads our lights.
//
//   node tests/engines/babylon_check.mjs --gltf OUT.gltf --report REPORT.json \
//        --screenshot lit.png [--dark-gltf IN.gltf --dark-screenshot dark.png] \
//        [--mask-screenshot water.png] [--water WaterNodeName] [--right-handed true]
//
// Loads OUT.gltf (a `streaklight fit` output) in Babylon.js's own glTF loader inside headless
// Chromium and checks that the RectAreaLights Babylon created have the positions, sizes,
// orientation (lighting the water side) and colours that REPORT.json (the fit's --report) says.
// Saves screenshots of the lit scene, of the input scene without our lights, and a mask of the
// water, which tests/engines.rs compares. Exit 0 = all checks passed, 1 = a check failed,
// 2 = the harness could not run (missing Node package, Chromium, or input).

import { readFileSync } from "node:fs";
import path from "node:path";
import {
  HERE, cross, dot, expectedLights, fail, fmt, launchBrowser, norm, openPage, parseArgs,
  requireModuleFile, requirePackage, scale, startServer, sub, unit,
} from "./harness.mjs";

const args = parseArgs(process.argv.slice(2), ["gltf", "report", "screenshot"], [
  "dark-gltf", "dark-screenshot", "mask-screenshot", "water", "right-handed",
]);
const rightHanded = args["right-handed"] === "true";

// A hung page (a shader that never compiles, a promise that never settles) must fail, not
// stall CI: the whole check normally takes 10 to 30 s.
const WATCHDOG_SECONDS = 240;
setTimeout(() => fail(`no result after ${WATCHDOG_SECONDS} s`), WATCHDOG_SECONDS * 1000).unref();

// Tolerances. Babylon stores matrices and vectors as float32 (relative precision 6e-8); the
// numbers pass through a node quaternion, a 180-degree orientation node and the handedness
// root, so 1e-4 relative leaves three orders of magnitude of margin while still catching any
// real mapping error (a swapped width/height, a missed aspect, a wrong axis or sign).
const REL = 1e-4;

requireModuleFile("@babylonjs/core/package.json");
requireModuleFile("@babylonjs/loaders/glTF/2.0/Extensions/EXT_lights_area.js");
const babylonVersion = JSON.parse(
  readFileSync(path.join(HERE, "node_modules/@babylonjs/loaders/package.json"), "utf8"),
).version;

const { lights: expected, report } = expectedLights(args.report);
if (expected.length === 0) fail(`${args.report} lists no written light: nothing to check`, 2);

// Babylon's LTC tables (areaLightsLTC.bin, normally fetched from its CDN) are the fitted
// GGX tables of Heitz et al.'s ltc_code, the same ones three.js ships as
// RectAreaLightTexturesLib (Babylon's LTC shader code is three's, with the same texture layout).
// The file interleaves, per texel, LTC1's four half floats then LTC2's four.
async function ltcTables() {
  const { RectAreaLightTexturesLib } = await requirePackage(
    "three/examples/jsm/lights/RectAreaLightTexturesLib.js",
  );
  RectAreaLightTexturesLib.init();
  const a = RectAreaLightTexturesLib.LTC_HALF_1.image.data;
  const b = RectAreaLightTexturesLib.LTC_HALF_2.image.data;
  const out = new Uint16Array(a.length * 2);
  for (let t = 0; t < a.length / 4; t++) {
    out.set(a.subarray(4 * t, 4 * t + 4), 8 * t);
    out.set(b.subarray(4 * t, 4 * t + 4), 8 * t + 4);
  }
  return Buffer.from(out.buffer);
}

const litPath = path.resolve(args.gltf);
const darkPath = args["dark-gltf"] ? path.resolve(args["dark-gltf"]) : null;
const server = await startServer(
  {
    "/node_modules/": path.join(HERE, "node_modules"),
    "/page/": HERE,
    "/lit/": path.dirname(litPath),
    ...(darkPath ? { "/dark/": path.dirname(darkPath) } : {}),
  },
  // Tools.AssetBaseUrl replaces Babylon's "https://assets.babylonjs.com/core" prefix.
  { "/babylon-assets/areaLights/areaLightsLTC.bin": await ltcTables() },
);
const browser = await launchBrowser(server.origin);
const problems = [];

let opened;
try {
  const started = Date.now();
  opened = await openPage(browser, `${server.origin}/page/babylon_page.html`);
  await opened.page.waitForFunction(() => typeof window.loadScene === "function", null, { timeout: 60000 });
  console.log(`Babylon.js ${babylonVersion} started in ${((Date.now() - started) / 1000).toFixed(1)} s`);
  // The scene without our lights first, then the lit one (whose mask render changes materials).
  if (darkPath && args["dark-screenshot"]) {
    await render(`/dark/${encodeURIComponent(path.basename(darkPath))}`, args["dark-screenshot"], null);
  }
  const lit = await render(`/lit/${encodeURIComponent(path.basename(litPath))}`, args.screenshot, args["mask-screenshot"]);
  console.log(`rendered in ${((Date.now() - started) / 1000).toFixed(1)} s`);
  compareLights(lit);
} catch (e) {
  problems.push(`the page failed: ${e.message.split("\n")[0]}\n  page log:\n    ${opened?.log.join("\n    ")}`);
} finally {
  await browser.close();
  await server.close();
}
if (browser.blocked.length) {
  problems.push(`the page tried to reach the network (blocked): ${[...new Set(browser.blocked)].join(", ")}`);
}
if (problems.length) {
  const missing = server.requests.filter((r) => r.status !== 200).map((r) => r.path);
  if (missing.length) console.error(`requests the server could not answer: ${missing.join(", ")}`);
  fail(`${problems.length} problem(s):\n  - ${problems.join("\n  - ")}`);
}
console.log(`all ${expected.length} light(s) match the report`);

/** Loads `url`, screenshots the canvas to `shot`, optionally the water mask to `maskShot`. */
async function render(url, shot, maskShot) {
  const { page, log } = opened;
  const errorsBefore = log.length;
  const result = await page.evaluate(([u, rh]) => window.loadScene(u, { rightHanded: rh }), [url, rightHanded]);
  const canvas = page.locator("#view");
  await canvas.screenshot({ path: shot });
  if (maskShot) {
    const water = args.water ?? report.settings?.water ?? "Water";
    await page.evaluate((w) => window.showOnly(w), water);
    await canvas.screenshot({ path: maskShot });
  }
  const errors = log.slice(errorsBefore).filter((l) => l.startsWith("[error]") || l.startsWith("[pageerror]"));
  if (errors.length) problems.push(`errors in the page while showing ${url}:\n      ${errors.join("\n      ")}`);
  return result;
}

/**
 * Babylon converts glTF's right-handed frame to its left-handed one with the loader's
 * `__root__` node (a 180-degree turn about Y and a mirror of Z). Everything Babylon made is
 * taken back into the glTF frame through the inverse of that root, so it can be compared with
 * the report's numbers as written.
 */
function compareLights(lit) {
  const m = lit.rootWorldMatrix; // Babylon: row vectors, translation in m[12..14]
  const rows = [[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]];
  for (let i = 0; i < 3; i++) {
    for (let j = 0; j < 3; j++) {
      if (Math.abs(dot(rows[i], rows[j]) - (i === j ? 1 : 0)) > 1e-6) {
        problems.push(`Babylon's __root__ is not a rotation/reflection (matrix ${m.join(", ")}): cannot map back to glTF`);
        return;
      }
    }
  }
  if (norm([m[12], m[13], m[14]]) > 1e-9) problems.push(`Babylon's __root__ is translated: ${m.slice(12, 15)}`);
  // Babylon world = glTF world * R (row vector). R orthogonal, so glTF = Babylon * R^T.
  const toGltf = (p) => [dot(p, rows[0]), dot(p, rows[1]), dot(p, rows[2])];
  const det = dot(cross(rows[0], rows[1]), rows[2]);
  console.log(`Babylon's handedness root: det ${det.toFixed(3)} (${det < 0 ? "mirror: left-handed scene" : "no mirror: right-handed scene"})`);

  const rect = lit.lights.filter((l) => l.className === "RectAreaLight");
  if (rect.length !== expected.length) {
    problems.push(
      `Babylon created ${rect.length} RectAreaLight(s) (${rect.map((l) => l.name).join(", ")}); the report lists ${expected.length}`,
    );
  }
  for (const want of expected) {
    // The light's pointer metadata names its node: /nodes/N/extensions/EXT_lights_area.
    const pointer = `/nodes/${want.nodeIndex}/extensions/EXT_lights_area`;
    const got = rect.find((l) => l.pointers.includes(pointer));
    const tag = `light "${want.name}" (node ${want.nodeIndex})`;
    if (!got) {
      problems.push(`${tag}: Babylon made no RectAreaLight from ${pointer}`);
      continue;
    }
    if (got.name !== want.name) problems.push(`${tag}: Babylon named it "${got.name}"`);
    if (!got.enabled) problems.push(`${tag}: disabled in Babylon`);
    if (!got.ltcReady) problems.push(`${tag}: its LTC tables never became ready (area lights would render black)`);

    const size = Math.max(want.width, want.height);
    const pos = toGltf(got.position);
    const posErr = norm(sub(pos, want.center));
    if (posErr > REL * Math.max(1, norm(want.center))) {
      problems.push(`${tag}: centre ${fmt(pos)} in glTF frame, report says ${fmt(want.center)} (off by ${posErr.toExponential(2)})`);
    }
    const w = toGltf(got.widthVector);
    const h = toGltf(got.heightVector);
    for (const [what, vec, len, axis] of [["width", w, want.width, want.u], ["height", h, want.height, want.v]]) {
      if (Math.abs(norm(vec) - len) > REL * size) {
        problems.push(`${tag}: ${what} ${norm(vec)} in Babylon, report says ${len}`);
      }
      // The rectangle is symmetric about its centre, so only the axis's line matters.
      const off = norm(cross(unit(vec), unit(axis)));
      if (!(off <= REL)) {
        problems.push(`${tag}: ${what} runs along ${fmt(unit(vec))} in glTF frame, report's axis is ${fmt(axis)}`);
      }
    }
    // Babylon's LTC shader (ltcHelperFunctions: rectCoords, lightNormal = cross(v1, v2)) lights
    // a point P only where dot(-(W x H), P - corner) >= 0, W and H being the world width and
    // height vectors: -(W x H) is the side it lights. Map that half-space back to glTF (R is
    // orthogonal, so the plane's normal maps like a vector) and compare with the report's normal.
    // (The cross product is taken in Babylon's frame, where the shader takes it: the mirror
    // root flips the sign of a cross product of mapped vectors.)
    const litSide = toGltf(unit(scale(cross(got.widthVector, got.heightVector), -1)));
    const align = dot(litSide, unit(want.normal));
    if (!(align >= 1 - REL)) {
      problems.push(
        `${tag}: Babylon lights the side ${fmt(litSide)} (glTF frame), the report's light emits towards ${fmt(want.normal)}` +
          (align < 0 ? " -- the light faces away from the water" : ""),
      );
    }
    // Babylon's diffuse x intensity is the light's radiance times the nits scale.
    const emitted = got.diffuse.map((c) => c * got.intensity);
    const wantEmitted = want.radiance.map((c) => c * want.nitsScale);
    const peak = Math.max(...wantEmitted);
    if (emitted.some((c, i) => !(Math.abs(c - wantEmitted[i]) <= REL * peak))) {
      problems.push(`${tag}: diffuse x intensity ${fmt(emitted)}, report's radiance x nits scale ${fmt(wantEmitted)}`);
    }
    console.log(
      `  ${tag}: centre ${fmt(pos)}, ${norm(w).toPrecision(6)} x ${norm(h).toPrecision(6)}, lights ${fmt(litSide)}, ` +
        `diffuse ${fmt(got.diffuse)} x ${got.intensity}`,
    );
  }
}
