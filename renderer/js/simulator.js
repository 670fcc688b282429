// The §4 live simulator: controls, three canvases, the ledger and the hover
// readout, wired to the renderer in render.js.  Only this module touches the
// DOM; the renderer core runs the same under node (tests/test_js_parity.py).
import { DEFAULT_SCENE, HEIGHT_FIELDS, MODELS, GRADIENTS, BUMPS, SPHERE_A, CHAMBER_NAMES,
         LOG_FLOOR, LINEAR_GAIN } from "./constants.js";
import { render_pair, probe_pixel } from "./render.js";
import { compare, to_srgb } from "./ledger.js";

// The step of the numeric pipeline as shown on the slider: 10^x rounded to two
// significant digits, so that the value printed is exactly the value used.
export function eps_of(log_eps) {
  return Number(Math.pow(10, log_eps).toPrecision(2));
}

// The numeric pipelines the left canvas can show: every gradient method but the exact one.
const NUMERIC = GRADIENTS.filter((g) => g !== "exact");

// What the left canvas shows, per numeric pipeline.
const NUMERIC_CAPTION = {
  central: "numeric: central differences, step ε",
  footprint: "numeric: central differences, step = the pixel's footprint",
};

const DEFAULT_STATE = {
  numeric: "central", height_field: DEFAULT_SCENE.height_field, k_u: DEFAULT_SCENE.k_u, k_v: DEFAULT_SCENE.k_v,
  beta: DEFAULT_SCENE.beta, bump: DEFAULT_SCENE.bump, log_eps: Math.log10(DEFAULT_SCENE.eps),
  model: DEFAULT_SCENE.model, resolution: 256, view: "shaded", scale: "log", zoom: 1,
  sphere_b: DEFAULT_SCENE.sphere_b,
};

// Grey level in [0, 1] of a difference d >= 0 on the chosen scale: on the log scale log10 d from
// LOG_FLOOR (black) to 0 (white), so that differences from the rounding level of float64 up to a
// whole channel are all visible; on the linear scale d times LINEAR_GAIN (both from renderer/jsgen.py).
export function difference_level(d, scale) {
  if (scale === "log") return d > 0 ? Math.min(1.0, Math.max(0.0, 1.0 - Math.log10(d) / LOG_FLOOR)) : 0.0;
  return Math.min(1.0, LINEAR_GAIN * d);
}

// The controls, in tab order.  kind: select | range | checkbox.
const CONTROLS = [
  { name: "height_field", label: "height field", kind: "select", options: HEIGHT_FIELDS },
  { name: "k_u", label: "k_u", kind: "range", min: 1, max: 24, step: 1 },
  { name: "k_v", label: "k_v", kind: "range", min: 1, max: 24, step: 1 },
  { name: "beta", label: "β (bump amplitude)", kind: "range", min: 0, max: 2, step: 0.01 },
  { name: "bump", label: "bump: the draft's chart formula or the displaced sphere's normal", kind: "select",
    options: BUMPS },
  { name: "numeric", label: "numeric gradient", kind: "select", options: NUMERIC },
  { name: "log_eps", label: "ε (finite-difference step)", kind: "range", min: -14, max: -1, step: 0.1,
    show: (x) => eps_of(x).toExponential(1) },
  { name: "model", label: "shading model", kind: "select", options: MODELS },
  { name: "resolution", label: "resolution", kind: "select", options: [64, 128, 256, 512] },
  { name: "view", label: "view", kind: "select", options: ["shaded", "bump", "kink"] },
  { name: "scale", label: "difference scale", kind: "select", options: ["log", "linear"] },
  { name: "zoom", label: "magnify the pole", kind: "select", options: [1, 2, 4, 8, 16, 32] },
  { name: "sphere_b", label: "sphere B", kind: "checkbox" },
];

