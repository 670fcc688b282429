// The §4 live simulator: presets, three canvases, the U-curve plot, the pixel
// readout, the controls and the ledger, wired to the renderer in render.js.
// Only this module touches the DOM; the renderer core runs the same under node
// (tests/test_js_parity.py, tests/test_js_reshade.py).
import { SIMULATOR_SCENE, HEIGHT_FIELDS, FIELD_CREASES, MODELS, GRADIENTS, BUMPS, SPHERE_A, CHAMBER_NAMES,
         LOG_FLOOR, LINEAR_GAIN, SLIDER_LOG_EPS, CURVE_LOG_EPS } from "./constants.js";
import { PairRenderer, probe_pixel } from "./render.js";
import { compare, to_srgb } from "./ledger.js";

// The step of the numeric pipeline as shown on the slider: 10^x rounded to two
// significant digits, so that the value printed is exactly the value used.
export function eps_of(log_eps) {
  return Number(Math.pow(10, log_eps).toPrecision(2));
}

// The numeric pipelines the left canvas can show: every gradient method but the exact one.
const NUMERIC = GRADIENTS.filter((g) => g !== "exact");

// The slider of log10 eps, and the steps of the U-curve (CURVE_LOG_EPS, from
// renderer/ledger.py): the slider's range in half decades, fine enough to show the bottom of the U and its two
// slopes, coarse enough to stay cheap (see CURVE_SAMPLE).  The slider moves by a
// tenth of a decade (an arrow key), so that it lands exactly on each decade; each
// decade is a tick mark (a <datalist>), to which Chromium snaps a pointer within a
// few pixels (a tenth of a decade is under 3 px on a phone), and Page Up / Page Down
// jump to the next decade.
const LOG_EPS = { min: SLIDER_LOG_EPS[0], max: SLIDER_LOG_EPS[1], step: 0.1, ticks: 1 };
// The U-curve is the ledger of every pixel of sphere A at each step.  A change of beta, bump or field
// draws it first within its update from a grid of at most CURVE_SAMPLE x CURVE_SAMPLE of the frame's
// pixels (every 6th column and row at 256 x 256, a 36th of sphere A: its steps cost less than
// re-shading sphere A once), then over every pixel a step at a time, between updates (`refine`; all
// the steps about 0.2 s at 256 x 256 on a desktop).  The sample alone misses most of the few pixels
// whose stencils straddle a crease, and its curve then fell far below the ledger's RMS.
export const CURVE_SAMPLE = 48;
export function curve_stride(resolution) {
  return Math.max(1, Math.ceil(resolution / CURVE_SAMPLE));
}

// The β slider: up to 2 for the chart formula; below R for the displaced sphere
// (scene.py: R + β h must stay positive), on the slider's grid of 0.01.
const BETA = { min: 0, max: 2, step: 0.01 };
export const beta_max = (bump) => bump === "surface" ? Math.round(100 * (SIMULATOR_SCENE.radius_a - BETA.step)) / 100 : BETA.max;
// What the hint says when a change of the shading normal changes the β slider's range.
export const beta_range_note = (bump, lowered) => `β now runs to ${beta_max(bump)}: ` + (bump === "surface"
  ? `the displaced sphere's radius R + βh must stay positive${lowered ? ", so β was lowered to it" : ""}.`
  : "the draft's chart formula puts no bound on β.");

export const DEFAULT_STATE = {
  numeric: "central", height_field: SIMULATOR_SCENE.height_field, k_u: SIMULATOR_SCENE.k_u,
  k_v: SIMULATOR_SCENE.k_v, beta: SIMULATOR_SCENE.beta, bump: SIMULATOR_SCENE.bump,
  log_eps: Math.log10(SIMULATOR_SCENE.eps), model: SIMULATOR_SCENE.model, resolution: 256, view: "shaded",
  scale: "log", zoom: 1, sphere_b: SIMULATOR_SCENE.sphere_b,
};

// Grey level in [0, 1] of a difference d >= 0 on the chosen scale: on the log scale log10 d from
// LOG_FLOOR (black) to 0 (white), so that differences from the rounding level of float64 up to a
// whole channel are all visible; on the linear scale d times LINEAR_GAIN (both from renderer/jsgen.py).
export function difference_level(d, scale) {
  if (scale === "log") return d > 0 ? Math.min(1.0, Math.max(0.0, 1.0 - Math.log10(d) / LOG_FLOOR)) : 0.0;
  return Math.min(1.0, LINEAR_GAIN * d);
}

// The 8-bit sRGB value of a linear channel in [0, 1], Math.round(255 to_srgb(x)) to
// within one level (from a table at steps of 1/4096): it halves the time of drawing
// the canvases, whose pow per channel it replaces (tests/js/bench_update.py).
const SRGB_TABLE = Uint8Array.from({ length: 4097 }, (_, i) => Math.round(255 * to_srgb(i / 4096)));
const srgb_byte = (x) => SRGB_TABLE[Math.round(4096 * Math.min(Math.max(x, 0.0), 1.0))];

const SUP = { "-": "⁻", 0: "⁰", 1: "¹", 2: "²", 3: "³", 4: "⁴", 5: "⁵", 6: "⁶", 7: "⁷", 8: "⁸", 9: "⁹" };
const power_of_ten = (e) => "10" + String(e).split("").map((c) => SUP[c]).join("");
const LOG_SCALE = `log: ${power_of_ten(LOG_FLOOR)} black, 1 white`;
const LINEAR_SCALE = `linear: |ΔI| × ${LINEAR_GAIN}`;

// The controls, in tab order.  kind: select | range | checkbox; `labels` names a select's options.
export const CONTROLS = [
  { name: "height_field", label: "height field", kind: "select", options: HEIGHT_FIELDS },
  { name: "log_eps", label: "ε, the finite-difference step", kind: "range", ...LOG_EPS,
    show: (x) => eps_of(x).toExponential(1) },
  { name: "beta", label: "β, the bump's amplitude", kind: "range", ...BETA, show: (x) => x.toFixed(2) },
  { name: "bump", label: "shading normal", kind: "select", options: BUMPS,
    labels: { surface: "the displaced sphere's", chart: "the draft's chart formula" } },
  { name: "view", label: "view", kind: "select", options: ["shaded", "bump", "kink"],
    labels: { shaded: "shaded", bump: "bump: size of ∇h", kink: "kink: the crease band" } },
  { name: "scale", label: "difference scale", kind: "select", options: ["log", "linear"],
    labels: { log: LOG_SCALE, linear: LINEAR_SCALE } },
  { name: "numeric", label: "numeric gradient", kind: "select", options: NUMERIC,
    labels: { central: "central, one step ε", footprint: "central, pixel footprint" } },
  // Even only: an odd kᵤ creases sine along the seam u = 0 ≡ 1, where h_u changes sign (§2 calls sine smooth).
  { name: "k_u", label: "kᵤ, frequency in u (even)", kind: "range", min: 2, max: 24, step: 2 },
  { name: "k_v", label: "kᵥ, frequency in v", kind: "range", min: 1, max: 24, step: 1 },
  { name: "model", label: "shading model", kind: "select", options: MODELS },
  { name: "resolution", label: "resolution", kind: "select", options: [64, 128, 256, 512],
    labels: { 64: "64 × 64", 128: "128 × 128", 256: "256 × 256", 512: "512 × 512" } },
  { name: "zoom", label: "magnify the pole", kind: "select", options: [1, 2, 4, 8, 16, 32],
    labels: { 1: "×1", 2: "×2", 4: "×4", 8: "×8", 16: "×16", 32: "×32" } },
  { name: "sphere_b", label: "sphere B", kind: "checkbox" },
];

