// One progress bar for a whole job. The server reports each stage's own fraction
// (calibration: lens / frame lights / lasers, scan, then the reconstruction's
// neighbours, normals, orientation, kernels, field, mesh, done); the bar gives
// each stage its share of a typical job's time on the thesis rig.

/** @type {[stage: string, from: number, to: number, text: string][]} */
const SPANS = [
  ['starting', 0, 0, 'Starting'],
  ['calibration: lens', 0, 0.04, 'Calibrating: lenses'],
  ['calibration: frame lights', 0.04, 0.06, 'Calibrating: frame lights'],
  ['calibration: lasers', 0.06, 0.1, 'Calibrating: lasers'],
  ['scan', 0.1, 0.7, 'Scanning: the lasers sweep, hold still'],
  ['neighbours', 0.7, 0.72, 'Building the surface'],
  ['normals', 0.72, 0.75, 'Building the surface'],
  ['orientation', 0.75, 0.78, 'Building the surface'],
  ['kernels', 0.78, 0.8, 'Building the surface'],
  ['field', 0.8, 0.92, 'Building the surface'],
  ['mesh', 0.92, 0.97, 'Building the surface'],
  ['done', 0.97, 0.99, 'Measuring and saving'],
];
const BY_STAGE = new Map(SPANS.map(([stage, a, b, text]) => [stage, { a, b, text }]));

// The share of the whole job in [a, b] that `kind` covers.
const KIND_RANGE = { scan: [0, 1], calibrate: [0, 0.1], reprocess: [0.7, 1], posture_check: [0, 1] };

export function overallFraction(kind, stage, fraction) {
  const s = BY_STAGE.get(stage);
  const f = Math.min(1, Math.max(0, Number.isFinite(fraction) ? fraction : 0));
  const [lo, hi] = KIND_RANGE[kind] || [0, 1];
  if (!s) return null;
  const x = s.a + (s.b - s.a) * f;
  return Math.min(1, Math.max(0, (x - lo) / (hi - lo)));
}

export function stageText(stage) {
  const s = BY_STAGE.get(stage);
  return s ? s.text : stage || 'Working';
}

// The time left, from the bar's position and the time the job has run: the bar's
// spans are shares of a typical job's time, so the rest takes as long again per
// share. Null (nothing to show) until the bar has moved 5 %, or without a clock.
/**
 * @param {number} fraction the bar's position, 0-1
 * @param {number} elapsedSeconds since the job started
 * @returns {string | null}
 */
export function timeLeftText(fraction, elapsedSeconds) {
  if (!(fraction >= 0.05) || !(elapsedSeconds > 0) || fraction >= 1) return null;
  const left = (elapsedSeconds * (1 - fraction)) / fraction;
  if (left < 60) return `about ${Math.max(5, Math.round(left / 5) * 5)} s left`;
  return `about ${Math.round(left / 60)} min left`;
}
