// The §4 simulator's renderer: renderer/kernel.py, step by step, in JavaScript.
//
// One pixel at a time, in the order of the data flow, with the kernel's
// function names:
//
// camera ray -> `nearest_hit` (chamber) -> `surface` (hit point, normal,
// albedo) -> on sphere A: `chart`, `tangent_frame`, `gradient`,
// `shading_normal` -> `shade`: ambient + per light, `reach` (attached and
// cast shadows) then `light_term`, Lambert and Blinn/Phong with the shading
// normal.
//
// Every formula of sphere A (chart, tangent frame, gradients, crease flag,
// footprint, perturbed normals) is imported from formulas.js, which
// renderer/codegen.py prints from renderer/formulas.py: the same sympy objects
// the kernel's generated.py is printed from.  What is written here is what
// kernel.py writes itself: intersection, shadows and shading, with the same
// operations in the same order, so that they round alike.  The kernel's
// `skip` path is the one taken here (an object that is off is not
// intersected, no shadow ray where the light adds nothing); tests/test_skips.py
// shows it gives the bits of the path that skips nothing.  The kernel's tuples
// are preallocated arrays of a `Pixel` record, so the pixel loop allocates nothing.
import { FIELD_CODES, height, exact_gradient, central_gradient, kink_band, chart, tangent_frame,
         perturbed_normal_chart, perturbed_normal_surface, footprint } from "./formulas.js";
import { GRADIENTS, MAX_SIDE, MAX_ZOOM, WINDOW_MARGIN, WINDOW_OFFSET, BACKGROUND, SPHERE_A, SPHERE_B,
         FLOOR, FLOOR_LIGHT, FLOOR_DARK, TINY } from "./constants.js";

// Codes of the gradient methods: their index in GRADIENTS (render.py `_run`).
const EXACT = GRADIENTS.indexOf("exact"), CENTRAL = GRADIENTS.indexOf("central");

// ---- the camera (render.py `image_plane`) ----------------------------------------

// Pixel centres on the image plane z = 0 (seed Cell 1's window), magnified by
// `zoom` about the optical axis.  Returns { x: Float64Array(width),
// y: Float64Array(height), window: its width 2 half / zoom }; row 0 is the top.
export function image_plane(radius_a, camera_z, width, height, zoom = 1.0) {
  const half = WINDOW_MARGIN * camera_z * radius_a / Math.sqrt(camera_z * camera_z - radius_a * radius_a);
  const x = new Float64Array(width);
  const y = new Float64Array(height);
  for (let i = 0; i < width; i++) x[i] = half * (2.0 * (i + 0.5) / width - 1.0) / zoom;
  for (let j = 0; j < height; j++) y[j] = (half * (1.0 - 2.0 * (j + 0.5) / height) - WINDOW_OFFSET * half) / zoom;
  return { x, y, window: 2.0 * half / zoom };
}

// ---- the kernel's own steps: intersection, shadows, shading ------------------------

function copysign(a, b) {
  return (b < 0.0 || Object.is(b, -0.0)) ? -Math.abs(a) : Math.abs(a);
}

// Nearest t > 0 of the ray E + t (x, y, -e), E = (0, 0, e), on a sphere, or
// Infinity (kernel.py `sphere_hit`): stable roots q = -(b + sign(b) sqrt(disc)),
// t = q / a, c / q; the discriminant from the centre's distance to the ray's line.
export function sphere_hit(x, y, e, cx, cy, cz, r) {
  const ox = -cx, oy = -cy, oz = e - cz;
  const a = x * x + y * y + e * e;
  const b = x * ox + y * oy - e * oz;
  const c = ox * ox + oy * oy + oz * oz - r * r;
  const f = b / a;
  const lx = ox - f * x, ly = oy - f * y, lz = oz + f * e;
  const disc = a * (r * r - (lx * lx + ly * ly + lz * lz));
  if (!(disc >= 0.0)) return Infinity;
  const q = -(b + copysign(Math.sqrt(disc), b));
  const t0 = q / a, t1 = c / q;
  // Python's min and max (numba's too): the first argument unless the second is
  // strictly smaller (larger); Math.min would turn a NaN into the answer.
  const near = t1 < t0 ? t1 : t0, far = t1 > t0 ? t1 : t0;
  return near > 0.0 ? near : (far > 0.0 ? far : Infinity);
}

