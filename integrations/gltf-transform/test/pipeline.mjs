// Runs a streaklight output through the real glTF-Transform CLI with this package's config
// (`copy`, `dedup`, `prune`, `optimize --simplify false`) and checks that every light, every
// light node's transform and extension, and every fallback quad come out identical. Also
// writes `stock-copy/stock-copy.gltf`: `copy` without the config, which drops the lights.
// Each output gets a folder of its own (OUT_DIR/COMMAND/COMMAND.gltf): glTF-Transform writes
// buffers under the names they had, so outputs sharing a folder would overwrite each other's.
//
// usage: node test/pipeline.mjs IN.gltf OUT_DIR   (prints one line per check; exit 1 on failure)

import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { isDeepStrictEqual } from 'node:util';

const here = dirname(fileURLToPath(import.meta.url));
const cli = join(here, '..', 'node_modules', '@gltf-transform', 'cli', 'bin', 'cli.js');
const config = join(here, '..', 'gltf-transform.config.mjs');
const [input, outDir] = process.argv.slice(2);
if (!input || !outDir) {
  console.error('usage: node test/pipeline.mjs IN.gltf OUT_DIR');
  process.exit(2);
}

const run = (args) => execFileSync(process.execPath, [cli, ...args], { stdio: ['ignore', 'pipe', 'pipe'] });
const read = (p) => JSON.parse(readFileSync(p, 'utf8'));

/** What must survive: the lights, and per streaklight node (by name) its light and frame. */
function lightsOf(json) {
  const nodes = {};
  for (const n of json.nodes ?? []) {
    const role = n.extras?.streaklight?.role;
    if (!role) continue;
    nodes[n.name] = {
      role,
      extension: n.extensions?.EXT_lights_area ?? null,
      extras: n.extras,
      // A light node's frame is the light's; a quad's geometry may be requantised by
      // optimize, so only its extras (which rebuild the light) must be identical.
      ...(role === 'light' ? { translation: n.translation, rotation: n.rotation } : {}),
    };
  }
  return { lights: json.extensions?.EXT_lights_area ?? null, used: (json.extensionsUsed ?? []).includes('EXT_lights_area'), nodes };
}

const want = lightsOf(read(input));
let failed = 0;
if (!want.lights || Object.keys(want.nodes).length === 0) {
  console.error(`${input}: no EXT_lights_area lights or streaklight nodes to check`);
  process.exit(1);
}
for (const command of [['copy'], ['dedup'], ['prune'], ['optimize', '--simplify', 'false']]) {
  mkdirSync(join(outDir, command[0]), { recursive: true });
  const out = join(outDir, command[0], `${command[0]}.gltf`);
  run([command[0], input, out, ...command.slice(1), '--config', config]);
  const got = lightsOf(read(out));
  if (isDeepStrictEqual(got, want)) {
    console.log(`ok: ${command.join(' ')} kept ${want.lights.lights.length} light(s) and ${Object.keys(want.nodes).length} streaklight node(s) -> ${out}`);
  } else {
    failed += 1;
    console.log(`FAILED: ${command.join(' ')} changed the lights -> ${out}\nwant ${JSON.stringify(want)}\ngot  ${JSON.stringify(got)}`);
  }
}
mkdirSync(join(outDir, 'stock-copy'), { recursive: true });
const stock = join(outDir, 'stock-copy', 'stock-copy.gltf');
run(['copy', input, stock]);
const stripped = lightsOf(read(stock));
if (stripped.lights !== null || stripped.used) {
  failed += 1;
  console.log(`FAILED: stock copy (without the extension) kept EXT_lights_area: ${stock}`);
} else {
  console.log(`ok: stock copy dropped EXT_lights_area -> ${stock}`);
}
process.exit(failed === 0 ? 0 : 1);
