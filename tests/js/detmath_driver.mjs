// node detmath_driver.mjs MODULE_DIR ARGS.f64 OUT.f64
// ARGS holds pairs (a, b) of float64; OUT receives, per pair, det_sin(a),
// det_atan2(a, b), Math.sin(a) and Math.atan2(a, b).
import { readFileSync, writeFileSync } from "node:fs";
import { resolve } from "node:path";
import { pathToFileURL } from "node:url";

const [moduleDir, argsPath, outPath] = process.argv.slice(2);
const { det_sin, det_atan2 } = await import(pathToFileURL(resolve(moduleDir, "detmath.js")).href);
const buf = readFileSync(argsPath);
const args = new Float64Array(buf.buffer, buf.byteOffset, buf.byteLength / 8);
const n = args.length / 2;
const out = new Float64Array(4 * n);
for (let k = 0; k < n; k++) {
  const a = args[2 * k], b = args[2 * k + 1];
  out[4 * k] = det_sin(a);
  out[4 * k + 1] = det_atan2(a, b);
  out[4 * k + 2] = Math.sin(a);
  out[4 * k + 3] = Math.atan2(a, b);
}
writeFileSync(outPath, Buffer.from(out.buffer));