// Does the segment from P to the light L meet the sphere (C, r)?  w = L - P,
// w2 = |w|^2 (kernel.py `segment_blocked`).
export function segment_blocked(wx, wy, wz, w2, L, cx, cy, cz, r) {
  const dx = L[0] - cx, dy = L[1] - cy, dz = L[2] - cz;
  const k = dx * dx + dy * dy + dz * dz - r * r;
  if (k < 0.0) return true;
  const g = wx * dx + wy * dy + wz * dz;
  if (k === 0.0) return g > 0.0 && 2.0 * g < w2;
  return g > 0.0 && g < w2 && g * g >= w2 * k;
}

// The nearest positive hit into px.t, px.code; ties go to A, then B, then the floor.
function nearest_hit(s, x, y, px) {
  let t = sphere_hit(x, y, s.camera_z, 0.0, 0.0, 0.0, s.radius_a);
  let code = t < Infinity ? SPHERE_A : BACKGROUND;
  if (s.sphere_b) {
    const tb = sphere_hit(x, y, s.camera_z, s.center_b[0], s.center_b[1], s.center_b[2], s.radius_b);
    if (tb < t) { t = tb; code = SPHERE_B; }
  }
  if (s.floor && 1.0 < t) { t = 1.0; code = FLOOR; }     // the floor z = 0 is the image plane: t = 1
  px.t = t; px.code = code;
}

// Hit point P, geometric normal N and albedo of a hit (geometry only).
// `checker` = sin(pi x) sin(pi y): a floor hit is the pixel centre (x, y, 0)
// itself (t = 1), so the caller takes the sines once per column and row.
function surface(s, x, y, checker, px) {
  const t = px.t, P = px.P, N = px.N, albedo = px.albedo;
  P[0] = t * x; P[1] = t * y; P[2] = s.camera_z * (1.0 - t);
  if (px.code === SPHERE_A) {
    const r = s.radius_a;
    N[0] = P[0] / r; N[1] = P[1] / r; N[2] = P[2] / r;
    albedo.set(s.albedo_a);
  } else if (px.code === SPHERE_B) {
    const c = s.center_b, r = s.radius_b;
    N[0] = (P[0] - c[0]) / r; N[1] = (P[1] - c[1]) / r; N[2] = (P[2] - c[2]) / r;
    albedo.set(s.albedo_b);
  } else {
    // Checker: light squares where sin(pi x) sin(pi y) >= 0 (seed Cell 1).
    const base = checker >= 0.0 ? FLOOR_LIGHT : FLOOR_DARK;
    const rg = base * (1.0 - s.floor_tint);
    N[0] = 0.0; N[1] = 0.0; N[2] = 1.0;
    albedo[0] = rg; albedo[1] = rg; albedo[2] = base;
  }
}

// Does light L reach P?  The geometric normal faces it (attached shadow), the
// floor plane does not separate them (floor on, P off the floor), Ns . w > 0
// (else the light adds nothing and no shadow ray is traced), and no blocker
// sphere (B for A, A for B, both for the floor) cuts the segment (cast
// shadow).  Writes the unit vector w from P to L into `w` once it is known.
function reach(s, L, P, N, code, Ns, w) {
  const wx = L[0] - P[0], wy = L[1] - P[1], wz = L[2] - P[2];
  if (!(N[0] * wx + N[1] * wy + N[2] * wz > 0.0)) return false;
  if (s.floor && code !== FLOOR && ((L[2] < 0.0 && P[2] > 0.0) || (L[2] > 0.0 && P[2] < 0.0))) return false;
  const w2 = wx * wx + wy * wy + wz * wz;
  const inv = 1.0 / Math.sqrt(w2);
  w[0] = wx * inv; w[1] = wy * inv; w[2] = wz * inv;
  if (!(Ns[0] * w[0] + Ns[1] * w[1] + Ns[2] * w[2] > 0.0)) return false;
  if (code !== SPHERE_A && segment_blocked(wx, wy, wz, w2, L, 0.0, 0.0, 0.0, s.radius_a)) return false;
  if (code !== SPHERE_B && s.sphere_b) {
    const c = s.center_b;
    if (segment_blocked(wx, wy, wz, w2, L, c[0], c[1], c[2], s.radius_b)) return false;
  }
  return true;
}

