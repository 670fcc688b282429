// Deterministic sine and atan2: renderer/detmath.py, operation for operation.
// Only +, -, *, /, sqrt and floor, which IEEE 754 rounds exactly, so this file
// and numpy give the same bits.  fdlibm's algorithms (FreeBSD msun
// e_rem_pio2.c, k_sin.c, k_cos.c, s_atan.c, e_atan2.c); see detmath.py for why.

const INVPIO2 = 6.36619772367581382433e-01;
const PIO2_1 = 1.57079632673412561417e+00;
const PIO2_2 = 6.07710050630396597660e-11;
const PIO2_2T = 2.02226624879595063154e-21;
const S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03, S3 = -1.98412698298579493134e-04;
const S4 = 2.75573137070700676789e-06, S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
const C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03, C3 = 2.48015872894767294178e-05;
const C4 = -2.75573143513906633035e-07, C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
const ATANHI = [4.63647609000806093515e-01, 7.85398163397448278999e-01,
                9.82793723247329054082e-01, 1.57079632679489655800e+00];
const ATANLO = [2.26987774529616870924e-17, 3.06161699786838301793e-17,
                1.39033110312309984516e-17, 6.12323399573676603587e-17];
const AT = [3.33333333333329318027e-01, -1.99999999998764832476e-01, 1.42857142725034663711e-01,
            -1.11111104054623557880e-01, 9.09088713343650656196e-02, -7.69187620504482999495e-02,
            6.66107313738753120669e-02, -5.83357013379057348645e-02, 4.97687799461593236017e-02,
            -3.65315727442169155270e-02, 1.62858201153657823623e-02];
const PI = 3.1415926535897931160e+00;
const PI_LO = 1.2246467991473531772e-16;
const PI_O_2 = 1.5707963267948965580e+00;

function kernel_sin(x, y) {
  const z = x * x;
  const w = z * z;
  const r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
  const v = z * x;
  return x - ((z * (0.5 * y - v * r) - y) - v * S1);
}

function kernel_cos(x, y) {
  const z = x * x;
  let w = z * z;
  const r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
  const hz = 0.5 * z;
  w = 1.0 - hz;
  return w + (((1.0 - w) - hz) + (z * r - x * y));
}

// Deterministic sine (detmath.py `sin`).
export function det_sin(x) {
  const fn = Math.floor(x * INVPIO2 + 0.5);
  const t = x - fn * PIO2_1;
  let w = fn * PIO2_2;
  const r = t - w;
  w = fn * PIO2_2T - ((t - r) - w);
  const y0 = r - w;
  const y1 = (r - y0) - w;
  let q = fn % 4.0;
  if (q < 0) q += 4.0;
  if (q === 0.0) return kernel_sin(y0, y1);
  if (q === 1.0) return kernel_cos(y0, y1);
  if (q === 2.0) return -kernel_sin(y0, y1);
  if (q === 3.0) return -kernel_cos(y0, y1);
  return NaN;
}

function atan_nonneg(t) {
  let id;
  if (t < 0.4375) id = -1;
  else if (t < 0.6875) { id = 0; t = (2.0 * t - 1.0) / (2.0 + t); }
  else if (t < 1.1875) { id = 1; t = (t - 1.0) / (t + 1.0); }
  else if (t < 2.4375) { id = 2; t = (t - 1.5) / (1.0 + 1.5 * t); }
  else { id = 3; t = -1.0 / t; }
  const z = t * t;
  const w = z * z;
  const s1 = z * (AT[0] + w * (AT[2] + w * (AT[4] + w * (AT[6] + w * (AT[8] + w * AT[10])))));
  const s2 = w * (AT[1] + w * (AT[3] + w * (AT[5] + w * (AT[7] + w * AT[9]))));
  if (id < 0) return t - t * (s1 + s2);
  return ATANHI[id] - ((t * (s1 + s2) - ATANLO[id]) - t);
}

function signbit(a) {
  return a < 0 || Object.is(a, -0);
}

// Deterministic atan2 (detmath.py `atan2`).
export function det_atan2(y, x) {
  if (Number.isNaN(x) || Number.isNaN(y)) return NaN;
  const ny = signbit(y), nx = signbit(x);
  if (x === 0.0 && y === 0.0) return nx ? (ny ? -PI : PI) : (ny ? -0.0 : 0.0);
  if (x === 0.0) return ny ? -PI_O_2 : PI_O_2;
  let ratio = Math.abs(y / x);
  if (Number.isNaN(ratio)) ratio = 0.0;
  const z = atan_nonneg(ratio);
  if (nx) return ny ? (z - PI_LO) - PI : PI - (z - PI_LO);
  return ny ? -z : z;
}
