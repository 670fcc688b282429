// Comparing the two pipelines: the JavaScript twin of renderer/ledger.py.
import { SPHERE_A } from "./constants.js";

// Ledger of two frames from `render` (ledger.py `compare`): max and RMS of
// |I_numeric - I_symbolic| over the colour channels of the pixels that are
// sphere A in both frames, flips (pixels whose chamber differs), pixels_a,
// and the mean |dI| on and off the crease band (NaN where a set is empty).
export function compare(numeric, symbolic) {
  if (numeric.image.length !== symbolic.image.length) {
    throw new RangeError(`frames must have the same size, got ${numeric.image.length / 3} and ${symbolic.image.length / 3} pixels`);
  }
  const n = numeric.chamber.length;
  let max_abs = 0.0, sum2 = 0.0, flips = 0, pixels_a = 0;
  let sum_kink = 0.0, n_kink = 0, sum_off = 0.0, n_off = 0;
  for (let k = 0; k < n; k++) {
    if (numeric.chamber[k] !== symbolic.chamber[k]) flips++;
    if (numeric.chamber[k] !== SPHERE_A || symbolic.chamber[k] !== SPHERE_A) continue;
    pixels_a++;
    for (let c = 0; c < 3; c++) {
      const d = Math.abs(numeric.image[3 * k + c] - symbolic.image[3 * k + c]);
      if (d > max_abs) max_abs = d;
      sum2 += d * d;
      if (symbolic.kink[k]) { sum_kink += d; n_kink++; } else { sum_off += d; n_off++; }
    }
  }
  return {
    max_abs,
    rms: pixels_a ? Math.sqrt(sum2 / (3 * pixels_a)) : 0.0,
    flips,
    pixels_a,
    mean_abs_kink: n_kink ? sum_kink / n_kink : NaN,
    mean_abs_off_kink: n_off ? sum_off / n_off : NaN,
  };
}

// sRGB transfer curve (IEC 61966-2-1) of one linear value (ledger.py `to_srgb`).
export function to_srgb(linear) {
  const c = Math.max(linear, 0.0);
  return c <= 0.0031308 ? 12.92 * c : 1.055 * Math.pow(c, 1.0 / 2.4) - 0.055;
}
