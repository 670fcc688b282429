// Parity driver: render cases with the JavaScript renderer core under node.
//   node parity_driver.mjs MODULE_DIR CASES.json OUT_DIR
// CASES.json is a list of { id, scene, width, height, gradient, zoom[, numeric] };
// `scene` holds the Scene fields that differ from the generated default.
// gradient "exact", "central" or "footprint" calls `render`; "pair" calls
// `render_pair` (the numeric pipeline `numeric`, default "central", and the
// exact one in one pass).  For each frame this writes OUT_DIR/<id>[.<pipeline>]
// .image.f64 (H*W*3 float64), .grad.f64 (H*W*2), .uv.f64 (H*W*2), .chamber.u8
// and .kink.u8, and prints one JSON line { id, ms }.
import { readFileSync, writeFileSync } from "node:fs";
import { join, resolve } from "node:path";
import { pathToFileURL } from "node:url";

const [moduleDir, casesPath, outDir] = process.argv.slice(2);
const mod = (name) => import(pathToFileURL(resolve(moduleDir, `${name}.js`)).href);
const { render, render_pair } = await mod("render");
const { DEFAULT_SCENE } = await mod("constants");

function save(prefix, frame) {
  for (const [name, ext] of [["image", "f64"], ["grad", "f64"], ["uv", "f64"], ["chamber", "u8"], ["kink", "u8"]]) {
    writeFileSync(join(outDir, `${prefix}.${name}.${ext}`), Buffer.from(frame[name].buffer));
  }
}

const cases = JSON.parse(readFileSync(casesPath, "utf-8"));
for (const c of cases) {
  const scene = { ...DEFAULT_SCENE, ...c.scene };
  const t0 = performance.now();
  if (c.gradient === "pair") {
    const numeric = c.numeric ?? "central";
    const frames = render_pair(scene, c.width, c.height, c.zoom ?? 1.0, numeric);
    save(`${c.id}.${numeric}`, frames.numeric);
    save(`${c.id}.exact`, frames.symbolic);
  } else {
    save(c.id, render(scene, c.width, c.height, c.gradient, c.zoom ?? 1.0));
  }
  console.log(JSON.stringify({ id: c.id, ms: performance.now() - t0 }));
}
