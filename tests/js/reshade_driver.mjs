// Re-shade driver: the simulator's PairRenderer through a sequence of scenes,
// beside full renders of each, under node.
//   node reshade_driver.mjs MODULE_DIR SPEC.json OUT_DIR
// SPEC.json: { width, height, steps: [{ id, scene, zoom, numeric }], curve: [eps...], strides: [...] }
// (`scene` holds the Scene fields that differ from the generated default).  Per step
// this writes OUT_DIR/<id>.{reshade.numeric, reshade.symbolic, render.numeric,
// render.exact}.<array> (see parity_driver.mjs) and prints one JSON line
// { id, full, shaded, curves, curve_render }: `curves[stride]` is
// PairRenderer.ledger_along_eps(curve, stride) for each of `strides`, and
// `curve_render` compare() of full central renders at each step against the
// exact render.
import { readFileSync, writeFileSync } from "node:fs";
import { join, resolve } from "node:path";
import { pathToFileURL } from "node:url";

const [moduleDir, specPath, outDir] = process.argv.slice(2);
const mod = (name) => import(pathToFileURL(resolve(moduleDir, `${name}.js`)).href);
const { render, PairRenderer } = await mod("render");
const { compare } = await mod("ledger");
const { DEFAULT_SCENE } = await mod("constants");

function save(prefix, frame) {
  for (const [name, ext] of [["image", "f64"], ["grad", "f64"], ["uv", "f64"], ["chamber", "u8"], ["kink", "u8"]]) {
    writeFileSync(join(outDir, `${prefix}.${name}.${ext}`), Buffer.from(frame[name].buffer, frame[name].byteOffset,
                                                                       frame[name].byteLength));
  }
}

const spec = JSON.parse(readFileSync(specPath, "utf-8"));
const { width, height } = spec;
const pair = new PairRenderer();
for (const step of spec.steps) {
  const scene = { ...DEFAULT_SCENE, ...step.scene }, zoom = step.zoom ?? 1.0, numeric = step.numeric ?? "central";
  const res = pair.update(scene, width, height, zoom, numeric);
  save(`${step.id}.reshade.numeric`, res.numeric);
  save(`${step.id}.reshade.symbolic`, res.symbolic);
  const exact = render(scene, width, height, "exact", zoom);
  save(`${step.id}.render.numeric`, render(scene, width, height, numeric, zoom));
  save(`${step.id}.render.exact`, exact);
  const curves = Object.fromEntries(spec.strides.map((stride) => [stride, pair.ledger_along_eps(spec.curve, stride)]));
  const curve_render = spec.curve.map((eps) => compare(render({ ...scene, eps }, width, height, "central", zoom), exact));
  console.log(JSON.stringify({ id: step.id, full: res.full, shaded: res.shaded, curves, curve_render }));
}
