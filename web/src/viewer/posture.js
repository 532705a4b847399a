// How the customer stood: the posture the server read from the surface, checked
// against the scanning posture the measurement rules assume (docs/measurements.md,
// "Posture"), and a picture of that posture for the customer to copy.
import { h } from '../ui/dom.js';

// The scanning posture the rules assume, as the server checks it
// (recon/measure/body_posture.hpp, kScanningPosture). The picture draws its middle.
export const WANTED = { armMin: 35, armMax: 50, anklesMin: 300, anklesMax: 450 };

const deg = (x) => `${Math.round(x)}°`;

// The posture as lines of text: [{ part, text, ok, message }], in the order a
// person reads a body (arms, feet, head, turn). Parts the server did not find are left out.
export function postureLines(posture) {
  if (!posture) return [];
  const check = new Map((posture.checks || []).map((c) => [c.part, c]));
  const lines = [];
  const arms = posture.arm_abduction_deg || [];
  for (const [i, side] of ['left', 'right'].entries()) {
    if (arms[i] === null || arms[i] === undefined) continue;
    const bend = posture.elbow_bend_deg?.[i];
    const c = check.get(`arm_${side}`) || { ok: true, message: '' };
    lines.push({
      part: `arm_${side}`,
      text: `${side[0].toUpperCase()}${side.slice(1)} arm ${deg(arms[i])} from the body${bend !== null && bend !== undefined ? `, elbow bent ${deg(bend)}` : ''}`,
      ok: c.ok,
      message: c.message,
    });
  }
  if (posture.ankle_distance_mm !== null && posture.ankle_distance_mm !== undefined) {
    const c = check.get('feet') || { ok: true, message: '' };
    lines.push({ part: 'feet', text: `Ankles ${Math.round(posture.ankle_distance_mm / 10)} cm apart`, ok: c.ok, message: c.message });
  }
  if (posture.head_tilt_deg !== null && posture.head_tilt_deg !== undefined) {
    const c = check.get('head') || { ok: true, message: '' };
    const f = posture.head_tilt_deg;
    const s = posture.head_side_tilt_deg || 0;
    const level = Math.abs(f) < 5 && Math.abs(s) < 5;
    lines.push({
      part: 'head',
      text: level ? 'Head level' : `Head tilted ${deg(Math.abs(f))} ${f >= 0 ? 'forward' : 'back'}, ${deg(Math.abs(s))} to the ${s >= 0 ? 'left' : 'right'}`,
      ok: c.ok,
      message: c.message,
    });
  }
  if (typeof posture.turn_deg === 'number') {
    const c = check.get('turn') || { ok: true, message: '' };
    const t = posture.turn_deg;
    lines.push({ part: 'turn', text: Math.abs(t) < 2 ? 'Facing the front' : `Turned ${deg(Math.abs(t))} to their ${t > 0 ? 'left' : 'right'} from the front`, ok: c.ok, message: c.message });
  }
  return lines;
}

// A front view of a standing figure, arms `arms` degrees from the body and the
// feet `ankles` mm apart (inline SVG, scaled to its box).
export function postureFigure({ arms = 42, ankles = 375, label = 'The scanning posture' } = {}) {
  const ns = 'http://www.w3.org/2000/svg';
  const el = (tag, attrs) => {
    const e = document.createElementNS(ns, tag);
    for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
    return e;
  };
  const svg = el('svg', { viewBox: '0 0 200 260', class: 'posture-figure', role: 'img', 'aria-label': label });
  const title = el('title', {});
  title.textContent = label;
  svg.append(title);
  const stroke = { stroke: 'currentColor', 'stroke-width': 9, 'stroke-linecap': 'round', fill: 'none' };
  svg.append(el('circle', { cx: 100, cy: 28, r: 17, fill: 'currentColor' }));
  svg.append(el('line', { x1: 100, y1: 52, x2: 100, y2: 140, ...stroke, 'stroke-width': 26 }));
  const a = (arms * Math.PI) / 180;
  const arm = 95;
  for (const s of [-1, 1]) {
    const x0 = 100 + s * 15;
    svg.append(el('line', { x1: x0, y1: 60, x2: x0 + s * arm * Math.sin(a), y2: 60 + arm * Math.cos(a), ...stroke }));
  }
  // Ankles drawn at their distance on a 1.75 m figure 250 units tall.
  const half = Math.min(70, (ankles / 1750) * 250 * 0.5);
  for (const s of [-1, 1]) {
    svg.append(el('line', { x1: 100 + s * 8, y1: 140, x2: 100 + s * half, y2: 245, ...stroke, 'stroke-width': 12 }));
    svg.append(el('line', { x1: 100 + s * half, y1: 250, x2: 100 + s * (half + 10), y2: 250, ...stroke, 'stroke-width': 7 }));
  }
  return svg;
}

