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

// Hit point of the ray through (x, y) on sphere A (centre 0, radius r) into P
// (kernel.py `sphere_a_point`): t = c / q and 1 - t = (r^2 + sqrt(disc)) / q,
// free of the cancellation of e (1 - t) where t is near 1.
function sphere_a_point(x, y, e, r, P) {
  const rho2 = x * x + y * y;
  const root = Math.sqrt(Math.max((rho2 + e * e) * r * r - e * e * rho2, 0.0));
  const q = e * e + root;
  const t = (e - r) * (e + r) / q;
  P[0] = t * x; P[1] = t * y; P[2] = e * ((r * r + root) / q);
}

// Hit point P, geometric normal N (unit) and albedo of a hit (geometry only).
// `checker` = sin(pi x) sin(pi y): a floor hit is the pixel centre (x, y, 0)
// itself (t = 1), so the caller takes the sines once per column and row.
function surface(s, x, y, checker, px) {
  const t = px.t, P = px.P, N = px.N, albedo = px.albedo;
  if (px.code === SPHERE_A) {
    const r = s.radius_a;
    sphere_a_point(x, y, s.camera_z, r, P);
    N[0] = P[0] / r; N[1] = P[1] / r; N[2] = P[2] / r;
    albedo.set(s.albedo_a);
    return;
  }
  P[0] = t * x; P[1] = t * y; P[2] = s.camera_z * (1.0 - t);
  if (px.code === SPHERE_B) {
    // P - C over its own length: it carries the rounding of E - C (kernel.py `surface`).
    const c = s.center_b;
    const nx = P[0] - c[0], ny = P[1] - c[1], nz = P[2] - c[2];
    const inv = 1.0 / Math.sqrt(nx * nx + ny * ny + nz * nz);
    N[0] = nx * inv; N[1] = ny * inv; N[2] = nz * inv;
    albedo.set(s.albedo_b);
  } else {
    // Checker: light squares where sin(pi x) sin(pi y) >= 0 (seed Cell 1).
    const base = checker >= 0.0 ? FLOOR_LIGHT : FLOOR_DARK;
    const rg = base * (1.0 - s.floor_tint);
    N[0] = 0.0; N[1] = 0.0; N[2] = 1.0;
    albedo[0] = rg; albedo[1] = rg; albedo[2] = base;
  }
}

// (wx, wy, wz) / |w| into `w`, given w2 = |w|^2 as computed (kernel.py
// `unit_vector`): below the smallest normal double (a light within its square
// root of the point it lights) w is first divided by its largest component.
const NORMAL_MIN = 2 ** -1022;
function unit_vector(wx, wy, wz, w2, w) {
  if (w2 < NORMAL_MIN) {
    const m = Math.max(Math.abs(wx), Math.abs(wy), Math.abs(wz));
    wx /= m; wy /= m; wz /= m;
    w2 = wx * wx + wy * wy + wz * wz;
  }
  const inv = 1.0 / Math.sqrt(w2);
  w[0] = wx * inv; w[1] = wy * inv; w[2] = wz * inv;
}

// Does light L reach P?  The geometric normal faces it (attached shadow), the
// floor plane does not separate them (floor on, P off the floor), and no
// blocker sphere (B for A, A for B, both for the floor) cuts the segment (cast
// shadow): geometry only.  With `gate`, Ns . w > 0 is asked first (else the
// light adds nothing, no shadow ray is traced and false is returned).  Writes
// the unit vector w from P to L into `w` once it is known.
function reach(s, L, P, N, code, Ns, w, gate = true) {
  const wx = L[0] - P[0], wy = L[1] - P[1], wz = L[2] - P[2];
  if (!(N[0] * wx + N[1] * wy + N[2] * wz > 0.0)) return false;
  if (s.floor && code !== FLOOR && ((L[2] < 0.0 && P[2] > 0.0) || (L[2] > 0.0 && P[2] < 0.0))) return false;
  const w2 = wx * wx + wy * wy + wz * wz;
  unit_vector(wx, wy, wz, w2, w);
  if (gate && !(Ns[0] * w[0] + Ns[1] * w[1] + Ns[2] * w[2] > 0.0)) return false;
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
  for (let e = n; e !== 0; e >>= 1) {      // n < 2^31 (Scene: shininess <= 1e4)
    if (e & 1) r *= a;
    a *= a;
  }
  return r;
}