// What the right arm of the U-curve (the larger steps) is made of, for a smooth height field
// and for one with creases (FIELD_CREASES); the left arm is rounding on every field.  Shown in
// the curve's caption.
export const RIGHT_ARM = {
  smooth: "Right arm: truncation error, which shrinks as ε² when ε shrinks; left arm: rounding, which grows as 1/ε.",
  creased: "Right arm: crease error — at the pixels within ε of a crease the stencil straddles it and the " +
          "quotient is off by the slope's jump times the share of the stencil past the crease; it shrinks only " +
          "as fewer pixels lie that near, slower than " +
          "truncation. Left arm: rounding, which grows as 1/ε.",
};

// The draft's four "Try this" experiments (§4), applied on top of the defaults,
// each opening on the view and scale that show its point; `hint` says what to look at.
export const PRESETS = [
  { id: "try1", label: "1 · sine: sweep ε down", set: { height_field: "sine", log_eps: LOG_EPS.max, scale: "log" },
    focus: "log_eps",
    hint: "On the log scale, move ε down with the slider (or the arrow keys): the difference darkens along the truncation " +
          "slope, bottoms out, then brightens as rounding takes over. The dot rides the U-curve; " +
          "the symbolic canvas never changes." },
  { id: "try2", label: "2 · ridges: where the pipelines part", set: { height_field: "ridges", view: "kink", scale: "linear" },
    hint: "Kink view, linear difference scale: the crease band is white on the renders and blue on the " +
          "difference, where the large differences sit: central differences straddle the crease." },
  { id: "try3", label: "3 · rings: magnify the pole", set: { height_field: "rings", zoom: 4, view: "shaded", bump: "chart" },
    hint: "The pole, magnified: the rings circle it, and the shading flips from one side of it to the other " +
          "with either normal: the bumped sphere comes to a cone's point. It opens on the draft's formula, whose β " +
          `slider runs to ${beta_max("chart")} (the displaced sphere's stops below R, as its radius R + βh must stay ` +
          "positive); the shading-normal control swaps them." },
  { id: "try4", label: "4 · β to 0", set: { beta: 0 }, focus: "beta",
    hint: "With β = 0 both renders are the un-bumped sphere: the difference is black, the ledger reads " +
          "zero and the U-curve lies on its floor. Move β up to bring the bump back." },
];

const HINT = "Hover over a canvas, tap it, or focus it and use the arrow keys (Shift: ten pixels; B, Shift+B: the next, " +
  "the previous pixel in the crease band), to read that pixel in the readout; " +
  "on the ε slider, Page Up and Page Down move a whole decade.";
// The controls shown above the canvases.
const MAIN = ["height_field", "log_eps", "beta"];

export function scene_of(state) {
  return { ...SIMULATOR_SCENE, height_field: state.height_field, k_u: state.k_u, k_v: state.k_v,
           beta: state.beta, bump: state.bump, eps: eps_of(state.log_eps), model: state.model,
           sphere_b: state.sphere_b };
}