// Unit vector from P to the eye (0, 0, camera_z), into `view`.
function view_vector(s, P, view) {
  const vx = -P[0], vy = -P[1], vz = s.camera_z - P[2];
  const inv = 1.0 / Math.sqrt(vx * vx + vy * vy + vz * vz);
  view[0] = vx * inv; view[1] = vy * inv; view[2] = vz * inv;
}

// The geometry of the highlight, independent of the shading normal Ns: the
// axis a into `axis`, and w . v returned.  The specular cosine is Ns . a
// (Blinn: a = the unit half vector) or 2 (Ns . w)(Ns . a) - w . v (Phong: a = v).
function specular_axis(s, w, view, axis) {
  if (s.phong) {
    axis.set(view);
    return w[0] * view[0] + w[1] * view[1] + w[2] * view[2];
  }
  const hx = w[0] + view[0], hy = w[1] + view[1], hz = w[2] + view[2];
  const inv = 1.0 / Math.max(Math.sqrt(hx * hx + hy * hy + hz * hz), TINY);   // |h| = 0 only where w = -v
  axis[0] = hx * inv; axis[1] = hy * inv; axis[2] = hz * inv;
  return 0.0;
}

// base ** n for an integer n >= 0 by repeated squaring, the multiplications
// in numba's order (numba/cpython/numbers.py `int_power`), so that the bits
// are the kernel's.
function int_power(base, n) {
  let r = 1.0, a = base;
  for (let e = n; e !== 0; e = Math.floor(e / 2)) {
    if (e % 2 === 1) r *= a;
    a *= a;
  }
  return r;
}

// Add a light's Lambert and Blinn/Phong terms at a point it reaches to rgb:
// `w` the unit vector to the light, (`axis`, `wv`) its `specular_axis`.
function light_term(s, color, w, axis, wv, Ns, albedo, rgb) {
  const mu = Ns[0] * w[0] + Ns[1] * w[1] + Ns[2] * w[2];
  if (!(mu > 0.0)) return;
  let spec_cos = Ns[0] * axis[0] + Ns[1] * axis[1] + Ns[2] * axis[2];
  if (s.phong) spec_cos = 2.0 * mu * spec_cos - wv;
  // Clamped before the power: rounding can put the cosine an ulp above 1.
  const base = Math.min(Math.max(spec_cos, 0.0), 1.0);
  // An integral exponent by repeated squaring, as the kernel (numba's float ** int).
  const n = Math.trunc(s.shininess);
  const spec = (n === s.shininess ? int_power(base, n) : Math.pow(base, s.shininess)) * s.ks;
  const diffuse = mu * s.kd;
  for (let c = 0; c < 3; c++) rgb[c] = rgb[c] + color[c] * (diffuse * albedo[c] + spec);
}

// Ambient plus every light that reaches P (seed Cell 1, `shade1`) into
// px.rgb, clipped to [0, 1].
function shade(s, px) {
  const P = px.P, rgb = px.rgb, view = px.view;
  for (let c = 0; c < 3; c++) rgb[c] = s.ka * s.ambient[c];
  view[2] = 0.0;
  for (let k = 0; k < s.lights.length; k++) {
    const L = s.lights[k].position;
    if (reach(s, L, P, px.N, px.code, px.Ns, px.w)) {
      if (view[2] === 0.0) view_vector(s, P, view);      // > 0 once computed: P is below the eye
      const wv = specular_axis(s, px.w, view, px.axis);
      light_term(s, s.lights[k].color, px.w, px.axis, wv, px.Ns, px.albedo, rgb);
    }
  }
  for (let c = 0; c < 3; c++) rgb[c] = Math.min(Math.max(rgb[c], 0.0), 1.0);
}

