// The two pipelines, one render function differing only in the gradient: the
// JavaScript twin of renderer/render.py.  render.py works on tiles of arrays;
// here the same steps run one pixel at a time, in the same order and with the
// same formulas, so that the two agree to rounding.  A reusable `Surface`
// record carries one pixel through the steps, so the loop allocates nothing.
import { field_functions, kink_band } from "./fields.js";
import { image_plane, sphere_hit, chart, tangent_frame, segment_hits_sphere } from "./geometry.js";
import { POLE_SIN_PHI, FLOOR_LIGHT, FLOOR_DARK, BACKGROUND, SPHERE_A, SPHERE_B, FLOOR,
         GRADIENTS } from "./constants.js";

// Python-style x mod 1 (numpy's `mod`: the result takes the divisor's sign).
function mod1(x) {
  const m = x % 1.0;
  if (m === 0) return 0.0;
  return m < 0 ? m + 1.0 : m;
}

// Central differences of the height function h (render.py `central_gradient`):
// u wraps, v clamps to [0, 1] with a one-sided quotient where it clamps.
// Writes [h_u, h_v] into out and returns it.
function _central_gradient(h, u, v, ku, kv, eps, out) {
  const up = mod1(u + eps);
  const um = mod1(u - eps);
  out[0] = (h(up, v, ku, kv) - h(um, v, ku, kv)) / (2.0 * eps);
  const vp = Math.min(1.0, v + eps);
  const vm = Math.max(0.0, v - eps);
  const clamped = (v + eps > 1.0) || (v - eps < 0.0);
  const den = clamped ? vp - vm : 2.0 * eps;
  out[1] = (h(u, vp, ku, kv) - h(u, vm, ku, kv)) / den;
  return out;
}

// render.py `central_gradient` for the field `name` at one chart point.
export function central_gradient(name, u, v, ku, kv, eps, out = new Float64Array(2)) {
  return _central_gradient(field_functions(name).height, u, v, ku, kv, eps, out);
}

function _dot(ax, ay, az, bx, by, bz) {
  return ax * bx + ay * by + az * bz;
}

// One pixel on its way through the pipeline (the arrays of render.py's
// `_Surface`, for a single ray).
class Surface {
  constructor() {
    this.chamber = BACKGROUND; this.t = Infinity;
    this.P = new Float64Array(3); this.N = new Float64Array(3); this.Ns = new Float64Array(3);
    this.albedo = new Float64Array(3); this.blockers = null;
    this.uvs = new Float64Array(3);            // u, v, sin(phi) on sphere A
    this.e_theta = new Float64Array(3); this.e_phi = new Float64Array(3);
    this.grad = new Float64Array(2); this.kink = false;
    this.rgb = new Float64Array(3);
  }
}

// What one frame needs from the scene, resolved once: the field's functions,
// the lights that can contribute (zero colour is skipped, as in render.py)
// and each object's shadow blockers.
function _prepare(scene) {
  const sphere_a = [[0.0, 0.0, 0.0], scene.radius_a];
  const sphere_b = [scene.center_b, scene.radius_b];
  return {
    scene,
    field: field_functions(scene.height_field),
    lights: scene.lights.filter((l) => l.color[0] || l.color[1] || l.color[2]),
    blockers: {
      [SPHERE_A]: scene.sphere_b ? [sphere_b] : [],
      [SPHERE_B]: [sphere_a],
      [FLOOR]: scene.sphere_b ? [sphere_a, sphere_b] : [sphere_a],
    },
  };
}

const ORIGIN = [0.0, 0.0, 0.0];

// Nearest positive hit (render.py `_nearest_hit`); ties go to A, then B, then the floor.
function _nearest_hit(scene, X, Y, s) {
  let t = Infinity, code = BACKGROUND;
  const tA = sphere_hit(X, Y, scene.camera_z, ORIGIN, scene.radius_a);
  if (tA < t) { t = tA; code = SPHERE_A; }
  if (scene.sphere_b) {
    const tB = sphere_hit(X, Y, scene.camera_z, scene.center_b, scene.radius_b);
    if (tB < t) { t = tB; code = SPHERE_B; }
  }
  if (scene.floor && 1.0 < t) { t = 1.0; code = FLOOR; }
  s.t = t; s.chamber = code;
}