const STYLE = `
.symrender-sim { font-size: 0.9rem; }
.symrender-sim .sim-stage { display: grid; grid-template-columns: repeat(3, minmax(0, 1fr)); gap: 0.6rem; }
.symrender-sim figure { margin: 0; min-width: 0; }
.symrender-sim canvas { width: 100%; aspect-ratio: 1; image-rendering: pixelated; background: #000; display: block;
  touch-action: manipulation; }
.symrender-sim canvas:focus { outline: 3px solid #4a90d9; }
/* The read-out pixel, ringed on each canvas (over it: the canvases' pixels stay the renderer's). */
.symrender-sim .sim-canvas-box { position: relative; }
.symrender-sim .sim-probe { position: absolute; box-sizing: border-box; width: 13px; height: 13px; margin: -6.5px 0 0 -6.5px;
  border: 2px solid #fff; border-radius: 50%; box-shadow: 0 0 0 1px #000, inset 0 0 0 1px #000; pointer-events: none; }
.symrender-sim figcaption { font-size: 0.8rem; line-height: 1.25; margin-top: 0.25rem; }
.symrender-sim .sim-curve { grid-column: 1 / span 2; grid-row: 2; }
.symrender-sim .sim-curve svg { width: 100%; height: 13rem; display: block; overflow: visible; }
.symrender-sim .sim-curve text { fill: currentColor; font-size: 11px; }
.symrender-sim .sim-curve-values summary { min-height: 1.75rem; cursor: pointer; }
.symrender-sim .sim-curve-values caption { caption-side: top; text-align: left; font-size: 0.8rem; }
.symrender-sim .sim-readout-box { grid-column: 3; grid-row: 2; min-width: 0; background: var(--pst-color-background, #fff); }
.symrender-sim .sim-more { display: none; }
.symrender-sim .sim-readout { font-size: 0.75rem; line-height: 1.3;
  display: grid; grid-template-columns: fit-content(40%) minmax(0, 1fr); gap: 0.1rem 0.5rem; align-content: start;
  font-variant-numeric: tabular-nums; }
/* No margin: the theme gives a classed <dl> 3rem below it, by a selector that outranks the rule above (on a phone
   it parted the readout from the U-curve). */
.symrender-sim .sim-stage dl.sim-readout { margin: 0; }
.symrender-sim .sim-readout dt { font-weight: 600; }
.symrender-sim .sim-readout dd { margin: 0; overflow-wrap: break-word; min-width: 0; }
.symrender-sim .sim-controls { display: grid; grid-template-columns: repeat(auto-fill, minmax(13rem, 1fr)); gap: 0.4rem 1rem; margin: 0.8rem 0; }
.symrender-sim .sim-controls label { display: flex; flex-direction: column; }
.symrender-sim .sim-controls label.sim-check { flex-direction: row; align-items: center; gap: 0.4rem; }
/* Every control a target of at least 24 x 24 CSS px (WCAG 2.2, 2.5.8): the browser's are 13-20 px tall. */
.symrender-sim input[type="range"] { height: 1.75rem; margin: 0; }
.symrender-sim select { min-height: 1.75rem; }
.symrender-sim input[type="checkbox"] { width: 1.5rem; height: 1.5rem; margin: 0; }
.symrender-sim button { min-height: 1.75rem; min-width: 1.75rem; }
.symrender-sim output { font-variant-numeric: tabular-nums; }
.symrender-sim .sim-presets { display: flex; flex-wrap: wrap; gap: 0.4rem; margin: 0.4rem 0; align-items: center; }
.symrender-sim .sim-presets button, .symrender-sim .sim-reset { padding: 0.2rem 0.6rem; }
.symrender-sim .sim-hint { min-height: 2.6em; margin: 0 0 0.4rem; font-style: italic; }
.symrender-sim .sim-note { grid-column: 1 / -1; margin: 0; font-style: italic; }
/* Empty, out of sight but not out of the accessibility tree: a live region shown only once it has text is often not read. */
.symrender-sim .sim-note:empty { position: absolute; width: 1px; height: 1px; overflow: hidden; clip-path: inset(50%); }
.symrender-sim .sim-status { position: absolute; width: 1px; height: 1px; overflow: hidden; clip-path: inset(50%); white-space: nowrap; }
.symrender-sim table { font-variant-numeric: tabular-nums; margin: 0.4rem 0; }
.symrender-sim td, .symrender-sim th { padding: 0.1rem 0.7rem; }
.symrender-sim .sim-main { grid-template-columns: repeat(3, minmax(0, 1fr)); margin: 0.4rem 0; }
/* On a phone: one column; the main controls stick just below the theme's sticky header (3.5rem high
   below 768 px, sphinx-book-theme), the readout to the bottom of the screen while the canvases scroll
   by.  The readout comes before the U-curve: a box sticking to the bottom covers only what precedes
   it, so the canvases and never the plot or its caption; it scrolls on under the controls. */
@media (max-width: 720px) {
  .symrender-sim .sim-main { grid-template-columns: minmax(0, 1fr); position: sticky; top: 3.5rem;
    z-index: 3; /* above the readout */ background: var(--pst-color-background, #fff); padding: 0.2rem 0;
    gap: 0 1rem; font-size: 0.9rem; }
  /* The field's menu beside its name: with the theme's header, the panel covers under a quarter of a phone's screen. */
  .symrender-sim .sim-main label:has(select) { flex-direction: row; align-items: center; gap: 0.5rem; }
  .symrender-sim .sim-main label:has(select) select { flex: 1; min-width: 0; }
  .symrender-sim .sim-stage { grid-template-columns: minmax(0, 1fr); }
  .symrender-sim .sim-curve, .symrender-sim .sim-readout-box { grid-column: 1; grid-row: auto; }
  /* The plot a little lower, so that the difference canvas, the readout and the plot fit under the controls at once. */
  .symrender-sim .sim-curve svg { height: 12rem; }
  .symrender-sim .sim-readout-box { position: sticky; bottom: 0; z-index: 2; padding: 0.3rem 0.4rem;
    border-top: 1px solid currentColor; max-height: 40vh; overflow-y: auto; display: flex; align-items: start; gap: 0.5rem; }
  .symrender-sim .sim-readout { flex: 1; }
  /* A pixel read out shows two rows, which pixel and its |ΔI|, until the reader asks for all: all ten pushed the
     U-curve off the screen. */
  .symrender-sim .sim-readout[data-i] + .sim-more { display: block; padding: 0 0.5rem; }
  .symrender-sim .sim-readout-box:has(.sim-more[aria-expanded="false"]) .sim-readout > :not(.sim-brief) { display: none; }
  /* All rows: the button on a line of its own above them, which then take the box's width. */
  .symrender-sim .sim-readout-box:has(.sim-more[aria-expanded="true"]) { flex-wrap: wrap; justify-content: end; }
  .symrender-sim .sim-readout-box:has(.sim-more[aria-expanded="true"]) .sim-readout { flex-basis: 100%; order: 1; }
}
`;

function el(tag, attrs = {}, children = []) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === "text") node.textContent = v; else node.setAttribute(k, v);
  }
  for (const child of children) node.append(child);
  return node;
}

// SVG markup of one element (the plot's text is ours: nothing to escape but <, &).
function svg(tag, attrs = {}, text = null) {
  const a = Object.entries(attrs).map(([k, v]) => ` ${k}="${v}"`).join("");
  return text === null ? `<${tag}${a}/>` : `<${tag}${a}>${String(text).replace(/&/g, "&amp;").replace(/</g, "&lt;")}</${tag}>`;
}

function fmt(x, digits = 3) {
  return Number.isFinite(x) ? x.toExponential(digits) : String(x);
}

// The U-curve plot's axes: log10 eps over the slider's range, log10 |ΔI| from
// CURVE_FLOOR (where an exact zero is drawn) to 0.
const CURVE_FLOOR = LOG_FLOOR - 1;
// The crease band on the difference canvas of the kink view: a sky blue at least (green, blue), its red
// channel left to the difference; against the black of no difference, 6.8:1 (a darker blue was near-invisible).
const BAND_GREEN = 150, BAND_BLUE = 255;
const CURVE_COLOURS = { rms: "#2f7ed8", max: "#e8590c" };

class Simulator {
  constructor(root) {
    this.root = root;
    this.state = { ...DEFAULT_STATE };
    this.renderer = new PairRenderer();
    this.timings = [];
    this.frames = null;
    this.curve = null;
    this.curve_generation = 0;
    this.probe = null;
    this.pending = false;
    this.drawn = null;
    this.build();
    this.update();
  }

