// Runs the Khronos glTF-Validator (npm `gltf-validator`) on one .gltf or .glb file and prints
// its report as JSON on stdout. External resources (.bin files, images) are read relative to
// the file, as a viewer would.
//
// Usage: node tests/validator/validate.mjs FILE
// Exit codes: 0 = report printed (read it for errors), 2 = usage or unreadable file,
// 3 = the validator package is not installed (run `npm ci --prefix tests/validator`),
// 4 = the validator could not process the file at all.
import { readFile } from "node:fs/promises";
import path from "node:path";

const file = process.argv[2];
if (!file || process.argv.length > 3) {
  console.error("usage: node tests/validator/validate.mjs FILE");
  process.exit(2);
}

let validator;
try {
  validator = (await import("gltf-validator")).default;
} catch (e) {
  console.error(
    `the npm package gltf-validator is missing (${e.message}); run \`npm ci --prefix tests/validator\``,
  );
  process.exit(3);
}

let bytes;
try {
  bytes = new Uint8Array(await readFile(file));
} catch (e) {
  console.error(`${file}: ${e.message}`);
  process.exit(2);
}

const dir = path.dirname(path.resolve(file));
try {
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0, // no limit
    externalResourceFunction: (uri) =>
      readFile(path.resolve(dir, decodeURIComponent(uri))).then(
        (data) => new Uint8Array(data),
      ),
  });
  process.stdout.write(JSON.stringify(report, null, 2) + "\n");
} catch (e) {
  console.error(`${file}: the validator could not process the file: ${e}`);
  process.exit(4);
}
