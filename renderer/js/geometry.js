// Camera, ray intersection, chart and tangent frame: the JavaScript twin of
// renderer/geometry.py.  Same names, same formulas, same order of operations
// (so +, -, *, / and sqrt round identically); one point per call instead of
// arrays.  Everything here depends on geometry alone.
import { POLE_SIN_PHI, WINDOW_MARGIN, WINDOW_OFFSET } from "./constants.js";
import { det_atan2 } from "./detmath.js";

// Pixel centres on the image plane z = 0 (geometry.py `image_plane`), scaled
// by 1/zoom about the optical axis (x = y = 0, where sphere A's pole is seen).
// Returns { x: Float64Array(width), y: Float64Array(height) }.
export function image_plane(radius_a, camera_z, width, height, zoom = 1.0) {
  const half = WINDOW_MARGIN * camera_z * radius_a / Math.sqrt(camera_z * camera_z - radius_a * radius_a);
  const x = new Float64Array(width);
  const y = new Float64Array(height);
  for (let i = 0; i < width; i++) x[i] = half * (2.0 * (i + 0.5) / width - 1.0) / zoom;
  for (let j = 0; j < height; j++) y[j] = (half * (1.0 - 2.0 * (j + 0.5) / height) - WINDOW_OFFSET * half) / zoom;
  return { x, y };
}

function copysign(s, b) {
  return (b < 0 || Object.is(b, -0)) ? -s : s;
}

function fmin(a, b) {
  if (Number.isNaN(a)) return b;
  if (Number.isNaN(b)) return a;
  return a < b ? a : b;
}

function fmax(a, b) {
  if (Number.isNaN(a)) return b;
  if (Number.isNaN(b)) return a;
  return a > b ? a : b;
}

// Nearest positive t of the ray from (0, 0, camera_z) through (x, y, 0), or
// Infinity (geometry.py `sphere_hit`: stable roots, discriminant from the
// distance of the centre to the ray's line).
export function sphere_hit(x, y, camera_z, center, radius) {
  const ocx = 0.0 - center[0], ocy = 0.0 - center[1], ocz = camera_z - center[2];
  const a = x * x + y * y + camera_z * camera_z;
  const b = x * ocx + y * ocy - camera_z * ocz;
  const c = ocx * ocx + ocy * ocy + ocz * ocz - radius * radius;
  const f = b / a;
  const lx = ocx - f * x, ly = ocy - f * y, lz = ocz + f * camera_z;
  const disc = a * (radius * radius - (lx * lx + ly * ly + lz * lz));
  if (!(disc >= 0.0)) return Infinity;
  const q = -(b + copysign(Math.sqrt(disc), b));
  const t0 = q / a;
  const t1 = c / q;
  const near = fmin(t0, t1);
  const far = fmax(t0, t1);
  return near > 0.0 ? near : (far > 0.0 ? far : Infinity);
}

// Sphere-A chart of a unit normal (geometry.py `chart`): writes
// [u, v, sin_phi] into out and returns it.  atan2 is the deterministic one
// (detmath.js), so (u, v) are the same bits as in Python.
export function chart(Nx, Ny, Nz, out = new Float64Array(3)) {
  const sin_phi = Math.sqrt(Nx * Nx + Ny * Ny);
  out[0] = (det_atan2(Ny, Nx) + Math.PI) / (2.0 * Math.PI);
  out[1] = det_atan2(sin_phi, Nz) / Math.PI;
  out[2] = sin_phi;
  return out;
}

// The chart's tangent pair with its pole fallback (geometry.py
// `tangent_frame`): writes e_theta and e_phi, [x, y, z] each.
export function tangent_frame(Nx, Ny, Nz, sin_phi, e_theta = new Float64Array(3), e_phi = new Float64Array(3)) {
  if (!(sin_phi > POLE_SIN_PHI)) {
    e_theta[0] = 1.0; e_theta[1] = 0.0; e_theta[2] = 0.0;
    e_phi[0] = 0.0; e_phi[1] = 1.0; e_phi[2] = 0.0;
    return;
  }
  const inv = 1.0 / sin_phi;
  const zx = Nz * inv;
  e_theta[0] = -Ny * inv; e_theta[1] = Nx * inv; e_theta[2] = 0.0;
  e_phi[0] = zx * Nx; e_phi[1] = zx * Ny; e_phi[2] = -sin_phi;
}

// Does the segment from P to the light L meet the sphere?  w = L - P and
// w2 = |w|^2 (geometry.py `segment_hits_sphere`).
export function segment_hits_sphere(wx, wy, wz, w2, L, center, radius) {
  const dx = L[0] - center[0], dy = L[1] - center[1], dz = L[2] - center[2];
  const k = dx * dx + dy * dy + dz * dz - radius * radius;
  if (k < 0.0) return true;
  const g = wx * dx + wy * dy + wz * dz;
  if (k === 0.0) return (g > 0.0) && (2.0 * g < w2);
  return (g > 0.0) && (g < w2) && (g * g >= w2 * k);
}