  build() {
    const root = this.root;
    root.replaceChildren();
    root.classList.add("symrender-sim");
    if (!document.getElementById("symrender-sim-style")) {
      document.head.append(el("style", { id: "symrender-sim-style", text: STYLE }));
    }
    const presets = PRESETS.map((p) => {
      const b = el("button", { type: "button", id: `sim-preset-${p.id}`, text: p.label });
      b.addEventListener("click", () => this.apply_preset(p));
      return b;
    });
    const reset = el("button", { type: "button", id: "sim-reset", class: "sim-reset", text: "reset" });
    reset.addEventListener("click", () => this.apply_preset({ set: {} }));
    root.append(el("div", { class: "sim-presets", role: "group", "aria-label": "Try this" },
                   [el("span", { text: "Try this:" }), ...presets, reset]));
    this.hint = el("p", { id: "sim-hint", class: "sim-hint", "aria-live": "polite", text: HINT });
    root.append(this.hint);
    // The step, the amplitude and the field sit just above the canvases (sticky on a phone), so the
    // reader sees the images move while dragging them; the other controls follow the ledger.
    this.main_controls = el("div", { class: "sim-controls sim-main" });
    root.append(this.main_controls);

    this.canvases = {};
    this.marks = [];
    const figs = ["numeric", "symbolic", "difference"].map((name) => {
      // An application, not an image: a screen reader in browse mode passes the arrow keys only to an
      // application; its role description still calls it an image.
      const canvas = el("canvas", { id: `sim-canvas-${name}`, tabindex: "0", role: "application",
                                    "aria-roledescription": "image with a probe",
                                    "aria-label": `${name} canvas (arrow keys move the probe)` });
      canvas.addEventListener("pointermove", (ev) => { if (ev.pointerType === "mouse") this.pointer(canvas, ev); });
      canvas.addEventListener("pointerdown", (ev) => this.pointer(canvas, ev));
      canvas.addEventListener("keydown", (ev) => this.probe_key(ev));
      this.canvases[name] = canvas;
      const mark = el("span", { class: "sim-probe", "aria-hidden": "true", hidden: "" });
      this.marks.push(mark);
      // Named in a few words (Chromium names a <figure> by nothing): its caption, read after them, is long.
      const figure_name = name === "difference" ? "the difference" : `the ${name} render`;
      return el("figure", { "aria-label": figure_name }, [el("div", { class: "sim-canvas-box" }, [canvas, mark]),
                                                          el("figcaption", { id: `sim-caption-${name}` })]);
    });
    // An inline <svg>, parsed from markup (no namespace address in the script).
    const holder = el("div");
    holder.innerHTML = svg("svg", { id: "sim-curve", role: "img" });
    this.plot = holder.firstChild;
    // The curve's numbers as a table, folded under the plot: what a screen reader (or anyone) reads of it.
    this.curve_rows = el("tbody", { id: "sim-curve-rows" });
    const values = el("details", { class: "sim-curve-values" }, [el("summary", { text: "The curve's values" }),
      el("table", { class: "sim-curve-table" }, [el("caption", { id: "sim-curve-table-caption" }),
                       el("thead", {}, [el("tr", {}, ["ε", "RMS |ΔI|", "max |ΔI|"].map((h) => el("th", { scope: "col", text: h })))]),
                       this.curve_rows])]);
    const curve = el("figure", { class: "sim-curve", "aria-label": "the U-curve" },
                     [this.plot, el("figcaption", { id: "sim-curve-caption" }), values]);
    this.readout = el("dl", { id: "sim-readout", class: "sim-readout" });
    // Shown on a phone only (STYLE), once a pixel is read out.
    const more = el("button", { type: "button", id: "sim-more", class: "sim-more", "aria-controls": "sim-readout",
                                "aria-expanded": "false", text: "all rows" });
    more.addEventListener("click", () => {
      const open = more.getAttribute("aria-expanded") === "false";
      more.setAttribute("aria-expanded", String(open));
      more.textContent = open ? "fewer rows" : "all rows";
    });
    // The readout right after the canvases it reads, in reading order; the grid puts it beside the U-curve.
    root.append(el("div", { class: "sim-stage" }, [...figs, el("div", { class: "sim-readout-box" }, [this.readout, more]), curve]));
    this.show_readout([["pixel", "hover over a canvas, tap it, or focus it and use the arrow keys", true]]);
    this.readout.setAttribute("aria-label", "the pixel readout");
    if (typeof ResizeObserver !== "undefined") new ResizeObserver(() => this.draw_curve()).observe(this.plot);

    const cell = (id) => el("td", { id });
    // Not a live region (a screen reader would read its changed cells without their headers): the status
    // below says what a change did, in one sentence.
    this.ledger = el("table", { class: "sim-ledger", "aria-label": "the ledger of the two renders" }, [
      el("thead", {}, [el("tr", {}, ["max |ΔI| on A", "RMS |ΔI| on A", "flips", "pixels on A", "last update"]
        .map((h) => el("th", { text: h })))]),
      el("tbody", {}, [el("tr", {}, ["sim-max", "sim-rms", "sim-flips", "sim-pixels", "sim-time"].map(cell))]),
    ]);
    root.append(this.ledger);
    this.status = el("p", { id: "sim-status", class: "sim-status", role: "status" });
    root.append(this.status);

    this.inputs = {};
    this.outputs = {};
    const controls = CONTROLS.map((c) => {
      let input, ticks = [];
      if (c.kind === "select") {
        input = el("select", { id: `sim-${c.name}` },
                   c.options.map((o) => el("option", { value: String(o), text: c.labels?.[o] ?? String(o) })));
        input.addEventListener("change", () => this.set_from_input(c, input));
        input.addEventListener("input", () => this.set_from_input(c, input));
      } else if (c.kind === "range") {
        input = el("input", { id: `sim-${c.name}`, type: "range", min: c.min, max: c.max, step: c.step });
        input.addEventListener("input", () => this.set_from_input(c, input));
        if (c.ticks) {
          ticks = [el("datalist", { id: `sim-${c.name}-ticks` }, Array.from(
            { length: Math.floor((c.max - c.min) / c.ticks) + 1 }, (_, k) => el("option", { value: String(c.min + k * c.ticks) })))];
          input.setAttribute("list", ticks[0].id);
          input.addEventListener("keydown", (ev) => this.tick_key(c, input, ev));
        }
      } else {
        input = el("input", { id: `sim-${c.name}`, type: "checkbox" });
        input.addEventListener("change", () => this.set_from_input(c, input));
      }
      this.inputs[c.name] = input;
      if (c.kind === "checkbox") {
        return el("label", { class: "sim-check" }, [input, el("span", { text: c.label })]);
      }
      if (c.kind === "select") return el("label", {}, [el("span", { text: c.label }), input]);
      // Hidden from a screen reader, which hears the value from the slider itself (an <output> is a live
      // region: it would say each value twice).
      const out = el("output", { id: `sim-${c.name}-value`, for: `sim-${c.name}`, "aria-hidden": "true" });
      this.outputs[c.name] = out;
      // `for`: the label's first labelable descendant is the <output>, which it would name instead.
      return el("label", { for: input.id }, [el("span", {}, [c.label + " ", out]), input, ...ticks]);
    });
    const main = CONTROLS.map((c, i) => MAIN.includes(c.name) ? controls[i] : null).filter(Boolean);
    this.main_controls.append(...main);
    // What a change of the shading normal did to β's range, said beside the menu that made it.
    this.note = el("p", { id: "sim-note", class: "sim-note", "aria-live": "polite" });
    const rest = controls.filter((c) => !main.includes(c));
    const at = rest.indexOf(controls[CONTROLS.findIndex((c) => c.name === "bump")]) + 1;
    root.append(el("div", { class: "sim-controls" }, [...rest.slice(0, at), this.note, ...rest.slice(at)]));
    this.sync_inputs();
  }