// (h_u, h_v) into px.grad by `method`: exact, central with step
// eps, or central with the pixel's footprint as steps (pixel spacing dx, dy
// on the image plane); the steps into px.steps (NaN for exact).
function gradient(s, method, eps, x, y, dx, dy, px) {
  const u = px.uvs[0], v = px.uvs[1], sin_phi = px.uvs[2];
  if (method === EXACT) {
    exact_gradient(s.field, u, v, s.k_u, s.k_v, px.grad);
    px.steps[0] = NaN; px.steps[1] = NaN;
    return;
  }
  if (method === CENTRAL) {
    px.steps[0] = eps; px.steps[1] = eps;
  } else {
    const P = px.P, N = px.N, f = px.frame;
    footprint(x, y, dx, dy, s.camera_z, P[0], P[1], P[2], N[0], N[1], N[2],
              f[0], f[1], f[2], f[3], f[4], f[5], s.radius_a, sin_phi, px.steps);
  }
  central_gradient(s.field, u, v, s.k_u, s.k_v, px.steps[0], px.steps[1], px.grad);
}

// N' of sphere A into px.Ns (formulas.py `PERTURBED_NORMAL`).
function shading_normal(s, px) {
  const N = px.N, f = px.frame, hu = px.grad[0], hv = px.grad[1];
  if (s.surface) {
    const u = px.uvs[0], v = px.uvs[1], sin_phi = px.uvs[2];
    const h = height(s.field, u, v, s.k_u, s.k_v);
    perturbed_normal_surface(N[0], N[1], N[2], f[0], f[1], f[2], f[3], f[4], f[5], hu, hv, s.beta,
                             h, s.radius_a, sin_phi, px.Ns);
    return;
  }
  perturbed_normal_chart(N[0], N[1], N[2], f[0], f[1], f[2], f[3], f[4], f[5], hu, hv, s.beta, px.Ns);
}

// ---- one pixel, one frame ------------------------------------------------------------

// The kernel's tuples of one pixel, reused from pixel to pixel.
class Pixel {
  constructor() {
    this.t = Infinity; this.code = BACKGROUND;
    this.P = new Float64Array(3); this.N = new Float64Array(3); this.Ns = new Float64Array(3);
    this.albedo = new Float64Array(3); this.rgb = new Float64Array(3);
    this.uvs = new Float64Array(3);        // chart: u, v, sin(phi)
    this.frame = new Float64Array(6);      // tangent_frame: e_theta, e_phi
    this.grad = new Float64Array(2);       // gradient: h_u, h_v
    this.kink = false;                     // the crease flag
    this.steps = new Float64Array(2);      // the central steps (eps_u, eps_v); NaN for exact
    this.w = new Float64Array(3); this.axis = new Float64Array(3); this.view = new Float64Array(3);
  }
}

// The kernel's `Params` of a scene object (kernel.py `params`, skip = True: the
// lights of zero colour are left out, they add exactly 0).
function params(scene) {
  if (!(scene.height_field in FIELD_CODES)) {
    throw new RangeError(`height_field must be one of ${Object.keys(FIELD_CODES).join(", ")}, got ${scene.height_field}`);
  }
  const f64 = (a) => Float64Array.from(a);
  return {
    camera_z: scene.camera_z, radius_a: scene.radius_a, center_b: f64(scene.center_b),
    radius_b: scene.radius_b, sphere_b: Boolean(scene.sphere_b), floor: Boolean(scene.floor),
    lights: scene.lights.filter((l) => l.color.some((c) => c !== 0))
      .map((l) => ({ position: f64(l.position), color: f64(l.color) })),
    ambient: f64(scene.ambient), albedo_a: f64(scene.albedo_a), albedo_b: f64(scene.albedo_b),
    ka: scene.ka, kd: scene.kd, ks: scene.ks, shininess: scene.shininess, phong: scene.model === "phong",
    floor_tint: scene.floor_tint, field: FIELD_CODES[scene.height_field], k_u: scene.k_u, k_v: scene.k_v,
    beta: scene.beta, surface: scene.bump === "surface",
  };
}

