// Parity driver: render cases with the JavaScript renderer core under node.
//   node parity_driver.mjs MODULE_DIR CASES.json OUT_DIR
// CASES.json is a list of { id, scene, width, height, gradient, zoom }; `scene`
// holds the Scene fields that differ from the generated default.  gradient
// "exact" or "central" calls `render`; "pair" calls `render_pair` (both
// pipelines in one pass).  For each frame this writes OUT_DIR/<id>[.<pipeline>]
// .image.f64 (H*W*3 float64), .grad.f64 (H*W*2), .chamber.u8 and .kink.u8, and
// prints one JSON line { id, ms }.
import { readFileSync, writeFileSync } from "node:fs";
import { join, resolve } from "node:path";
import { pathToFileURL } from "node:url";

const [moduleDir, casesPath, outDir] = process.argv.slice(2);
const mod = (name) => import(pathToFileURL(resolve(moduleDir, `${name}.js`)).href);
const { render, render_pair } = await mod("render");
const { DEFAULT_SCENE } = await mod("constants");

function save(prefix, frame) {
  writeFileSync(join(outDir, `${prefix}.image.f64`), Buffer.from(frame.image.buffer));
  writeFileSync(join(outDir, `${prefix}.grad.f64`), Buffer.from(frame.grad.buffer));
  writeFileSync(join(outDir, `${prefix}.chamber.u8`), Buffer.from(frame.chamber.buffer));
  writeFileSync(join(outDir, `${prefix}.kink.u8`), Buffer.from(frame.kink.buffer));
}

const cases = JSON.parse(readFileSync(casesPath, "utf-8"));
for (const c of cases) {
  const scene = { ...DEFAULT_SCENE, ...c.scene };
  const t0 = performance.now();
  if (c.gradient === "pair") {
    const { numeric, symbolic } = render_pair(scene, c.width, c.height, c.zoom ?? 1.0);
    save(`${c.id}.central`, numeric);
    save(`${c.id}.exact`, symbolic);
  } else {
    save(c.id, render(scene, c.width, c.height, c.gradient, c.zoom ?? 1.0));
  }
  console.log(JSON.stringify({ id: c.id, ms: performance.now() - t0 }));
}