// Add a light's Lambert and Blinn/Phong terms at a point it reaches to rgb:
// the unit vector w to the light and its `specular_axis` (axis, wv), the
// vectors at offset `o` of `w` and `axis`.
function light_term(s, color, w, axis, o, wv, Ns, albedo, rgb) {
  const mu = Ns[0] * w[o] + Ns[1] * w[o + 1] + Ns[2] * w[o + 2];
  if (!(mu > 0.0)) return;
  let spec_cos = Ns[0] * axis[o] + Ns[1] * axis[o + 1] + Ns[2] * axis[o + 2];
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
      light_term(s, s.lights[k].color, px.w, px.axis, 0, wv, px.Ns, px.albedo, rgb);
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

// N' of sphere A into Ns (formulas.py `PERTURBED_NORMAL`) from the normal at
// offset n of N, the tangent frame at offset f of F, the gradient (hu, hv),
// and the height h and sin(phi) (read by the surface bump only).
function shading_normal(s, N, n, F, f, hu, hv, h, sin_phi, Ns) {
  if (s.surface) {
    perturbed_normal_surface(N[n], N[n + 1], N[n + 2], F[f], F[f + 1], F[f + 2], F[f + 3], F[f + 4], F[f + 5],
                             hu, hv, s.beta, h, s.radius_a, sin_phi, Ns);
    return;
  }
  perturbed_normal_chart(N[n], N[n + 1], N[n + 2], F[f], F[f + 1], F[f + 2], F[f + 3], F[f + 4], F[f + 5],
                         hu, hv, s.beta, Ns);
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
  if (scene.bump === "surface" && !(scene.beta < scene.radius_a)) {     // scene.py: R + beta h > 0
    throw new RangeError(`beta must be < radius_a = ${scene.radius_a} when bump is "surface", got ${scene.beta}`);
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
    const h = s.surface ? height(s.field, px.uvs[0], px.uvs[1], s.k_u, s.k_v) : 0.0;
    shading_normal(s, px.N, 0, px.frame, 0, px.grad[0], px.grad[1], h, px.uvs[2], px.Ns);
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

// ---- geometry kept between frames: re-shading sphere A -----------------------------
//
// Theorem "bump moves no boundary": what a pixel sees, its hit point, normal,
// chart and tangent frame, and which lights reach it on geometry alone do not
// depend on the bump.  A G-buffer keeps them for a frame; `shade_a` shades
// sphere A on it for any values of the bump's fields (kernel.py `render_row`
// does the same for an eps sweep), bit for bit what `render` gives
// (tests/test_js_reshade.py).

// The Scene fields a G-buffer does not depend on.
export const BUMP_FIELDS = ["height_field", "k_u", "k_v", "beta", "eps", "bump"];

// The geometry of a width x height frame of `scene`: `chamber` (H*W), `image`
// (H*W*3: the final colour of every pixel off sphere A, 0 on it), `uv` (H*W*2,
// sphere A's chart), and per pixel a of sphere A (row-major; `pixels[a]` its
// index in the frame): N (3), uvs (3: u, v, sin phi), frame (6: e_theta,
// e_phi), steps (2: the footprint's), and per light l (index q = a * lights + l)
// lit[q] (it reaches the point on geometry alone: `reach` ungated), w (3, the
// unit vector to it), axis (3) and wv (its `specular_axis`).  Throws RangeError
// as `render` does.
export function gbuffer(scene, width, height, zoom = 1.0) {
  check_args(width, height, "exact", zoom);
  const s = params(scene);
  const { x, y, dx, dy, sin_x, sin_y } = camera(scene, width, height, zoom);
  const n = width * height, nl = s.lights.length;
  const chamber = new Uint8Array(n), t = new Float64Array(n);
  const px = new Pixel();
  let m = 0;
  for (let j = 0; j < height; j++) {
    for (let i = 0; i < width; i++) {
      nearest_hit(s, x[i], y[j], px);
      chamber[j * width + i] = px.code; t[j * width + i] = px.t;
      if (px.code === SPHERE_A) m++;
    }
  }
  const gb = { scene: { ...scene }, s, width, height, zoom, lights: nl, chamber,
               image: new Float64Array(3 * n), uv: new Float64Array(2 * n), pixels: new Int32Array(m),
               N: new Float64Array(3 * m), uvs: new Float64Array(3 * m), frame: new Float64Array(6 * m),
               steps: new Float64Array(2 * m), lit: new Uint8Array(m * nl), w: new Float64Array(3 * m * nl),
               axis: new Float64Array(3 * m * nl), wv: new Float64Array(m * nl), terms: null, along: new Map() };
  let a = 0;
  for (let j = 0; j < height; j++) {
    for (let i = 0; i < width; i++) {
      const k = j * width + i;
      px.code = chamber[k]; px.t = t[k];
      if (px.code === BACKGROUND) continue;                 // black
      surface(s, x[i], y[j], sin_x[i] * sin_y[j], px);
      if (px.code !== SPHERE_A) {
        px.Ns.set(px.N);
        shade(s, px);
        gb.image.set(px.rgb, 3 * k);
        continue;
      }
      const N = px.N, f = px.frame;
      chart(N[0], N[1], N[2], px.uvs);
      tangent_frame(N[0], N[1], N[2], px.uvs[2], f);
      footprint(x[i], y[j], dx, dy, s.camera_z, px.P[0], px.P[1], px.P[2], N[0], N[1], N[2],
                f[0], f[1], f[2], f[3], f[4], f[5], s.radius_a, px.uvs[2], px.steps);
      view_vector(s, px.P, px.view);
      for (let l = 0; l < nl; l++) {
        const q = a * nl + l;
        gb.lit[q] = reach(s, s.lights[l].position, px.P, N, SPHERE_A, null, px.w, false) ? 1 : 0;
        if (!gb.lit[q]) continue;
        gb.wv[q] = specular_axis(s, px.w, px.view, px.axis);
        gb.w.set(px.w, 3 * q); gb.axis.set(px.axis, 3 * q);
      }
      gb.pixels[a] = k;
      gb.N.set(N, 3 * a); gb.uvs.set(px.uvs, 3 * a); gb.frame.set(f, 6 * a); gb.steps.set(px.steps, 2 * a);
      gb.uv[2 * k] = px.uvs[0]; gb.uv[2 * k + 1] = px.uvs[1];
      a++;
    }
  }
  return gb;
}

// `scene`'s kernel parameters, after checking that it has the G-buffer's geometry:
// RangeError naming the first field (outside BUMP_FIELDS) that differs.
function bump_params(gb, scene) {
  for (const name of Object.keys(gb.scene)) {
    if (!BUMP_FIELDS.includes(name) && JSON.stringify(scene[name]) !== JSON.stringify(gb.scene[name])) {
      throw new RangeError(`scene.${name} is ${JSON.stringify(scene[name])}, but the G-buffer was made with ` +
                           `${JSON.stringify(gb.scene[name])}: only ${BUMP_FIELDS.join(", ")} may change`);
    }
  }
  return params(scene);
}

// The height field's terms on sphere A, kept in the G-buffer while the field
// and its frequencies stay: the crease flag (H*W), and per pixel of A the
// height h and the exact gradient (2).
function field_terms(gb, s) {
  const key = `${s.field} ${s.k_u} ${s.k_v}`;
  if (gb.terms !== null && gb.terms.key === key) return gb.terms;
  const m = gb.pixels.length, uvs = gb.uvs, out = new Float64Array(2);
  const terms = { key, kink: new Uint8Array(gb.chamber.length), h: new Float64Array(m), grad: new Float64Array(2 * m) };
  for (let a = 0; a < m; a++) {
    const u = uvs[3 * a], v = uvs[3 * a + 1];
    terms.kink[gb.pixels[a]] = kink_band(s.field, u, v, s.k_u, s.k_v) ? 1 : 0;
    terms.h[a] = height(s.field, u, v, s.k_u, s.k_v);
    exact_gradient(s.field, u, v, s.k_u, s.k_v, out);
    terms.grad[2 * a] = out[0]; terms.grad[2 * a + 1] = out[1];
  }
  gb.terms = terms;
  return terms;
}

// (h_u, h_v) of pixel a of sphere A by gradient `method` into out (`gradient`
// on the kept geometry).
function gradient_a(gb, s, terms, a, method, eps, out) {
  if (method === EXACT) {
    out[0] = terms.grad[2 * a]; out[1] = terms.grad[2 * a + 1];
    return;
  }
  const u = gb.uvs[3 * a], v = gb.uvs[3 * a + 1];
  if (method === CENTRAL) central_gradient(s.field, u, v, s.k_u, s.k_v, eps, eps, out);
  else central_gradient(s.field, u, v, s.k_u, s.k_v, gb.steps[2 * a], gb.steps[2 * a + 1], out);
}

// Pixel a of sphere A with the gradient (hu, hv): the shading normal into
// px.Ns and the colour into px.rgb (`shading_normal` and `shade` on the kept
// geometry: `light_term` for every light that reaches the point on geometry
// alone, which adds nothing where Ns . w <= 0).
function shade_a_pixel(gb, s, terms, a, hu, hv, px) {
  shading_normal(s, gb.N, 3 * a, gb.frame, 6 * a, hu, hv, terms.h[a], gb.uvs[3 * a + 2], px.Ns);
  const rgb = px.rgb, nl = gb.lights;
  for (let c = 0; c < 3; c++) rgb[c] = s.ka * s.ambient[c];
  for (let l = 0; l < nl; l++) {
    const q = a * nl + l;
    if (gb.lit[q]) light_term(s, s.lights[l].color, gb.w, gb.axis, 3 * q, gb.wv[q], px.Ns, s.albedo_a, rgb);
  }
  for (let c = 0; c < 3; c++) rgb[c] = Math.min(Math.max(rgb[c], 0.0), 1.0);
}

// The frame of `scene` by `gradient` on the G-buffer `gb` (see `new_frame`):
// only sphere A is shaded; `scene` may differ from gb's in BUMP_FIELDS only
// (else RangeError).  `grad`, if given, is the gradient to shade with (H*W*2,
// a frame's `grad`): the caller vouches that it is this scene's by `gradient`
// (`PairRenderer` passes it when only beta or bump changed).  The frame shares
// gb's chamber and uv arrays.
export function shade_a(gb, scene, gradient, grad = null) {
  check_args(gb.width, gb.height, gradient, gb.zoom);
  const s = bump_params(gb, scene), terms = field_terms(gb, s), method = GRADIENTS.indexOf(gradient);
  const frame = { image: gb.image.slice(), chamber: gb.chamber, kink: terms.kink,
                  grad: grad === null ? new Float64Array(2 * gb.chamber.length) : grad, uv: gb.uv,
                  width: gb.width, height: gb.height, gradient };
  const px = new Pixel(), g = px.grad;
  for (let a = 0; a < gb.pixels.length; a++) {
    const k = gb.pixels[a];
    if (grad === null) {
      gradient_a(gb, s, terms, a, method, scene.eps, g);
      frame.grad[2 * k] = g[0]; frame.grad[2 * k + 1] = g[1];
    }
    shade_a_pixel(gb, s, terms, a, frame.grad[2 * k], frame.grad[2 * k + 1], px);
    frame.image[3 * k] = px.rgb[0]; frame.image[3 * k + 1] = px.rgb[1]; frame.image[3 * k + 2] = px.rgb[2];
  }
  return frame;
}

// The ledger (ledger.js `compare`: max and RMS of |I_numeric - I_symbolic| on
// sphere A) of the central pipeline at each step of `eps_list` against the
// frame `symbolic`, over the pixels of sphere A whose column and row are
// multiples of `stride`: [{ eps, max_abs, rms, pixels_a }].  With stride 1 it is
// `compare` of the full frames, bit for bit.  With `keep`, the gradients at
// these pixels and steps are kept in gb, per height field, k_u, k_v, list of
// steps and stride: a change of beta or bump re-shades with them.
export function ledger_along_eps(gb, scene, symbolic, eps_list, stride = 1, keep = true) {
  if (!(Number.isInteger(stride) && stride >= 1)) throw new RangeError(`stride must be an integer >= 1, got ${stride}`);
  const s = bump_params(gb, scene), terms = field_terms(gb, s), px = new Pixel();
  const key = JSON.stringify([terms.key, eps_list, stride]);
  if (!keep || !gb.along.has(key)) {
    const sample = [];
    gb.pixels.forEach((k, a) => {
      if ((k % gb.width) % stride === 0 && Math.floor(k / gb.width) % stride === 0) sample.push(a);
    });
    const grads = new Float64Array(2 * sample.length * eps_list.length);
    eps_list.forEach((eps, e) => sample.forEach((a, i) => {
      gradient_a(gb, s, terms, a, CENTRAL, eps, px.grad);
      grads.set(px.grad, 2 * (e * sample.length + i));
    }));
    if (!keep) return along(gb, s, terms, symbolic, eps_list, sample, grads, px);
    if (gb.along.size >= 4) gb.along.clear();             // fields or strides have changed: start afresh
    gb.along.set(key, { sample, grads });
  }
  const { sample, grads } = gb.along.get(key);
  return along(gb, s, terms, symbolic, eps_list, sample, grads, px);
}

// `ledger_along_eps` on the gradients `grads` at the pixels `sample` of sphere A.
function along(gb, s, terms, symbolic, eps_list, sample, grads, px) {
  return eps_list.map((eps, e) => {
    let max_abs = 0.0, sum2 = 0.0;
    sample.forEach((a, i) => {
      const o = 2 * (e * sample.length + i), k = gb.pixels[a];
      shade_a_pixel(gb, s, terms, a, grads[o], grads[o + 1], px);
      for (let c = 0; c < 3; c++) {
        const d = Math.abs(px.rgb[c] - symbolic.image[3 * k + c]);
        if (d > max_abs) max_abs = d;
        sum2 += d * d;
      }
    });
    return { eps, max_abs, rms: sample.length ? Math.sqrt(sum2 / (3 * sample.length)) : 0.0, pixels_a: sample.length };
  });
}

// The simulator's two frames, a numeric pipeline ("central" or "footprint")
// and the symbolic one ("exact"), with memory: `update` makes a new G-buffer
// only when the geometry changes (size, zoom, or a Scene field outside
// BUMP_FIELDS), and re-shades a pipeline only when its inputs change (the
// symbolic one: the height field, k_u, k_v, beta, bump; the numeric one also
// its gradient and, for "central", eps).  Each frame equals `render`'s bit for
// bit (tests/test_js_reshade.py).
export class PairRenderer {
  constructor() { this.gb = null; this.keys = {}; this.frames = { numeric: null, symbolic: null }; }

  // { numeric, symbolic, full: whether the geometry was computed afresh,
  //   shaded: the pipelines shaded by this call }.
  update(scene, width, height, zoom = 1.0, numeric = "central") {
    check_args(width, height, numeric, zoom);
    if (numeric === "exact") throw new RangeError("numeric must be a numeric gradient (central or footprint), got exact");
    const geometry = JSON.stringify([width, height, zoom,
                                     Object.entries(scene).filter(([name]) => !BUMP_FIELDS.includes(name))]);
    const full = geometry !== this.keys.geometry;
    if (full) {
      this.gb = gbuffer(scene, width, height, zoom);
      this.keys = { geometry };
    }
    // What each pipeline's gradient depends on, and what its colours depend on.
    const grads = { symbolic: [scene.height_field, scene.k_u, scene.k_v],
                    numeric: [scene.height_field, scene.k_u, scene.k_v, numeric, numeric === "central" ? scene.eps : null] };
    const shaded = [];
    for (const [name, gradient] of [["symbolic", "exact"], ["numeric", numeric]]) {
      const grad = JSON.stringify(grads[name]), key = JSON.stringify([grad, scene.beta, scene.bump]);
      if (key === this.keys[name]) continue;
      const same = this.frames[name] !== null && grad === this.keys[name + "_grad"];
      this.frames[name] = shade_a(this.gb, scene, gradient, same ? this.frames[name].grad : null);
      this.keys[name] = key;
      this.keys[name + "_grad"] = grad;
      shaded.push(name);
    }
    this.scene = { ...scene };
    return { ...this.frames, full, shaded };
  }

  // `ledger_along_eps` of the central pipeline on the current G-buffer and symbolic frame.
  ledger_along_eps(eps_list, stride = 1, keep = true) {
    return ledger_along_eps(this.gb, this.scene, this.frames.symbolic, eps_list, stride, keep);
  }
}

// A numeric pipeline ("central" or "footprint") and the symbolic one ("exact")
// from one G-buffer: { numeric, symbolic }, each equal to `render`'s frame bit
// for bit (tests/test_js_parity.py).
export function render_pair(scene, width, height, zoom = 1.0, numeric = "central") {
  const { numeric: n, symbolic } = new PairRenderer().update(scene, width, height, zoom, numeric);
  return { numeric: n, symbolic };
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
