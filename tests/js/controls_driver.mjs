// Controls driver: every position of every control of the simulator, as the scene it renders.
//   node controls_driver.mjs MODULE_DIR
// Prints one JSON object: { default: scene_of(DEFAULT_STATE), positions: [{ control, value, scene }],
// presets: [{ id, scene }] }: for a select each option, for a range its ends, its default and each
// tick (the decades of log eps) and, on an integer slider of at most 100 steps (the frequencies), every value,
// for the checkbox both states, each applied alone to the default state;
// the presets, and each shading normal with β at the top of its slider.
import { resolve } from "node:path";
import { pathToFileURL } from "node:url";

const [moduleDir] = process.argv.slice(2);
const sim = await import(pathToFileURL(resolve(moduleDir, "simulator.js")).href);
const { CONTROLS, DEFAULT_STATE, PRESETS, scene_of, beta_max } = sim;

// The β slider's top depends on the shading normal (the displaced sphere's needs β below R).
const top = (c, state) => (c.name === "beta" ? beta_max(state.bump) : c.max);
function values(c) {
  if (c.kind === "select") return c.options;
  if (c.kind === "checkbox") return [true, false];
  const out = new Set([c.min, top(c, DEFAULT_STATE), DEFAULT_STATE[c.name]]);
  if (c.ticks) for (let x = Math.ceil(c.min); x <= c.max; x += c.ticks) out.add(x);
  if (Number.isInteger(c.min) && Number.isInteger(c.step) && (c.max - c.min) / c.step <= 100)
    for (let x = c.min; x <= c.max; x += c.step) out.add(x);
  return [...out];
}
const positions = [];
for (const c of CONTROLS) {
  for (const value of values(c)) {
    positions.push({ control: c.name, value, scene: scene_of({ ...DEFAULT_STATE, [c.name]: value }) });
  }
}
const presets = PRESETS.map((p) => ({ id: p.id, scene: scene_of({ ...DEFAULT_STATE, ...p.set }) }));
// Each shading normal with β at the top of its slider (a scene Python must accept too).
for (const bump of CONTROLS.find((c) => c.name === "bump").options) {
  const state = { ...DEFAULT_STATE, bump, beta: beta_max(bump) };
  presets.push({ id: `beta-top-${bump}`, scene: scene_of(state) });
}
console.log(JSON.stringify({ default: scene_of(DEFAULT_STATE), positions, presets }));