// The seed's four "Try this" experiments (§4), applied on top of the defaults.
export const PRESETS = [
  { id: "try1", label: "1 · sine: sweep ε from 1e-1 down", set: { height_field: "sine", log_eps: -1 }, focus: "log_eps" },
  { id: "try2", label: "2 · ridges in the kink view", set: { height_field: "ridges", view: "kink" } },
  { id: "try3", label: "3 · rings, magnify the pole", set: { height_field: "rings", zoom: 8, view: "shaded" } },
  { id: "try4", label: "4 · β to 0", set: { beta: 0 }, focus: "beta" },
];

export function scene_of(state) {
  return { ...DEFAULT_SCENE, height_field: state.height_field, k_u: state.k_u, k_v: state.k_v,
           beta: state.beta, bump: state.bump, eps: eps_of(state.log_eps), model: state.model,
           sphere_b: state.sphere_b };
}

const STYLE = `
.symrender-sim { font-size: 0.9rem; }
.symrender-sim .sim-canvases { display: grid; grid-template-columns: repeat(3, minmax(0, 1fr)); gap: 0.6rem; }
.symrender-sim figure { margin: 0; min-width: 0; }
.symrender-sim canvas { width: 100%; aspect-ratio: 1; image-rendering: pixelated; background: #000; display: block; }
.symrender-sim canvas:focus { outline: 3px solid #4a90d9; }
.symrender-sim figcaption { font-size: 0.8rem; line-height: 1.25; margin-top: 0.25rem; }
.symrender-sim .sim-controls { display: grid; grid-template-columns: repeat(auto-fill, minmax(13rem, 1fr)); gap: 0.4rem 1rem; margin: 0.8rem 0; }
.symrender-sim .sim-controls label { display: flex; flex-direction: column; }
.symrender-sim .sim-controls label.sim-check { flex-direction: row; align-items: center; gap: 0.4rem; }
.symrender-sim output { font-variant-numeric: tabular-nums; }
.symrender-sim .sim-presets { display: flex; flex-wrap: wrap; gap: 0.4rem; margin: 0.4rem 0; }
.symrender-sim .sim-presets button, .symrender-sim .sim-reset { padding: 0.2rem 0.6rem; }
.symrender-sim table { font-variant-numeric: tabular-nums; margin: 0.4rem 0; }
.symrender-sim td, .symrender-sim th { padding: 0.1rem 0.7rem; }
.symrender-sim .sim-readout { font-family: monospace; font-size: 0.8rem; white-space: pre; overflow-x: auto; min-height: 9em; }
`;

function el(tag, attrs = {}, children = []) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === "text") node.textContent = v; else node.setAttribute(k, v);
  }
  for (const child of children) node.append(child);
  return node;
}

function fmt(x, digits = 3) {
  return Number.isFinite(x) ? x.toExponential(digits) : String(x);
}

class Simulator {
  constructor(root) {
    this.root = root;
    this.state = { ...DEFAULT_STATE };
    this.timings = [];
    this.frames = null;
    this.probe = null;
    this.pending = false;
    this.build();
    this.update();
  }