// Geometry of pixel (x, y), what does not depend on the gradient: chamber,
// hit point, normal, albedo; on sphere A the chart and the tangent frame
// (theorem "bump moves no boundary").
function geometry(s, x, y, checker, px) {
  nearest_hit(s, x, y, px);
  if (px.code === BACKGROUND) return;
  surface(s, x, y, checker, px);
  if (px.code !== SPHERE_A) { px.Ns.set(px.N); return; }
  const N = px.N;
  chart(N[0], N[1], N[2], px.uvs);
  tangent_frame(N[0], N[1], N[2], px.uvs[2], px.frame);
  px.kink = kink_band(s.field, px.uvs[0], px.uvs[1], s.k_u, s.k_v);
}

// The rest of pixel (x, y) after `geometry`: on sphere A the gradient and the
// shading normal, then the shade (black background).
function shade_pixel(s, method, eps, x, y, dx, dy, px) {
  if (px.code === BACKGROUND) { px.rgb.fill(0.0); return; }
  if (px.code === SPHERE_A) {
    gradient(s, method, eps, x, y, dx, dy, px);
    shading_normal(s, px);
  }
  shade(s, px);
}

function check_args(width, height, gradient, zoom) {
  for (const [name, value] of [["width", width], ["height", height]]) {
    if (!Number.isInteger(value) || value < 1 || value > MAX_SIDE) {
      throw new RangeError(`${name} must be an integer between 1 and ${MAX_SIDE} pixels, got ${value}`);
    }
  }
  if (!GRADIENTS.includes(gradient)) {
    throw new RangeError(`gradient must be one of ${GRADIENTS.join(", ")}, got ${gradient}`);
  }
  if (!(zoom >= 1.0 && zoom <= MAX_ZOOM)) throw new RangeError(`zoom must be between 1 and ${MAX_ZOOM}, got ${zoom}`);
}

// The camera of a frame: pixel centres, their spacing dx, dy (the footprint's
// ray differentials, as render.py `_run` passes them) and the floor checker's
// sines sin(pi x) per column and sin(pi y) per row.
function camera(scene, width, height, zoom) {
  const { x, y, window } = image_plane(scene.radius_a, scene.camera_z, width, height, zoom);
  const dx = width > 1 ? x[1] - x[0] : window;
  const dy = height > 1 ? y[0] - y[1] : window;
  return { x, y, dx, dy, sin_x: x.map((xi) => Math.sin(Math.PI * xi)), sin_y: y.map((yj) => Math.sin(Math.PI * yj)) };
}

// A frame (render.py `Frame`, flattened row-major, row 0 at the top):
// image (H*W*3) linear RGB in [0, 1], chamber (H*W), kink (H*W, 1 in the crease
// band), grad (H*W*2: h_u, h_v on sphere A, 0 elsewhere), uv (H*W*2: sphere A's
// chart, 0 elsewhere), width, height, gradient.
function new_frame(width, height, gradient) {
  const n = width * height;
  return { image: new Float64Array(3 * n), chamber: new Uint8Array(n), kink: new Uint8Array(n),
           grad: new Float64Array(2 * n), uv: new Float64Array(2 * n), width, height, gradient };
}

function store(frame, k, px) {
  frame.chamber[k] = px.code;
  frame.image[3 * k] = px.rgb[0]; frame.image[3 * k + 1] = px.rgb[1]; frame.image[3 * k + 2] = px.rgb[2];
  if (px.code === SPHERE_A) {
    frame.grad[2 * k] = px.grad[0]; frame.grad[2 * k + 1] = px.grad[1];
    frame.uv[2 * k] = px.uvs[0]; frame.uv[2 * k + 1] = px.uvs[1];
    frame.kink[k] = px.kink ? 1 : 0;
  }
}