// Geometry of the hit (render.py `_surfaces` up to the gradient): hit point,
// geometric normal, albedo, blockers; on sphere A the chart, the tangent
// frame and the kink flag.  Depends on geometry alone.
function _surface(ctx, X, Y, s) {
  const scene = ctx.scene;
  _nearest_hit(scene, X, Y, s);
  if (s.chamber === BACKGROUND) return;
  const t = s.t, P = s.P, N = s.N;
  P[0] = t * X; P[1] = t * Y; P[2] = scene.camera_z * (1.0 - t);
  s.blockers = ctx.blockers[s.chamber];
  if (s.chamber === SPHERE_A) {
    for (let c = 0; c < 3; c++) { N[c] = P[c] / scene.radius_a; s.albedo[c] = scene.albedo_a[c]; }
    chart(N[0], N[1], N[2], s.uvs);
    s.kink = ctx.field.creased && kink_band(scene.height_field, s.uvs[0], s.uvs[1], scene.k_u, scene.k_v);
    tangent_frame(N[0], N[1], N[2], s.uvs[2], s.e_theta, s.e_phi);
  } else if (s.chamber === SPHERE_B) {
    for (let c = 0; c < 3; c++) { N[c] = (P[c] - scene.center_b[c]) / scene.radius_b; s.albedo[c] = scene.albedo_b[c]; }
  } else {
    N[0] = 0.0; N[1] = 0.0; N[2] = 1.0;
    // Checker: light squares where sin(pi x) sin(pi y) >= 0 (seed Cell 1).
    const light_square = Math.sin(Math.PI * P[0]) * Math.sin(Math.PI * P[1]) >= 0.0;
    const base = light_square ? FLOOR_LIGHT : FLOOR_DARK;
    const rg = base * (1.0 - scene.floor_tint);
    s.albedo[0] = rg; s.albedo[1] = rg; s.albedo[2] = base;
  }
  s.Ns.set(N);
}

// The pipelines' one difference: the chart gradient on sphere A.
function _gradient(ctx, gradient, s) {
  const scene = ctx.scene, u = s.uvs[0], v = s.uvs[1];
  if (gradient === "exact") ctx.field.gradient(u, v, scene.k_u, scene.k_v, s.grad);
  else _central_gradient(ctx.field.height, u, v, scene.k_u, scene.k_v, scene.eps, s.grad);
}

// Perturbed normal on sphere A (render.py `_surfaces`):
// N' = M / |M|, M = N + beta (h_u e_theta + h_v e_phi) for bump = "chart";
// the displaced surface's normal for bump = "surface".
function _perturb(ctx, s) {
  const scene = ctx.scene, N = s.N, Ns = s.Ns;
  if (scene.beta === 0.0) { Ns.set(N); return; }   // beta = 0 is the un-bumped scene, exactly
  const hu = s.grad[0], hv = s.grad[1];
  let bu, bv;
  if (scene.bump === "chart") {
    bu = scene.beta * hu; bv = scene.beta * hv;
  } else {
    // Normal of P = (R + beta h) N: h_theta = h_u / 2 pi, h_phi = h_v / pi.
    const h = ctx.field.height(s.uvs[0], s.uvs[1], scene.k_u, scene.k_v);
    const w = -scene.beta / (scene.radius_a + scene.beta * h);
    const s_phi = Math.max(s.uvs[2], POLE_SIN_PHI);
    bu = w * hu / (2.0 * Math.PI * s_phi); bv = w * hv / Math.PI;
  }
  for (let c = 0; c < 3; c++) Ns[c] = N[c] + bu * s.e_theta[c] + bv * s.e_phi[c];
  const inv = 1.0 / Math.sqrt(_dot(Ns[0], Ns[1], Ns[2], Ns[0], Ns[1], Ns[2]));
  for (let c = 0; c < 3; c++) Ns[c] = Ns[c] * inv;
}