  build() {
    const root = this.root;
    root.replaceChildren();
    if (!document.getElementById("symrender-sim-style")) {
      document.head.append(el("style", { id: "symrender-sim-style", text: STYLE }));
    }
    this.canvases = {};
    const figs = [
      ["numeric", NUMERIC_CAPTION.central],
      ["symbolic", "symbolic: the exact gradient"],
      ["difference", "log₁₀ |ΔI|"],
    ].map(([name, caption]) => {
      const canvas = el("canvas", { id: `sim-canvas-${name}`, tabindex: "0", role: "img",
                                    "aria-label": `${caption} (arrow keys move the probe)` });
      canvas.addEventListener("mousemove", (ev) => this.hover(canvas, ev));
      canvas.addEventListener("keydown", (ev) => this.probe_key(ev));
      this.canvases[name] = canvas;
      return el("figure", {}, [canvas, el("figcaption", { id: `sim-caption-${name}`, text: caption })]);
    });
    root.append(el("div", { class: "sim-canvases" }, figs));

    const presets = PRESETS.map((p) => {
      const b = el("button", { type: "button", id: `sim-preset-${p.id}`, text: p.label });
      b.addEventListener("click", () => this.apply_preset(p));
      return b;
    });
    const reset = el("button", { type: "button", id: "sim-reset", class: "sim-reset", text: "reset" });
    reset.addEventListener("click", () => this.apply_preset({ set: {} }));
    root.append(el("div", { class: "sim-presets", role: "group", "aria-label": "Try this" },
                   [el("span", { text: "Try this:" }), ...presets, reset]));

    this.inputs = {};
    this.outputs = {};
    const controls = CONTROLS.map((c) => {
      let input;
      if (c.kind === "select") {
        input = el("select", { id: `sim-${c.name}` },
                   c.options.map((o) => el("option", { value: String(o), text: String(o) })));
        input.addEventListener("change", () => this.set_from_input(c, input));
        input.addEventListener("input", () => this.set_from_input(c, input));
      } else if (c.kind === "range") {
        input = el("input", { id: `sim-${c.name}`, type: "range", min: c.min, max: c.max, step: c.step });
        input.addEventListener("input", () => this.set_from_input(c, input));
      } else {
        input = el("input", { id: `sim-${c.name}`, type: "checkbox" });
        input.addEventListener("change", () => this.set_from_input(c, input));
      }
      this.inputs[c.name] = input;
      if (c.kind === "checkbox") {
        return el("label", { class: "sim-check" }, [input, el("span", { text: c.label })]);
      }
      if (c.kind === "select") return el("label", {}, [el("span", { text: c.label }), input]);
      const out = el("output", { id: `sim-${c.name}-value`, for: `sim-${c.name}` });
      this.outputs[c.name] = out;
      return el("label", {}, [el("span", {}, [c.label + " ", out]), input]);
    });
    root.append(el("div", { class: "sim-controls" }, controls));

    const cell = (id) => el("td", { id });
    this.ledger = el("table", { class: "sim-ledger", "aria-live": "polite" }, [
      el("thead", {}, [el("tr", {}, ["max |ΔI| on A", "RMS |ΔI| on A", "flips (one shared geometry pass: 0 by construction)",
                                      "pixels on A", "update (both pipelines)"]
        .map((h) => el("th", { text: h })))]),
      el("tbody", {}, [el("tr", {}, ["sim-max", "sim-rms", "sim-flips", "sim-pixels", "sim-time"].map(cell))]),
    ]);
    root.append(this.ledger);
    this.readout = el("div", { id: "sim-readout", class: "sim-readout", "aria-live": "polite",
                               text: "hover over a canvas (or focus one and use the arrow keys) to probe a pixel" });
    root.append(this.readout);
    this.sync_inputs();
  }

  sync_inputs() {
    for (const c of CONTROLS) {
      const input = this.inputs[c.name];
      const value = this.state[c.name];
      if (c.kind === "checkbox") input.checked = value; else input.value = String(value);
      if (this.outputs[c.name]) this.outputs[c.name].textContent = c.show ? c.show(value) : String(value);
    }
  }

  set_from_input(c, input) {
    let value;
    if (c.kind === "checkbox") value = input.checked;
    else if (c.kind === "range" || typeof c.options[0] === "number") value = Number(input.value);
    else value = input.value;
    this.state[c.name] = value;
    if (this.outputs[c.name]) this.outputs[c.name].textContent = c.show ? c.show(value) : String(value);
    this.schedule();
  }

  apply_preset(p) {
    this.state = { ...DEFAULT_STATE, ...p.set };
    this.sync_inputs();
    this.update();
    if (p.focus) this.inputs[p.focus].focus();
  }

