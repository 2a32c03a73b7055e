// Opens a `fit --debug-dir` folder's index.html in headless Chromium and checks it against the
// fit's report: every picture loads, the page names every light with the report's size, and
// its warnings are the report's. Prints what it saw as JSON and saves a screenshot.
//
// node debug_page_check.mjs --dir DEBUG_DIR --report REPORT.json --screenshot OUT.png

import { readFileSync } from "node:fs";
import { fail, launchBrowser, openPage, parseArgs, startServer } from "./harness.mjs";

const args = parseArgs(process.argv.slice(2), ["dir", "report", "screenshot"]);
const report = JSON.parse(readFileSync(args.report, "utf8"));
const server = await startServer({ "/": args.dir });
const browser = await launchBrowser(server.origin);
const problems = [];
let seen;
try {
  const { page, log } = await openPage(browser, `${server.origin}/index.html`);
  await page.waitForLoadState("load");
  seen = await page.evaluate(() => ({
    title: document.title,
    text: document.body.innerText,
    images: [...document.images].map((img) => ({
      src: img.getAttribute("src"),
      complete: img.complete,
      width: img.naturalWidth,
      height: img.naturalHeight,
      shownWidth: img.getBoundingClientRect().width,
    })),
    lights: [...document.querySelectorAll("tr.light")].map((row) => ({
      name: row.dataset.light,
      width: row.dataset.width,
      height: row.dataset.height,
      unconstrained: row.querySelectorAll("li.edge.unconstrained").length,
    })),
    warnings: [...document.querySelectorAll("#warnings li")].map((li) => li.textContent),
  }));
  await page.screenshot({ path: args.screenshot, fullPage: true });
  if (seen.images.length < 5) problems.push(`only ${seen.images.length} pictures on the page`);
  for (const img of seen.images) {
    if (!img.complete || img.width === 0) problems.push(`the picture ${img.src} did not load`);
    if (img.shownWidth < 50) problems.push(`the picture ${img.src} is shown ${img.shownWidth} px wide`);
  }
  if (seen.lights.length !== report.lights.length) {
    problems.push(`the page lists ${seen.lights.length} lights, the report ${report.lights.length}`);
  }
  for (const light of report.lights) {
    const row = seen.lights.find((l) => l.name === light.name);
    if (!row) {
      problems.push(`the page does not name ${light.name}`);
      continue;
    }
    if (!seen.text.includes(light.name)) problems.push(`${light.name} is not visible text`);
    for (const key of ["width", "height"]) {
      if (row[key] !== light[key].toFixed(4)) {
        problems.push(`${light.name}: the page says ${key} ${row[key]}, the report ${light[key]}`);
      }
    }
    const unconstrained = Object.values(light.edges).filter((e) => e.status === "unconstrained").length;
    if (row.unconstrained !== unconstrained) {
      problems.push(`${light.name}: the page marks ${row.unconstrained} edges unconstrained, the report ${unconstrained}`);
    }
  }
  if (JSON.stringify(seen.warnings) !== JSON.stringify(report.warnings)) {
    problems.push(`the page's warnings ${JSON.stringify(seen.warnings)} are not the report's ${JSON.stringify(report.warnings)}`);
  }
  const errors = log.filter((l) => l.startsWith("[error]") || l.startsWith("[pageerror]"));
  if (errors.length) problems.push(`console errors: ${errors.join("; ")}`);
  if (browser.blocked.length) problems.push(`requests outside the folder: ${browser.blocked.join(", ")}`);
  const missing = server.requests.filter((r) => r.status !== 200);
  if (missing.length) problems.push(`missing files: ${missing.map((r) => r.path).join(", ")}`);
} finally {
  await browser.close();
  await server.close();
}
console.log(JSON.stringify({ images: seen?.images, lights: seen?.lights, warnings: seen?.warnings?.length }));
if (problems.length) fail(problems.join("\n"));