// Render the Chapter-9 scene (render.py `render`) with the gradient "exact",
// "central" (step scene.eps) or "footprint" (the pixel's footprint in the
// chart).  `scene` holds the fields of renderer.Scene (DEFAULT_SCENE's names).
// Returns a frame (see `new_frame`).  Throws RangeError naming the argument
// for a bad size, gradient, zoom or height field.
export function render(scene, width, height, gradient = "exact", zoom = 1.0) {
  check_args(width, height, gradient, zoom);
  const s = params(scene);
  const { x, y, dx, dy, sin_x, sin_y } = camera(scene, width, height, zoom);
  const method = GRADIENTS.indexOf(gradient);
  const frame = new_frame(width, height, gradient);
  const px = new Pixel();
  for (let j = 0; j < height; j++) {
    for (let i = 0; i < width; i++) {
      geometry(s, x[i], y[j], sin_x[i] * sin_y[j], px);
      shade_pixel(s, method, scene.eps, x[i], y[j], dx, dy, px);
      store(frame, j * width + i, px);
    }
  }
  return frame;
}

// A numeric pipeline ("central" or "footprint") and the symbolic one ("exact")
// in one pass: { numeric, symbolic }, each equal to `render`'s frame bit for
// bit (tests/test_js_parity.py).  The geometry is computed once per pixel and
// pixels off sphere A are shaded once: they do not depend on the gradient
// (theorem "bump moves no boundary").
export function render_pair(scene, width, height, zoom = 1.0, numeric = "central") {
  check_args(width, height, numeric, zoom);
  if (numeric === "exact") throw new RangeError("numeric must be a numeric gradient (central or footprint), got exact");
  const s = params(scene);
  const { x, y, dx, dy, sin_x, sin_y } = camera(scene, width, height, zoom);
  const method = GRADIENTS.indexOf(numeric);
  const frames = { numeric: new_frame(width, height, numeric), symbolic: new_frame(width, height, "exact") };
  const px = new Pixel();
  for (let j = 0; j < height; j++) {
    for (let i = 0; i < width; i++) {
      const k = j * width + i;
      geometry(s, x[i], y[j], sin_x[i] * sin_y[j], px);
      shade_pixel(s, method, scene.eps, x[i], y[j], dx, dy, px);
      store(frames.numeric, k, px);
      if (px.code === SPHERE_A) shade_pixel(s, EXACT, scene.eps, x[i], y[j], dx, dy, px);
      store(frames.symbolic, k, px);
    }
  }
  return frames;
}

// Everything both pipelines compute for pixel (column i, row j) of a
// width x height frame: the readout behind the simulator's hover.
export function probe_pixel(scene, width, height, i, j, zoom = 1.0, numeric = "central") {
  check_args(width, height, numeric, zoom);
  const s = params(scene);
  const { x, y, dx, dy, sin_x, sin_y } = camera(scene, width, height, zoom);
  const record = (gradient) => {
    const px = new Pixel();
    geometry(s, x[i], y[j], sin_x[i] * sin_y[j], px);
    shade_pixel(s, GRADIENTS.indexOf(gradient), scene.eps, x[i], y[j], dx, dy, px);
    const on_a = px.code === SPHERE_A;
    return { gradient, chamber: px.code, P: px.code === BACKGROUND ? null : Array.from(px.P),
             uv: on_a ? [px.uvs[0], px.uvs[1]] : null, grad: on_a ? [px.grad[0], px.grad[1]] : null,
             steps: on_a && gradient !== "exact" ? Array.from(px.steps) : null,
             kink: on_a && px.kink, rgb: Array.from(px.rgb) };
  };
  return { i, j, X: x[i], Y: y[j], numeric: record(numeric), symbolic: record("exact") };
}