// Ambient plus, per light, Lambert and Blinn/Phong (render.py `_shade`).  A
// light reaches P only if the geometric normal faces it and no blocker sphere,
// nor the floor plane, cuts the segment; the shading normal Ns enters only
// the Lambert and specular factors.  Writes the clipped colour to s.rgb.
function _shade(ctx, s) {
  const scene = ctx.scene;
  const Px = s.P[0], Py = s.P[1], Pz = s.P[2];
  const Nx = s.N[0], Ny = s.N[1], Nz = s.N[2];
  const Sx = s.Ns[0], Sy = s.Ns[1], Sz = s.Ns[2];
  const floor_blocks = scene.floor && s.chamber !== FLOOR;
  const out = s.rgb;
  for (let c = 0; c < 3; c++) out[c] = scene.ka * scene.ambient[c];
  let vx = -Px, vy = -Py, vz = scene.camera_z - Pz;
  let inv = 1.0 / Math.sqrt(_dot(vx, vy, vz, vx, vy, vz));
  vx = vx * inv; vy = vy * inv; vz = vz * inv;
  for (let l = 0; l < ctx.lights.length; l++) {
    const L = ctx.lights[l].position, color = ctx.lights[l].color;
    let wx = L[0] - Px, wy = L[1] - Py, wz = L[2] - Pz;
    let lit = _dot(Nx, Ny, Nz, wx, wy, wz) > 0.0;
    if (floor_blocks) lit = lit && !((Pz > 0.0 && L[2] < 0.0) || (Pz < 0.0 && L[2] > 0.0));
    const w2 = _dot(wx, wy, wz, wx, wy, wz);
    for (let b = 0; lit && b < s.blockers.length; b++) {
      lit = !segment_hits_sphere(wx, wy, wz, w2, L, s.blockers[b][0], s.blockers[b][1]);
    }
    if (!lit) continue;
    inv = 1.0 / Math.sqrt(w2);
    wx = wx * inv; wy = wy * inv; wz = wz * inv;
    const mu = _dot(Sx, Sy, Sz, wx, wy, wz);
    if (!(mu > 0.0)) continue;
    let spec_cos;
    if (scene.model === "blinn") {
      const hx = wx + vx, hy = wy + vy, hz = wz + vz;
      const hn = Math.sqrt(_dot(hx, hy, hz, hx, hy, hz));
      spec_cos = _dot(Sx, Sy, Sz, hx, hy, hz) / (hn > 0.0 ? hn : 1.0);
    } else {
      const two_mu = 2.0 * mu;
      spec_cos = _dot(two_mu * Sx - wx, two_mu * Sy - wy, two_mu * Sz - wz, vx, vy, vz);
    }
    const spec = Math.pow(Math.min(Math.max(spec_cos, 0.0), 1.0), scene.shininess) * scene.ks;
    const diffuse = mu * scene.kd;
    for (let c = 0; c < 3; c++) out[c] += color[c] * (diffuse * s.albedo[c] + spec);
  }
  for (let c = 0; c < 3; c++) out[c] = Math.min(1.0, Math.max(0.0, out[c]));
}

function _check_args(width, height, gradient, zoom) {
  for (const [name, value] of [["width", width], ["height", height]]) {
    if (!Number.isInteger(value) || value < 1 || value > 8192) {
      throw new RangeError(`${name} must be an integer between 1 and 8192 pixels, got ${value}`);
    }
  }
  if (gradient !== null && !GRADIENTS.includes(gradient)) {
    throw new RangeError(`gradient must be one of ${GRADIENTS.join(", ")}, got ${gradient}`);
  }
  if (!(zoom >= 1.0 && zoom <= 1e6)) throw new RangeError(`zoom must be between 1 and 1e6, got ${zoom}`);
}

function _frame(width, height, gradient) {
  const n = width * height;
  return { image: new Float64Array(3 * n), chamber: new Uint8Array(n), kink: new Uint8Array(n),
           grad: new Float64Array(2 * n), width, height, gradient };
}

