// Smoke test of the three.js example:
//
//   node tests/engines/threejs_check.mjs --gltf OUT.gltf --report REPORT.json --screenshot shot.png
//
// Opens examples/threejs/index.html (GLTFLoader + examples/threejs/ext-lights-area-plugin.js,
// three from this folder's node_modules) on OUT.gltf in headless Chromium and checks that the
// RectAreaLights the plugin made match REPORT.json. three.js is right-handed like glTF, so
// world coordinates compare directly. Exit codes as babylon_check.mjs.

import { writeFileSync } from "node:fs";
import path from "node:path";
import {
  HERE, cross, dot, expectedLights, fail, fmt, launchBrowser, norm, openPage, parseArgs,
  requireModuleFile, scale, startServer, sub, unit,
} from "./harness.mjs";

const args = parseArgs(process.argv.slice(2), ["gltf", "report", "screenshot"]);
const WATCHDOG_SECONDS = 180;
setTimeout(() => fail(`no result after ${WATCHDOG_SECONDS} s`), WATCHDOG_SECONDS * 1000).unref();
const REL = 1e-4; // three keeps matrices in float32, as Babylon does: see babylon_check.mjs

requireModuleFile("three/build/three.module.js");
const { lights: expected } = expectedLights(args.report);
if (expected.length === 0) fail(`${args.report} lists no written light: nothing to check`, 2);

const repo = path.resolve(HERE, "../..");
const litPath = path.resolve(args.gltf);
// The page's import map reaches three at ../../tests/engines/node_modules: serve the repository.
const server = await startServer({ "/lit/": path.dirname(litPath), "/": repo });
const browser = await launchBrowser(server.origin);
const problems = [];
try {
  const scene = encodeURIComponent(`/lit/${path.basename(litPath)}`);
  const { page, log } = await openPage(browser, `${server.origin}/examples/threejs/index.html?scene=${scene}&size=600`);
  try {
    await page.waitForFunction(() => window.streaklightResult || window.streaklightError, null, { timeout: 90000 });
  } catch (e) {
    throw new Error(`the example page never finished: ${e.message.split("\n")[0]}\n  page log:\n    ${log.join("\n    ")}`);
  }
  const error = await page.evaluate(() => window.streaklightError);
  if (error) throw new Error(`the example page failed: ${error}\n  page log:\n    ${log.join("\n    ")}`);
  const made = await page.evaluate(() => window.streaklightResult);
  await page.waitForTimeout(500); // a few frames of the animation loop
  // The canvas's own pixels (preserveDrawingBuffer): a software-rendered animation loop is too
  // slow for Playwright's "element is stable" wait before an element screenshot.
  const png = await page.evaluate(() => document.querySelector("canvas").toDataURL("image/png"));
  writeFileSync(args.screenshot, Buffer.from(png.split(",")[1], "base64"));
  compare(made);
  const errors = log.filter((l) => l.startsWith("[error]") || l.startsWith("[pageerror]"));
  if (errors.length) problems.push(`errors in the page:\n      ${errors.join("\n      ")}`);
} catch (e) {
  problems.push(e.message);
} finally {
  await browser.close();
  await server.close();
}
if (browser.blocked.length) problems.push(`the page tried to reach the network (blocked): ${browser.blocked.join(", ")}`);
if (problems.length) fail(`${problems.length} problem(s):\n  - ${problems.join("\n  - ")}`);
console.log(`three.js: all ${expected.length} RectAreaLight(s) match the report`);

function compare(made) {
  if (made.length !== expected.length) {
    problems.push(`the plugin made ${made.length} RectAreaLight(s); the report lists ${expected.length}`);
  }
  for (const want of expected) {
    const tag = `light "${want.name}" (node ${want.nodeIndex})`;
    const got = made.find((l) => l.userData?.EXT_lights_area?.node === want.nodeIndex);
    if (!got) {
      problems.push(`${tag}: no RectAreaLight for this node`);
      continue;
    }
    const size = Math.max(want.width, want.height);
    if (norm(sub(got.position, want.center)) > REL * Math.max(1, norm(want.center))) {
      problems.push(`${tag}: at ${fmt(got.position)}, report says ${fmt(want.center)}`);
    }
    if (Math.abs(got.width - want.width) > REL * size || Math.abs(got.height - want.height) > REL * size) {
      problems.push(`${tag}: ${got.width} x ${got.height}, report says ${want.width} x ${want.height}`);
    }
    // RectAreaLight spans its local X (width) and Y (height) and lights the side its local -Z
    // points to (three's LTC_Evaluate, the same test as Babylon's).
    for (const [what, axis, wantAxis] of [["width", got.xAxis, want.u], ["height", got.yAxis, want.v]]) {
      if (!(norm(cross(unit(axis), unit(wantAxis))) <= REL)) {
        problems.push(`${tag}: ${what} along ${fmt(unit(axis))}, report's axis is ${fmt(wantAxis)}`);
      }
    }
    const litSide = unit(scale(got.zAxis, -1));
    if (!(dot(litSide, unit(want.normal)) >= 1 - REL)) {
      problems.push(`${tag}: lights the side ${fmt(litSide)}, the report's light emits towards ${fmt(want.normal)}`);
    }
    const emitted = got.color.map((c) => c * got.intensity);
    const wantEmitted = want.radiance.map((c) => c * want.nitsScale);
    const peak = Math.max(...wantEmitted);
    if (emitted.some((c, i) => !(Math.abs(c - wantEmitted[i]) <= REL * peak))) {
      problems.push(`${tag}: color x intensity ${fmt(emitted)}, report's radiance x nits scale ${fmt(wantEmitted)}`);
    }
  }
}