// What the station shows before a scan: the posture to copy, in a picture.
export function wantedPostureCard() {
  return h(
    'figure',
    { class: 'wanted-posture' },
    postureFigure({ arms: (WANTED.armMin + WANTED.armMax) / 2, ankles: (WANTED.anklesMin + WANTED.anklesMax) / 2, label: 'Stand like this' }),
    h(
      'figcaption',
      {},
      h('strong', {}, 'Stand like this'),
      h('small', { class: 'muted' }, ` facing the front, arms ${WANTED.armMin}–${WANTED.armMax}° from the body, ankles ${WANTED.anklesMin / 10}–${WANTED.anklesMax / 10} cm apart, looking ahead`),
    ),
  );
}

// The figure as the customer stood (their arms' mean angle) beside the lines.
function postureHead(posture, label, title) {
  const lines = postureLines(posture);
  const arms = posture.arm_abduction_deg || [];
  const meanArm = arms.filter((x) => typeof x === 'number');
  return h('div', { class: 'posture-head' },
    postureFigure({
      arms: meanArm.length ? meanArm.reduce((s, x) => s + x, 0) / meanArm.length : 42,
      ankles: posture.ankle_distance_mm ?? 375,
      label,
    }),
    h(
      'div',
      {},
      h('h2', {}, title),
      h('ul', { class: 'posture-lines' }, lines.map((l) => h('li', { class: l.ok ? 'ok' : 'warn', dataset: { part: l.part } }, l.text, l.ok ? null : h('small', {}, ` — ${l.message}`)))),
    ),
  );
}

// The station's card after a posture check (the job's posture_check): how the
// customer stands now, and what to ask of them before the scan.
export function postureCheckCard(check) {
  if (!check?.posture) return null;
  const p = check.posture;
  const seconds = (check.acquisition_seconds || 0) + (check.processing_seconds || 0);
  return h(
    'div',
    { class: `posture-card posture-check ${check.ok ? 'ok' : 'warn'}`, id: 'posture-check', dataset: { ok: check.ok ? 'true' : 'false' } },
    postureHead(p, 'How the customer stands', check.ok ? 'Ready to scan' : 'Ask the customer to change how they stand, then check again'),
    h('p', { class: 'muted small' }, `From a quick sweep (${check.frames} frames, ${seconds.toFixed(1)} s). The head is checked by the scan.`),
  );
}

// The viewer's card: how the customer stood and what was outside the posture,
// with the measurements that depend on it.
export function postureCard(posture, measurements = []) {
  if (!posture) return null;
  const flagged = measurements.filter((m) => m.geometry?.outside_posture).map((m) => m.label || m.name);
  return h(
    'div',
    { class: `card posture-card ${posture.ok ? 'ok' : 'warn'}`, id: 'posture', dataset: { ok: posture.ok ? 'true' : 'false' } },
    postureHead(posture, 'How the customer stood', posture.ok ? 'Posture: as the measurements assume' : 'Posture: check before trusting the flagged values'),
    flagged.length
      ? h('p', { class: 'posture-flagged' }, `⚑ ${flagged.length} value${flagged.length > 1 ? 's' : ''} taken outside the posture ${flagged.length > 1 ? 'their definitions assume' : 'its definition assumes'}: ${flagged.join(', ')}. Scan again in the posture shown at the station for the standard's values.`)
      : null,
  );
}