  // Page Up / Page Down on a slider with tick marks: to the next tick above or below (the ε slider: the
  // next decade), as a reader's drag would (an input event).
  tick_key(c, input, ev) {
    if (ev.key !== "PageUp" && ev.key !== "PageDown") return;
    ev.preventDefault();
    const x = Number(input.value) / c.ticks, up = ev.key === "PageUp";
    const k = up ? Math.floor(x + 1e-9) + 1 : Math.ceil(x - 1e-9) - 1;
    input.value = String(Math.min(c.max, Math.max(c.min, k * c.ticks)));
    input.dispatchEvent(new Event("input"));
  }

  // What a slider's value reads as (its aria-valuetext), and the value printed beside it.
  show_value(c, value) {
    const text = (c.show ? c.show(value) : String(value)) + (c.name === "log_eps" && this.eps_unused() ? ", unused" : "");
    if (this.outputs[c.name]) this.outputs[c.name].textContent = text;
    if (c.kind === "range") this.inputs[c.name].setAttribute("aria-valuetext", text);
  }

  // The β slider's range follows the shading normal; β is clamped into it.
  clamp_beta() {
    const top = beta_max(this.state.bump);
    this.inputs.beta.max = String(top);
    this.state.beta = Math.min(this.state.beta, top);
  }

  // With each pixel's footprint as its step, ε steps nothing: its slider is disabled and says so.
  eps_unused() {
    return this.state.numeric === "footprint";
  }

  sync_inputs() {
    this.clamp_beta();
    this.inputs.log_eps.disabled = this.eps_unused();
    for (const c of CONTROLS) {
      const input = this.inputs[c.name];
      const value = this.state[c.name];
      if (c.kind === "checkbox") input.checked = value; else input.value = String(value);
      this.show_value(c, value);
    }
  }

  set_from_input(c, input) {
    let value;
    if (c.kind === "checkbox") value = input.checked;
    else if (c.kind === "range" || typeof c.options[0] === "number") value = Number(input.value);
    else value = input.value;
    const before = { ...this.state };   // a menu fires both input and change: say the new range once
    this.state[c.name] = value;
    if (c.name === "bump" || c.name === "numeric") this.sync_inputs();
    if (c.name === "bump" && value !== before.bump) {
      this.note.textContent = beta_range_note(value, this.state.beta < before.beta);
    } else if (c.name !== "bump") {
      this.note.textContent = "";                                 // the note said its piece
    }
    this.show_value(c, value);
    this.schedule();
  }

  apply_preset(p) {
    const bump = this.state.bump;
    this.state = { ...DEFAULT_STATE, ...p.set };
    this.sync_inputs();
    // A preset that swaps the shading normal changes the β slider's range: said as the control says it.
    this.note.textContent = this.state.bump === bump ? "" : beta_range_note(this.state.bump, false);
    this.hint.textContent = p.hint ?? HINT;
    this.root.dataset.preset = p.id ?? "";
    this.update();
    if (p.focus) this.inputs[p.focus].focus();
  }