  schedule() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => { this.pending = false; this.update(); });
  }

  update() {
    const s = this.state;
    const scene = scene_of(s);
    const t0 = performance.now();
    // One pass for both pipelines: the geometry is shared (bump moves no boundary).
    const { numeric, symbolic } = render_pair(scene, s.resolution, s.resolution, s.zoom, s.numeric);
    const ledger = compare(numeric, symbolic);
    this.draw(numeric, symbolic);
    const ms = performance.now() - t0;
    this.timings.push({ resolution: s.resolution, ms });
    this.frames = { scene, numeric, symbolic, ledger, ms };
    const put = (id, text, value) => {
      const td = this.root.querySelector(`#${id}`);
      td.textContent = text;
      td.dataset.value = String(value);
    };
    put("sim-max", fmt(ledger.max_abs), ledger.max_abs);
    put("sim-rms", fmt(ledger.rms), ledger.rms);
    put("sim-flips", String(ledger.flips), ledger.flips);
    put("sim-pixels", String(ledger.pixels_a), ledger.pixels_a);
    put("sim-time", `${ms.toFixed(1)} ms`, ms);
    this.root.dataset.updates = String(this.timings.length);
    if (this.probe) this.show_probe(this.probe.i, this.probe.j);
  }

  draw(numeric, symbolic) {
    const view = this.state.view, scale = this.state.scale;
    const n = numeric.chamber.length;
    const w = numeric.width, h = numeric.height;
    let gmax = 0.0;
    if (view === "bump") {
      for (let k = 0; k < n; k++) {
        if (symbolic.chamber[k] === SPHERE_A) gmax = Math.max(gmax, Math.hypot(symbolic.grad[2 * k], symbolic.grad[2 * k + 1]));
      }
    }
    const gnorm = (f, k) => Math.hypot(f.grad[2 * k], f.grad[2 * k + 1]) / (gmax || 1.0);
    for (const name of ["numeric", "symbolic", "difference"]) {
      const canvas = this.canvases[name];
      canvas.width = w; canvas.height = h;
      const ctx = canvas.getContext("2d");
      const img = ctx.createImageData(w, h);
      const px = img.data;
      const frame = name === "numeric" ? numeric : symbolic;
      for (let k = 0; k < n; k++) {
        let r, g, b;
        if (name !== "difference") {
          if (view === "bump") {
            const on_a = frame.chamber[k] === SPHERE_A;
            r = g = b = on_a ? to_srgb(gnorm(frame, k)) : 0.0;
          } else {
            r = to_srgb(frame.image[3 * k]); g = to_srgb(frame.image[3 * k + 1]); b = to_srgb(frame.image[3 * k + 2]);
            if (view === "kink") {
              if (symbolic.kink[k]) { r = g = b = 1.0; } else { r *= 0.4; g *= 0.4; b *= 0.4; }
            }
          }
        } else if (view === "bump") {
          const both = numeric.chamber[k] === SPHERE_A && symbolic.chamber[k] === SPHERE_A;
          r = g = b = both ? difference_level(Math.abs(gnorm(numeric, k) - gnorm(symbolic, k)), scale) : 0.0;
        } else if (scale === "log") {     // one grey level: the largest channel difference
          r = g = b = difference_level(Math.max(Math.abs(numeric.image[3 * k] - symbolic.image[3 * k]),
                                                Math.abs(numeric.image[3 * k + 1] - symbolic.image[3 * k + 1]),
                                                Math.abs(numeric.image[3 * k + 2] - symbolic.image[3 * k + 2])), scale);
          if (view === "kink" && symbolic.kink[k]) { r *= 0.6; g *= 0.6; b = Math.max(b, 0.35); }
        } else {
          r = difference_level(Math.abs(numeric.image[3 * k] - symbolic.image[3 * k]), scale);
          g = difference_level(Math.abs(numeric.image[3 * k + 1] - symbolic.image[3 * k + 1]), scale);
          b = difference_level(Math.abs(numeric.image[3 * k + 2] - symbolic.image[3 * k + 2]), scale);
          if (view === "kink" && symbolic.kink[k]) b = Math.max(b, 0.35);
        }
        px[4 * k] = Math.round(255 * r); px[4 * k + 1] = Math.round(255 * g);
        px[4 * k + 2] = Math.round(255 * b); px[4 * k + 3] = 255;
      }
      ctx.putImageData(img, 0, 0);
    }
    const pipe = this.state.numeric;
    const diff = scale === "log" ? `log₁₀ |Δ| from ${LOG_FLOOR} (black) to 0 (white)` : `|Δ| × ${LINEAR_GAIN}`;
    const cap = { shaded: [NUMERIC_CAPTION[pipe] ?? `numeric: ${pipe}`, "symbolic: the exact gradient", `|ΔI|: ${diff}`],
                  bump: [`bump view: |∇h|, numeric (${pipe})`, "bump view: |∇h|, exact", `|Δ|∇h|| relative to its max: ${diff}`],
                  kink: [`kink view: crease band (white), numeric (${pipe})`, "kink view: crease band (white), exact", `|ΔI|: ${diff}; band in blue`] }[view];
    ["numeric", "symbolic", "difference"].forEach((name, i) => {
      this.root.querySelector(`#sim-caption-${name}`).textContent = cap[i];
    });
  }

  hover(canvas, ev) {
    const rect = canvas.getBoundingClientRect();
    const res = this.state.resolution;
    const i = Math.min(res - 1, Math.max(0, Math.floor((ev.clientX - rect.left) * res / rect.width)));
    const j = Math.min(res - 1, Math.max(0, Math.floor((ev.clientY - rect.top) * res / rect.height)));
    this.show_probe(i, j);
  }

  probe_key(ev) {
    const moves = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] };
    if (!(ev.key in moves)) return;
    ev.preventDefault();
    const res = this.state.resolution;
    const p = this.probe || { i: res >> 1, j: res >> 1 };
    const [di, dj] = moves[ev.key];
    this.show_probe(Math.min(res - 1, Math.max(0, p.i + di)), Math.min(res - 1, Math.max(0, p.j + dj)));
  }

  show_probe(i, j) {
    const s = this.state;
    const res = s.resolution;
    if (i >= res || j >= res) { i = res >> 1; j = res >> 1; }
    this.probe = { i, j };
    const pr = probe_pixel(this.frames.scene, res, res, i, j, s.zoom, s.numeric);
    const a = pr.symbolic, b = pr.numeric;
    const vec = (v) => v ? "(" + v.map((x) => x.toPrecision(10)).join(", ") + ")" : "—";
    const lines = [
      `pixel (column ${i}, row ${j})  ray through (${pr.X.toPrecision(8)}, ${pr.Y.toPrecision(8)}, 0)`,
      `object        ${CHAMBER_NAMES[a.chamber]}`,
      `world point   ${vec(a.P)}`,
    ];
    if (a.chamber === SPHERE_A) {
      lines.push(`(u, v)        ${vec(a.uv)}`);
      lines.push(`∇h exact      ${vec(a.grad)}`);
      const steps = b.steps[0] === b.steps[1] ? `ε = ${b.steps[0].toExponential(1)}`
        : `ε_u = ${b.steps[0].toExponential(2)}, ε_v = ${b.steps[1].toExponential(2)}`;
      lines.push(`${("∇h " + b.gradient).padEnd(14)}${vec(b.grad)}   (${steps})`);
      lines.push(`kink band     ${a.kink ? "yes: the gradient is undefined on the crease" : "no"}`);
    }
    lines.push(`RGB symbolic  ${vec(a.rgb)}`);
    lines.push(`RGB numeric   ${vec(b.rgb)}`);
    this.readout.textContent = lines.join("\n");
    const d = this.readout.dataset;
    d.i = String(i); d.j = String(j); d.chamber = String(a.chamber);
    d.u = a.uv ? String(a.uv[0]) : ""; d.v = a.uv ? String(a.uv[1]) : "";
  }
}

export function start(root) {
  const sim = new Simulator(root);
  root.symrender = sim;
  return sim;
}

if (typeof document !== "undefined") {
  const boot = () => document.querySelectorAll("[data-symrender-sim]").forEach((root) => start(root));
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", boot); else boot();
}