function _store(frame, k, s) {
  frame.chamber[k] = s.chamber;
  frame.image[3 * k] = s.rgb[0]; frame.image[3 * k + 1] = s.rgb[1]; frame.image[3 * k + 2] = s.rgb[2];
  if (s.chamber === SPHERE_A) {
    frame.grad[2 * k] = s.grad[0]; frame.grad[2 * k + 1] = s.grad[1];
    frame.kink[k] = s.kink ? 1 : 0;
  }
}

// Trace one ray (X, Y) through one pipeline into the record s.
function _trace(ctx, gradient, X, Y, s) {
  _surface(ctx, X, Y, s);
  if (s.chamber === BACKGROUND) { s.rgb.fill(0.0); return s; }
  if (s.chamber === SPHERE_A) { _gradient(ctx, gradient, s); _perturb(ctx, s); }
  _shade(ctx, s);
  return s;
}

// Render the Chapter-9 scene through one pipeline (render.py `render`).
// Returns { image: Float64Array(H*W*3) linear RGB in [0, 1], chamber:
// Uint8Array(H*W), kink: Uint8Array(H*W), grad: Float64Array(H*W*2), width,
// height, gradient }, row 0 at the top.  Throws RangeError naming the argument
// for a bad size, gradient or zoom.
export function render(scene, width, height, gradient = "exact", zoom = 1.0) {
  _check_args(width, height, gradient, zoom);
  const ctx = _prepare(scene);
  const { x, y } = image_plane(scene.radius_a, scene.camera_z, width, height, zoom);
  const frame = _frame(width, height, gradient);
  const s = new Surface();
  for (let j = 0; j < height; j++) {
    for (let i = 0; i < width; i++) _store(frame, j * width + i, _trace(ctx, gradient, x[i], y[j], s));
  }
  return frame;
}

// Both pipelines in one pass: { numeric, symbolic }, each equal to `render`'s
// frame bit for bit.  Everything before the gradient is computed once per
// pixel, and pixels off sphere A are shaded once: they do not depend on the
// gradient (theorem "bump moves no boundary"; verify/ checks it with
// independent renders, tests/test_js_parity.py checks this function against
// `render`).
export function render_pair(scene, width, height, zoom = 1.0) {
  _check_args(width, height, null, zoom);
  const ctx = _prepare(scene);
  const { x, y } = image_plane(scene.radius_a, scene.camera_z, width, height, zoom);
  const numeric = _frame(width, height, "central");
  const symbolic = _frame(width, height, "exact");
  const s = new Surface();
  for (let j = 0; j < height; j++) {
    for (let i = 0; i < width; i++) {
      const k = j * width + i;
      _surface(ctx, x[i], y[j], s);
      if (s.chamber === BACKGROUND) { s.rgb.fill(0.0); _store(numeric, k, s); _store(symbolic, k, s); continue; }
      if (s.chamber !== SPHERE_A) { _shade(ctx, s); _store(numeric, k, s); _store(symbolic, k, s); continue; }
      _gradient(ctx, "central", s); _perturb(ctx, s); _shade(ctx, s); _store(numeric, k, s);
      _gradient(ctx, "exact", s); _perturb(ctx, s); _shade(ctx, s); _store(symbolic, k, s);
    }
  }
  return { numeric, symbolic };
}

// Everything both pipelines compute for pixel (column i, row j) of a
// width x height frame: the readout behind the simulator's hover.
export function probe_pixel(scene, width, height, i, j, zoom = 1.0) {
  _check_args(width, height, null, zoom);
  const ctx = _prepare(scene);
  const { x, y } = image_plane(scene.radius_a, scene.camera_z, width, height, zoom);
  const record = (gradient) => {
    const s = _trace(ctx, gradient, x[i], y[j], new Surface());
    const on_a = s.chamber === SPHERE_A;
    return { chamber: s.chamber, P: s.chamber ? Array.from(s.P) : null,
             uv: on_a ? [s.uvs[0], s.uvs[1]] : null, grad: on_a ? Array.from(s.grad) : null,
             kink: on_a && s.kink, rgb: Array.from(s.rgb) };
  };
  return { i, j, X: x[i], Y: y[j], numeric: record("central"), symbolic: record("exact") };
}