  schedule() {
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => { this.pending = false; this.update(); });
  }

  // Re-shade what changed (render.js `PairRenderer`), the ledger, the canvases, the U-curve.
  update() {
    const s = this.state;
    const scene = scene_of(s);
    const t0 = performance.now();
    const res = this.renderer.update(scene, s.resolution, s.resolution, s.zoom, s.numeric);
    const ledger = compare(res.numeric, res.symbolic);
    this.frame_ledger = ledger;
    const t_shade = performance.now();
    this.draw(res);
    const t1 = performance.now();
    if (res.full || res.shaded.includes("symbolic") || this.curve === null) {
      const stride = curve_stride(s.resolution);
      this.curve = { stride, points: this.renderer.ledger_along_eps(CURVE_LOG_EPS.map(eps_of), stride) };
      this.curve_generation += 1;
      if (stride > 1) this.refine(this.curve_generation); else this.root.dataset.curve = "every pixel";
    }
    this.curve.here = this.renderer.ledger_along_eps([scene.eps], this.curve.stride, false)[0];
    this.draw_curve();
    const ms = performance.now() - t0;
    this.timings.push({ resolution: s.resolution, ms, shade_ms: t_shade - t0, draw_ms: t1 - t_shade,
                        curve_ms: performance.now() - t1, full: res.full, shaded: res.shaded });
    this.frames = { scene, numeric: res.numeric, symbolic: res.symbolic, ledger, ms };
    // What the change did, said once (the control says its own new value): the difference on sphere A.
    this.status.textContent = `On sphere A ${this.describe(ledger)}.`;
    const put = (id, text, value) => {
      const td = this.root.querySelector(`#${id}`);
      td.textContent = text;
      td.dataset.value = String(value);
    };
    put("sim-max", fmt(ledger.max_abs), ledger.max_abs);
    put("sim-rms", fmt(ledger.rms), ledger.rms);
    put("sim-flips", String(ledger.flips), ledger.flips);
    put("sim-pixels", ledger.pixels_a.toLocaleString("en-US"), ledger.pixels_a);   // with thousands separators, as the book prints counts
    put("sim-time", `${ms.toFixed(0)} ms (${res.full ? "new geometry" : "sphere A re-shaded"})`, ms);
    this.root.dataset.updates = String(this.timings.length);
    if (this.probe) this.show_probe(this.probe.i, this.probe.j, false);
  }

  // The three canvases.  Off sphere A nothing changes while the geometry, the
  // view and the scale stay, so only A's pixels are redrawn then, and only on
  // the canvases whose frame was re-shaded.
  draw(res) {
    const { numeric, symbolic } = res;
    const view = this.state.view, scale = this.state.scale, w = numeric.width, h = numeric.height;
    const look = `${view} ${scale} ${w}`;
    const all = res.full || this.drawn !== look;
    this.drawn = look;
    const n = numeric.chamber.length;
    let gmax = 0.0;
    if (view === "bump") {
      for (let k = 0; k < n; k++) {
        if (symbolic.chamber[k] === SPHERE_A) gmax = Math.max(gmax, Math.hypot(symbolic.grad[2 * k], symbolic.grad[2 * k + 1]));
      }
    }
    const gnorm = (f, k) => Math.hypot(f.grad[2 * k], f.grad[2 * k + 1]) / (gmax || 1.0);
    const pixels = all ? null : this.renderer.gb.pixels;
    const redraw = { numeric: all || res.shaded.includes("numeric"), symbolic: all || res.shaded.includes("symbolic") };
    redraw.difference = redraw.numeric || redraw.symbolic;
    for (const name of ["numeric", "symbolic", "difference"]) {
      if (!redraw[name]) continue;
      const canvas = this.canvases[name];
      if (all) { canvas.width = w; canvas.height = h; }
      const ctx = canvas.getContext("2d");
      const img = all ? ctx.createImageData(w, h) : this.images[name];
      const px = img.data;
      const frame = name === "numeric" ? numeric : symbolic;
      const count = pixels ? pixels.length : n;
      for (let a = 0; a < count; a++) {
        const k = pixels ? pixels[a] : a;
        let r, g, b;                      // bytes
        if (name !== "difference") {
          if (view === "bump") {
            r = g = b = frame.chamber[k] === SPHERE_A ? srgb_byte(gnorm(frame, k)) : 0;
          } else {
            r = srgb_byte(frame.image[3 * k]); g = srgb_byte(frame.image[3 * k + 1]); b = srgb_byte(frame.image[3 * k + 2]);
            if (view === "kink") {
              if (symbolic.kink[k]) { r = g = b = 255; } else { r = Math.round(0.4 * r); g = Math.round(0.4 * g); b = Math.round(0.4 * b); }
            }
          }
        } else {
          const level = (d) => Math.round(255 * difference_level(d, scale));
          if (view === "bump") {
            const both = numeric.chamber[k] === SPHERE_A && symbolic.chamber[k] === SPHERE_A;
            r = g = b = both ? level(Math.abs(gnorm(numeric, k) - gnorm(symbolic, k))) : 0;
          } else if (scale === "log") {     // one grey level: the largest channel difference
            r = g = b = level(Math.max(Math.abs(numeric.image[3 * k] - symbolic.image[3 * k]),
                                       Math.abs(numeric.image[3 * k + 1] - symbolic.image[3 * k + 1]),
                                       Math.abs(numeric.image[3 * k + 2] - symbolic.image[3 * k + 2])));
            if (view === "kink" && symbolic.kink[k]) { r = Math.round(0.6 * r); g = Math.max(r, BAND_GREEN); b = BAND_BLUE; }
          } else {
            r = level(Math.abs(numeric.image[3 * k] - symbolic.image[3 * k]));
            g = level(Math.abs(numeric.image[3 * k + 1] - symbolic.image[3 * k + 1]));
            b = level(Math.abs(numeric.image[3 * k + 2] - symbolic.image[3 * k + 2]));
            if (view === "kink" && symbolic.kink[k]) { g = Math.max(g, BAND_GREEN); b = BAND_BLUE; }
          }
        }
        px[4 * k] = r; px[4 * k + 1] = g; px[4 * k + 2] = b; px[4 * k + 3] = 255;
      }
      ctx.putImageData(img, 0, 0);
      (this.images ??= {})[name] = img;
    }
    const pipe = this.state.numeric === "central" ? `central differences, ε = ${eps_of(this.state.log_eps).toExponential(1)}`
      : "central differences, step = the pixel's footprint";
    const diff = scale === "log" ? `log scale, ${power_of_ten(LOG_FLOOR)} black to 1 white` : `linear scale, × ${LINEAR_GAIN}`;
    const cap = { shaded: [`numeric: ${pipe}`, "symbolic: the exact gradient", `difference |ΔI|, ${diff}`],
                  bump: [`size of ∇h, numeric (${pipe})`, "size of ∇h, exact", `difference of the sizes, ${diff}`],
                  kink: [`crease band in white, numeric (${pipe})`, "crease band in white, exact",
                         `difference |ΔI|, ${diff}; the band in blue`] }[view];
    ["numeric", "symbolic", "difference"].forEach((name, i) => {
      this.root.querySelector(`#sim-caption-${name}`).textContent = cap[i];
    });
  }

  // Each canvas's text alternative (its aria-label): what it draws, in
  // words, and the ledger's numbers for the difference; rewritten on every update.  Returns those numbers
  // in words, as the status line says them too (the band's means with them: the chapter's point).
  describe(ledger) {
    const totals = `max |ΔI| ${fmt(ledger.max_abs, 1)}, RMS ${fmt(ledger.rms, 1)}, ${ledger.flips} flips`;
    // Where the differences sit, as the difference canvas shows them: on a field with creases, the ledger's mean
    // |ΔI| on the crease band and off it.
    const where = Number.isFinite(ledger.mean_abs_kink) && Number.isFinite(ledger.mean_abs_off_kink)
      ? `; mean |ΔI| ${fmt(ledger.mean_abs_kink, 1)} in the crease band, ${fmt(ledger.mean_abs_off_kink, 1)} off it` : "";
    const s = this.state, bump = CONTROLS.find((c) => c.name === "bump").labels[s.bump];
    const view = { shaded: "shaded", bump: "the size of ∇h in grey", kink: "the crease band in white" }[s.view];
    const what = `sphere A with the ${s.height_field} field, β = ${s.beta.toFixed(2)}, kᵤ = ${s.k_u}, kᵥ = ${s.k_v}, ` +
      `the shading normal ${bump}, ${s.resolution} × ${s.resolution} pixels` + (s.zoom > 1 ? `, the pole magnified ×${s.zoom}` : "");
    const pipe = s.numeric === "central" ? `central differences at ε = ${eps_of(s.log_eps).toExponential(1)}`
      : "central differences, each pixel's footprint its step";
    const scale = s.scale === "log" ? `log scale, ${power_of_ten(LOG_FLOOR)} black to 1 white` : `linear scale, × ${LINEAR_GAIN}`;
    const text = {
      numeric: `Render by ${pipe}: ${what}; ${view}.`,
      symbolic: `Render by the exact gradient: ${what}; ${view}.`,
      // The ledger is of the shaded renders in every view (the bump view draws the sizes of ∇h instead).
      difference: (s.view === "bump" ? `Difference of the sizes of ∇h of the two renders, ${scale}; the shaded renders' `
        : `Difference |ΔI| of the two shaded renders, ${scale}${s.view === "kink" ? ", the crease band in blue" : ""}; `) +
        `on sphere A ${totals}${where}.`,
    };
    for (const [name, t] of Object.entries(text)) {
      this.canvases[name].setAttribute("aria-label", `${t} Arrow keys move the probe, with Shift ten pixels; ` +
                                       "B moves it to the next pixel in the crease band, Shift+B to the one before.");
    }
    return totals + where;
  }

  // The U-curve over every pixel of sphere A, one step of ε per task, replacing the sample's when all
  // are done; a newer curve (generation) stops it.  The frames it reads change only with a newer curve.
  refine(generation) {
    const eps_list = CURVE_LOG_EPS.map(eps_of), points = [];
    const step = () => {
      if (generation !== this.curve_generation) return;
      points.push(this.renderer.ledger_along_eps([eps_list[points.length]], 1, false)[0]);
      if (points.length < eps_list.length) { setTimeout(step, 0); return; }
      this.curve = { stride: 1, points, here: this.renderer.ledger_along_eps([this.frames.scene.eps], 1, false)[0] };
      this.draw_curve();
      this.root.dataset.curve = "every pixel";
    };
    delete this.root.dataset.curve;
    setTimeout(step, 0);
  }

  // The U-curve: RMS and max |ΔI| on sphere A against ε, log-log, the current ε marked.
  draw_curve() {
    if (this.curve === null) return;
    const plot = this.plot, box = plot.getBoundingClientRect();
    const W = Math.max(box.width, 240), H = Math.max(box.height, 160);
    const m = { left: 44, right: 10, top: 24, bottom: 36 };
    const X = (le) => m.left + (le - LOG_EPS.min) / (LOG_EPS.max - LOG_EPS.min) * (W - m.left - m.right);
    const Y = (d) => {
      const ld = d > 0 ? Math.max(CURVE_FLOOR, Math.log10(d)) : CURVE_FLOOR;
      return m.top + (0 - ld) / (0 - CURVE_FLOOR) * (H - m.top - m.bottom);
    };
    plot.setAttribute("viewBox", `0 0 ${W} ${H}`);
    const nodes = [];
    for (let e = LOG_EPS.min; e <= LOG_EPS.max; e++) {
      nodes.push(svg("line", { x1: X(e), x2: X(e), y1: m.top, y2: H - m.bottom, stroke: "currentColor", "stroke-opacity": 0.12 }));
      if ((e - LOG_EPS.min) % 3 === 0) nodes.push(svg("text", { x: X(e), y: H - m.bottom + 14, "text-anchor": "middle" }, power_of_ten(e)));
    }
    for (let d = CURVE_FLOOR + 1; d <= 0; d++) {
      nodes.push(svg("line", { x1: m.left, x2: W - m.right, y1: Y(10 ** d), y2: Y(10 ** d), stroke: "currentColor", "stroke-opacity": 0.12 }));
      if (d % 4 === 0 && d > CURVE_FLOOR + 1) {
        nodes.push(svg("text", { x: m.left - 4, y: Y(10 ** d) + 4, "text-anchor": "end" }, power_of_ten(d)));
      }
    }
    nodes.push(svg("text", { x: m.left - 4, y: H - m.bottom + 4, "text-anchor": "end" }, "0"));
    nodes.push(svg("text", { x: (m.left + W - m.right) / 2, y: H - 4, "text-anchor": "middle" }, "ε, the finite-difference step"));
    nodes.push(svg("rect", { x: m.left, y: m.top, width: W - m.left - m.right, height: H - m.top - m.bottom,
                             fill: "none", stroke: "currentColor", "stroke-opacity": 0.5 }));
    const points = this.curve.points;
    for (const key of ["rms", "max"]) {
      const value = (p) => key === "rms" ? p.rms : p.max_abs;
      nodes.push(svg("polyline", { id: `sim-curve-${key}`, fill: "none", stroke: CURVE_COLOURS[key], "stroke-width": 2,
                                   "stroke-dasharray": key === "max" ? "6 3" : "none",
                                   points: points.map((p, i) => `${X(CURVE_LOG_EPS[i]).toFixed(1)},${Y(value(p)).toFixed(1)}`).join(" ") }));
    }
    // The image-best step: of the curve's steps, the one of least RMS |ΔI| over sphere A in this
    // frame (none when every RMS is 0, as at β = 0).
    const best = points.reduce((b, p, i) => (p.rms < points[b].rms ? i : b), 0);
    const marked = points[best].rms < Math.max(...points.map((p) => p.rms));
    const best_eps = eps_of(CURVE_LOG_EPS[best]).toExponential(1);
    if (marked) {
      const xb = X(CURVE_LOG_EPS[best]), yb = Math.min(Y(points[best].rms) + 6, H - m.bottom - 22);
      nodes.push(svg("path", { id: "sim-curve-best", d: `M ${xb.toFixed(1)} ${yb.toFixed(1)} l -5 9 l 10 0 z`,
                               fill: CURVE_COLOURS.rms, stroke: "currentColor", "data-eps": String(eps_of(CURVE_LOG_EPS[best])) }));
      nodes.push(svg("text", { id: "sim-curve-best-label", x: xb, y: yb + 21, "text-anchor": "middle" },
                               `best ε ${this.curve.stride === 1 ? "=" : "≈"} ${best_eps}`));   // ≈: of the sample
    }
    const here = this.curve.here, x = X(Math.log10(here.eps)), unused = this.eps_unused();
    if (!unused) {   // footprint steps: the frame has no one ε to mark
      nodes.push(svg("line", { id: "sim-curve-marker", x1: x, x2: x, y1: m.top, y2: H - m.bottom, stroke: "currentColor",
                               "stroke-dasharray": "2 2" }));
      for (const key of ["rms", "max"]) {
        nodes.push(svg("circle", { cx: x, cy: Y(key === "rms" ? here.rms : here.max_abs), r: 4.5, fill: CURVE_COLOURS[key],
                                   stroke: "currentColor" }));
      }
    }
    // Sampled (until `refine` is done), the curve's values differ from the ledger's, which counts every pixel: its legend says so.
    const over = this.curve.stride === 1 ? " on sphere A" : " (sampled)";
    [["rms", "RMS |ΔI|" + over], ["max", "max |ΔI|" + over]].forEach(([key, label], i) => {
      const y = m.top - 8, x0 = m.left + i * 160;
      nodes.push(svg("line", { x1: x0, x2: x0 + 22, y1: y - 4, y2: y - 4, stroke: CURVE_COLOURS[key], "stroke-width": 2,
                               "stroke-dasharray": key === "max" ? "6 3" : "none" }));
      nodes.push(svg("text", { x: x0 + 27, y }, label));
    });
    plot.innerHTML = nodes.join("");
    // Each row's ε, with "best" at the triangle's and "current" at the slider's (when it is one of the curve's steps).
    const current = unused ? -1 : CURVE_LOG_EPS.findIndex((l) => eps_of(l) === here.eps);
    this.curve_rows.replaceChildren(...points.map((p, i) => el("tr", {}, [
      el("th", { scope: "row", text: eps_of(CURVE_LOG_EPS[i]).toExponential(1) +
        [marked && i === best && "best", i === current && "current"].filter(Boolean).map((m) => ` (${m})`).join("") }),
      el("td", { text: fmt(p.rms, 2) }), el("td", { text: fmt(p.max_abs, 2) })])));
    const stride = this.curve.stride, s = this.state.resolution;
    const sample = stride === 1 ? `every pixel of sphere A in the ${s} × ${s} frame`
                                : `one pixel in each ${stride} × ${stride} block of the ${s} × ${s} frame ` +
                                  "(every pixel's curve follows in a moment)";
    this.root.querySelector("#sim-curve-table-caption").textContent = `|ΔI| on sphere A at each step ε, over ${sample}; (current): the slider's ε, if one of them`;
    const said = unused ? this.frame_ledger : here;     // with footprint steps, the frame's own ledger
    plot.setAttribute("aria-label", `U-curve: RMS and max |ΔI| on sphere A against ε, log-log; ` +
                      (unused ? "the frame takes each pixel's footprint as its step: " : `at ε = ${here.eps.toExponential(1)} `) +
                      `RMS ${fmt(said.rms, 1)}, max ${fmt(said.max_abs, 1)}` +
                      (marked ? `; the image-best step: ${best_eps}` : ""));
    plot.dataset.eps = String(here.eps);
    this.root.querySelector("#sim-curve-caption").textContent =
      `The U-curve of central differences, on ${sample}, at half-decade steps of ε; ` +
      (unused ? "no ε is marked: the frame takes each pixel's footprint as its step; "
              : "the dotted line and the dots: the current ε; ") +
      `the triangle: the image-best step, the one of these steps with the least RMS. ` +
      `An exact zero lies on the bottom axis. ${RIGHT_ARM[FIELD_CREASES[this.state.height_field] ? "creased" : "smooth"]}`;
  }

  pointer(canvas, ev) {
    const rect = canvas.getBoundingClientRect();
    const res = this.state.resolution;
    const i = Math.min(res - 1, Math.max(0, Math.floor((ev.clientX - rect.left) * res / rect.width)));
    const j = Math.min(res - 1, Math.max(0, Math.floor((ev.clientY - rect.top) * res / rect.height)));
    this.show_probe(i, j);
  }

  probe_key(ev) {
    const moves = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, -1], ArrowDown: [0, 1] };
    const band = ev.key === "b" || ev.key === "B";
    if (!(ev.key in moves) && !band) return;
    ev.preventDefault();
    if (band) { this.probe_band(ev.shiftKey ? -1 : 1); return; }
    const res = this.state.resolution;
    if (!this.probe) { this.show_probe(res >> 1, res >> 1); return; }      // the first press reads the centre
    const p = this.probe, n = ev.shiftKey ? 10 : 1, [di, dj] = moves[ev.key];
    this.show_probe(Math.min(res - 1, Math.max(0, p.i + n * di)), Math.min(res - 1, Math.max(0, p.j + n * dj)));
  }

  // The probe to the next pixel of sphere A in the crease band (dir 1; -1, the one before), row by row from the
  // probe's pixel and round: the band is a pixel or two wide, and arrow keys step over it.  The status line
  // says so when the frame has none.
  probe_band(dir) {
    const f = this.frames.symbolic, res = this.state.resolution, n = res * res;
    const from = this.probe ? this.probe.j * res + this.probe.i : (dir > 0 ? -1 : n);
    for (let step = 1; step <= n; step++) {
      const k = (((from + dir * step) % n) + n) % n;
      if (f.kink[k] && f.chamber[k] === SPHERE_A) { this.show_probe(k % res, Math.floor(k / res)); return; }
    }
    this.status.textContent = "No pixel of sphere A is in the crease band.";
  }

  // rows: [name, value, brief]; a brief row is one a phone shows until the reader asks for all (STYLE).
  show_readout(rows) {
    this.readout.replaceChildren(...rows.flatMap(([k, v, brief]) => {
      const cls = brief ? { class: "sim-brief" } : {};
      return [el("dt", { text: k, ...cls }), el("dd", { text: v, ...cls })];
    }));
  }

  // The readout of pixel (i, j); a probe moved there (say) also says, in the status line, which pixel it
  // reads, whether it is in the crease band (where the two pipelines part) and its |ΔI|, first: the
  // readout is no live region (after a change of a control it would be read whole again).
  show_probe(i, j, say = true) {
    const s = this.state;
    const res = s.resolution;
    if (i >= res || j >= res) { i = res >> 1; j = res >> 1; }
    this.probe = { i, j };
    for (const mark of this.marks) {
      mark.hidden = false;
      mark.style.left = `${(100 * (i + 0.5)) / res}%`;
      mark.style.top = `${(100 * (j + 0.5)) / res}%`;
    }
    const pr = probe_pixel(this.frames.scene, res, res, i, j, s.zoom, s.numeric);
    const a = pr.symbolic, b = pr.numeric;
    // A negative component with the minus sign, as the book's prose writes it (a screen reader says "minus").
    const signed = (x, digits) => x.toPrecision(digits).replace(/^-/, "\u2212");
    const vec = (v, digits = 10) => v ? "(" + v.map((x) => signed(x, digits)).join(", ") + ")" : "—";
    // |ΔI| second, the readout's one number that says how the two pipelines differ, in view below the canvases.
    const delta = fmt(Math.max(...a.rgb.map((x, c) => Math.abs(x - b.rgb[c]))), 2);
    const rows = [["pixel", `x\u00a0=\u00a0${i}, y\u00a0=\u00a0${j}: ${CHAMBER_NAMES[a.chamber].replaceAll(" ", "\u00a0")}`, true],
                  ["|ΔI|", `${delta}, the largest channel`, true], ["hit point", vec(a.P, 6)]];
    if (a.chamber === SPHERE_A) {
      rows.push(["(u, v)", vec(a.uv, 8)]);
      rows.push(["∇h exact", vec(a.grad)]);
      rows.push([`∇h ${b.gradient}`, vec(b.grad)]);
      rows.push(["step", b.steps[0] === b.steps[1] ? `ε = ${b.steps[0].toExponential(1)}`
        : `εᵤ = ${b.steps[0].toExponential(2)}, εᵥ = ${b.steps[1].toExponential(2)}`]);
      rows.push(["crease", a.kink ? "in the band: the stencil may reach across a crease" : "not in the band"]);
    }
    rows.push(["RGB exact", vec(a.rgb, 6)]);
    rows.push([`RGB ${b.gradient}`, vec(b.rgb, 6)]);
    this.show_readout(rows);
    const band = a.kink ? ", in the crease band" : "";
    if (say) this.status.textContent = `Pixel x ${i}, y ${j}, ${CHAMBER_NAMES[a.chamber]}${band}: |ΔI| ${delta}.`;
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
