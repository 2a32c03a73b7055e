// Smoke test of the three.js example, run the way its README says:
//
//   node tests/engines/threejs_check.mjs --gltf OUT.gltf --report REPORT.json --screenshot shot.png
//
// Starts the example's own server (its package.json's `start` script, on a free port), opens
// its page (examples/threejs/index.html: GLTFLoader + ext-lights-area-plugin.js, three from
// examples/threejs/node_modules) on OUT.gltf in headless Chromium, and checks that the
// RectAreaLights the plugin made match REPORT.json. OUT.gltf is served from a second local
// server (with CORS), as `?scene=URL`. three.js is right-handed like glTF, so world coordinates
// compare directly. Exit codes as babylon_check.mjs.

import { spawn } from "node:child_process";
import { existsSync, readFileSync, writeFileSync } from "node:fs";
import path from "node:path";
import {
  HERE, cross, dot, expectedLights, fail, fmt, launchBrowser, norm, openPage, parseArgs, scale,
  startServer, sub, unit,
} from "./harness.mjs";

const args = parseArgs(process.argv.slice(2), ["gltf", "report", "screenshot"]);
const WATCHDOG_SECONDS = 180;
setTimeout(() => fail(`no result after ${WATCHDOG_SECONDS} s`), WATCHDOG_SECONDS * 1000).unref();
const REL = 1e-4; // three keeps matrices in float32, as Babylon does: see babylon_check.mjs
const EXAMPLE = path.resolve(HERE, "../../examples/threejs");
const EXAMPLE_HINT = "run `npm ci --prefix examples/threejs` from the repository root";

const threeVersion = exampleThree();
const { lights: expected } = expectedLights(args.report);
if (expected.length === 0) fail(`${args.report} lists no written light: nothing to check`, 2);

const litPath = path.resolve(args.gltf);
const example = await startExample();
const server = await startServer({ "/lit/": path.dirname(litPath) });
const browser = await launchBrowser([example.origin, server.origin]);
const problems = [];
try {
  await refusesOutside(example.origin);
  const scene = encodeURIComponent(`${server.origin}/lit/${encodeURIComponent(path.basename(litPath))}`);
  const { page, log } = await openPage(browser, `${example.origin}/?scene=${scene}&size=600`);
  // An error in the page (a module of the import map or the scene it cannot load) may stop
  // its script before it can report: fail at once, instead of at the timeout.
  let finished = false;
  const erred = (async () => {
    while (!finished && !log.some((l) => l.startsWith("[error]") || l.startsWith("[pageerror]"))) {
      await new Promise((resolve) => setTimeout(resolve, 200));
    }
    if (!finished) throw new Error("an error in the page");
  })();
  try {
    await Promise.race([
      page.waitForFunction(() => window.streaklightResult || window.streaklightError, null, { timeout: 90000 }),
      erred,
    ]);
    finished = true;
  } catch (e) {
    finished = true;
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
  example.close();
}
if (browser.blocked.length) problems.push(`the page tried to reach the network (blocked): ${browser.blocked.join(", ")}`);
if (problems.length) fail(`${problems.length} problem(s):\n  - ${problems.join("\n  - ")}`);
console.log(`three.js ${threeVersion}: all ${expected.length} RectAreaLight(s) match the report`);

function readJson(file) {
  try {
    return JSON.parse(readFileSync(file, "utf8"));
  } catch (e) {
    return fail(`cannot read ${file}: ${e.message}`, 2);
  }
}

/**
 * The version of three the example installed, after checking that it is the one its
 * package.json pins and the one this folder pins (for the Babylon check's LTC tables), so
 * that both engines' results stay comparable.
 */
function exampleThree() {
  const pinned = readJson(path.join(EXAMPLE, "package.json")).dependencies?.three;
  const ours = readJson(path.join(HERE, "package.json")).dependencies?.three;
  if (pinned !== ours) {
    fail(`examples/threejs/package.json pins three ${pinned}, tests/engines/package.json ${ours}: pin one version in both`);
  }
  const installed = path.join(EXAMPLE, "node_modules/three/package.json");
  if (!existsSync(installed)) fail(`examples/threejs/node_modules/three is missing: ${EXAMPLE_HINT}`, 2);
  const version = readJson(installed).version;
  if (version !== pinned) fail(`examples/threejs/node_modules holds three ${version}, its package.json pins ${pinned}: ${EXAMPLE_HINT}`, 2);
  return version;
}

/** Runs the example's `npm start` command (`node SCRIPT`) on a free port; returns its origin. */
async function startExample() {
  const start = readJson(path.join(EXAMPLE, "package.json")).scripts?.start ?? "";
  const [command, ...rest] = start.split(" ");
  if (command !== "node") fail(`examples/threejs/package.json's start script is ${JSON.stringify(start)}, not \`node SCRIPT\``, 2);
  const child = spawn(process.execPath, rest, {
    cwd: EXAMPLE,
    env: { ...process.env, PORT: "0" },
    stdio: ["ignore", "pipe", "pipe"],
  });
  process.on("exit", () => child.kill()); // also when fail() exits early
  let output = "";
  const origin = await new Promise((resolve, reject) => {
    const read = (data) => {
      output += data;
      const url = output.match(/^open (http:\/\/[^/\s]+)\/$/m);
      if (url) resolve(url[1]);
    };
    child.stdout.on("data", read);
    child.stderr.on("data", read);
    child.on("error", reject);
    child.on("exit", (code) => reject(new Error(`exited with code ${code}:\n${output}`)));
  }).catch((e) => fail(`\`${start}\` in examples/threejs did not start serving: ${e.message}`, 2));
  return { origin, close: () => child.kill() };
}

/** The example's server must not hand out files outside its folder. */
async function refusesOutside(origin) {
  const inside = await fetch(`${origin}/package.json`);
  if (inside.status !== 200) problems.push(`the example's server answers ${inside.status} for its own package.json`);
  // The repository's README.md, two folders up. "%2f" is not a path separator to the URL
  // parser, so the ".." segments reach the server undecoded.
  if (!existsSync(path.join(EXAMPLE, "../../README.md"))) fail("no README.md in the repository root", 2);
  const outside = await fetch(`${origin}/..%2f..%2fREADME.md`);
  if (outside.status !== 404) problems.push(`the example's server answers ${outside.status} for ../../README.md, outside its folder`);
}

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
