// The measurement table: the automatic set (ISO 8559-1) and the saved ones,
// each row selecting its line on the body. Values shown in the chosen unit.
import { formatDifference, formatLength } from '../units.js';
import { h } from '../ui/dom.js';

/** @typedef {import('../api.js').StoredMeasurement} StoredMeasurement */

export const KIND_LABEL = {
  girth: 'girth',
  height: 'height',
  distance: 'straight',
  surface_length: 'over skin',
  arc: 'along tape',
};

// Values within this of their reading whatever the filled-in skin under them is
// are not marked (the server's kEstimateThresholdMm, recon/measure/fill_bound.hpp).
export const ESTIMATE_THRESHOLD_MM = 2;

export const FILLED_NOTE = `An estimate: skin the cameras did not see (filled in by the reconstruction) lies under its line and could move it by about the amount shown; check it with a tape if it matters.`;

/**
 * Whether a value is an estimate: the server says so, or (scans archived before it
 * did) its line crosses filled-in skin at all.
 * @param {{ estimated?: boolean, crosses_filled_hole?: boolean }} g the measurement's geometry
 */
export function isEstimate(g) {
  return g.estimated ?? !!g.crosses_filled_hole;
}

/**
 * "±6 mm", "±0.6 cm"; "±?" where the server could not say how much.
 * @param {{ fill_bound_mm?: number | null }} g
 * @param {string} unit
 */
export function fillBoundText(g, unit) {
  return typeof g.fill_bound_mm === 'number' ? `±${formatLength(g.fill_bound_mm, unit)}` : '±?';
}

/**
 * What the marks in a table of `measurements` mean, in sight under it (a tooltip
 * is out of reach on a touch screen); null when no row carries one.
 * @param {StoredMeasurement[]} measurements
 */
export function tableLegend(measurements) {
  const estimates = measurements.some((m) => isEstimate(m.geometry || {}));
  const posture = measurements.some((m) => (m.geometry || {}).outside_posture);
  if (!estimates && !posture) return null;
  return h(
    'dl',
    { class: 'table-legend' },
    estimates ? [h('dt', {}, '≈ ±x'), h('dd', {}, `an estimate: skin the cameras did not see lies under its line and could move it by about x. Values it could move by ${ESTIMATE_THRESHOLD_MM} mm or less are not marked.`)] : null,
    posture ? [h('dt', {}, '⚑'), h('dd', {}, 'taken outside the posture its definition assumes: not the standard’s value.')] : null,
  );
}

export const POSTURE_NOTE = 'Taken outside the posture its definition assumes (see Posture): not the standard’s value.';

export const COLOURS = { selected: 0xd6336c, fresh: 0x0b7a75, compare: 0x7048e8 };

// How far beside the body (mm) a height's rule stands.
const HEIGHT_RULE_GAP = 80;

// Draws a measurement's geometry on a BodyView under `key`. A height is drawn as a
// rule standing beside the body (its vertical line would run through the body's
// inside), its ends marked, with a leader from the landmark it was read at.
export function drawMeasurement(view, key, m, colour = COLOURS.selected) {
  const g = m.geometry || m;
  view.clearOverlays(key);
  const box = view.modelBounds();
  if ((g.kind || m.kind) === 'height' && g.path && g.path.length >= 2 && box) {
    const [low, high] = [...g.path].sort((a, b) => a[1] - b[1]).filter((_, i, all) => i === 0 || i === all.length - 1);
    const x = box.max.x + HEIGHT_RULE_GAP;
    const top = [x, high[1], high[2]];
    const foot = [x, low[1], high[2]];
    view.showPath(`${key}:path`, [foot, top], { color: colour, width: 3.5, onTop: true });
    view.showPath(`${key}:leader`, [high, top], { color: colour, width: 1.5, onTop: true });
    view.showMarker(`${key}:top`, top, { color: colour, radius: 6 });
    view.showMarker(`${key}:foot`, foot, { color: colour, radius: 6 });
    view.showMarker(`${key}:landmark`, high, { color: colour, radius: 5 });
    return;
  }
  if (g.path && g.path.length >= 2) view.showPath(`${key}:path`, g.path, { closed: !!g.closed, color: colour, width: 3.5 });
  const moved = arcEndsMoved(g);
  if (moved) {
    // The arc's ends where the tape put them, each with a thin leader back to
    // the point tapped, so that a shorter arc than the straight distance shows why.
    view.showMarker(`${key}:from`, moved.from, { color: colour, radius: 6 });
    view.showMarker(`${key}:to`, moved.to, { color: colour, radius: 6 });
    view.showMarker(`${key}:tapped-from`, g.from, { color: colour, radius: 3 });
    view.showMarker(`${key}:tapped-to`, g.to, { color: colour, radius: 3 });
    view.showPath(`${key}:moved-from`, [g.from, moved.from], { color: colour, width: 1 });
    view.showPath(`${key}:moved-to`, [g.to, moved.to], { color: colour, width: 1 });
  } else if (g.from && g.to && g.kind !== 'height') {
    view.showMarker(`${key}:from`, g.from, { color: colour, radius: 6 });
    view.showMarker(`${key}:to`, g.to, { color: colour, radius: 6 });
  }
}

// The side of the body a measurement lies on, as the view that shows it: 'back'
// for a length down the back, 'left' for the left arm; null for one that goes
// round the body (a girth) or stands beside it (a height), which any view shows.
// The body faces +Z (the scan frame); `box` is its bounding box.
/**
 * @param {{ kind?: string, geometry?: any, path?: number[][], from?: number[], to?: number[] }} m
 * @param {{ min: { x: number, z: number }, max: { x: number, z: number } } | null} box
 * @returns {'front' | 'back' | 'left' | 'right' | null}
 */
export function sideShowing(m, box) {
  const g = m.geometry || m;
  if (!box || (g.kind || m.kind) === 'height' || g.closed) return null;
  const points = g.path && g.path.length ? g.path : [g.from, g.to].filter(Boolean);
  if (!points.length) return null;
  const cx = (box.min.x + box.max.x) / 2;
  const cz = (box.min.z + box.max.z) / 2;
  // Offsets from the body's axis as fractions of its half-width and half-depth,
  // so that a point on the back and one at the shoulder's tip weigh alike.
  const hx = Math.max(1, (box.max.x - box.min.x) / 2);
  const hz = Math.max(1, (box.max.z - box.min.z) / 2);
  let dx = 0;
  let dz = 0;
  for (const p of points) {
    dx += (p[0] - cx) / hx;
    dz += (p[2] - cz) / hz;
  }
  dx /= points.length;
  dz /= points.length;
  // Near the axis: round the body, or across its middle; any view shows it.
  if (Math.hypot(dx, dz) < 0.25) return null;
  if (Math.abs(dz) >= Math.abs(dx)) return dz > 0 ? 'front' : 'back';
  return dx > 0 ? 'left' : 'right';
}

// An arc's ends as the server placed them on the tape: how far each moved from
// the point tapped (a tape bridges hollows, so a tap in one lands on the tape's
// hull). Null for anything else, or ends that stayed within `within` mm.
/**
 * @param {any} result
 * @param {number} [within]
 * @returns {{ from: number[], to: number[], moved: [number, number] } | null}
 */
export function arcEndsMoved(result, within = 2) {
  const g = result?.geometry || result;
  if (!g || g.kind !== 'arc' || !g.from || !g.to || !g.path || g.path.length < 2) return null;
  const ends = [g.path[0], g.path[g.path.length - 1]];
  const moved = /** @type {[number, number]} */ ([Math.hypot(...ends[0].map((v, i) => v - g.from[i])), Math.hypot(...ends[1].map((v, i) => v - g.to[i]))]);
  if (Math.max(...moved) <= within) return null;
  return { from: ends[0], to: ends[1], moved };
}

// A row's own value is missing where only the compared scan has the measurement.
const has = (m) => Number.isFinite(m.value_mm);

// rows: [{m, other?}] - `other` is the same measurement on a second scan (compare).
/**
 * @param {object} options
 * @param {(StoredMeasurement & { plain_label?: string })[]} options.measurements
 * @param {string} options.unit
 * @param {string | null} options.selected the name of the selected row
 * @param {(m: StoredMeasurement) => void} options.onSelect
 * @param {((m: StoredMeasurement) => void) | null} [options.onDelete] a Delete button on each saved row
 * @param {StoredMeasurement[] | null} [options.compareWith] the same scan's measurements on another scan
 * @param {[string, string]} [options.columns] the headings of the two values compared, as shown
 * @param {boolean} [options.otherFirst] the compared value's column before the row's own (a
 *   comparison shown in the order of its two bodies); the change is still row − compared
 * @param {string} [options.caption]
 * @param {Record<string, string>} [options.groups] the heading of each source's rows
 * @param {boolean} [options.plain] the customer's table: plain names (`plain_label`), no kinds or
 *   clauses, no posture flag, an estimate starred (the page says why in a sentence)
 * @param {string} [options.locale] the values' decimal mark and the headings' language
 * @param {[string, string]} [options.headings] the name and value columns' headings
 */
export function measurementTable({
  measurements,
  unit,
  selected,
  onSelect,
  onDelete,
  compareWith = null,
  columns = ['This scan', 'Other'],
  otherFirst = false,
  caption,
  groups = { automatic: 'Automatic (ISO 8559-1)', user: 'Saved by staff' },
  plain = false,
  locale,
  headings = ['Measurement', 'Value'],
}) {
  const byName = new Map((compareWith || []).map((m) => [m.name, m]));
  const head = h(
    'tr',
    {},
    h('th', { scope: 'col' }, headings[0]),
    h('th', { scope: 'col', class: 'num' }, compareWith ? columns[0] : headings[1]),
    compareWith ? h('th', { scope: 'col', class: 'num' }, columns[1]) : null,
    compareWith ? h('th', { scope: 'col', class: 'num' }, 'Change') : null,
    onDelete ? h('th', { scope: 'col' }, h('span', { class: 'sr-only' }, 'Delete')) : null,
  );
  const body = h('tbody');
  let lastSource = null;
  for (const m of measurements) {
    if (m.source !== lastSource) {
      lastSource = m.source;
      body.append(h('tr', { class: 'group' }, h('th', { colspan: 5, scope: 'colgroup' }, groups[m.source] || m.source)));
    }
    const g = m.geometry || {};
    const other = byName.get(m.name);
    // A row the compared scan has and this one does not carries no value.
    const ownCell = h(
      'td',
      { class: 'num value' },
      g.outside_posture && !plain ? h('span', { class: 'posture-flag', title: POSTURE_NOTE, 'aria-label': POSTURE_NOTE }, '⚑ ') : null,
      isEstimate(g) && !plain ? h('span', { class: 'filled', title: FILLED_NOTE }, '≈ ') : null,
      has(m) ? formatLength(m.value_mm, unit, { locale }) : '—',
      isEstimate(g) && !plain && has(m) ? h('small', { class: 'fill-bound', 'aria-label': `could be off by ${fillBoundText(g, unit).slice(1)}` }, fillBoundText(g, unit)) : null,
    );
    const otherCell = compareWith ? h('td', { class: 'num' }, other ? formatLength(other.value_mm, unit) : '—') : null;
    const row = h(
      'tr',
      {
        class: `row-select${selected === m.name ? ' selected' : ''}`,
        tabindex: 0,
        dataset: { name: m.name },
        'aria-selected': selected === m.name ? 'true' : 'false',
        onclick: () => onSelect && onSelect(m),
        onkeydown: (e) => {
          if ((e.key === 'Enter' || e.key === ' ') && onSelect) {
            e.preventDefault();
            onSelect(m);
          }
        },
      },
      h(
        'td',
        {},
        h('span', { class: 'm-label' }, (plain && m.plain_label) || m.label || m.name),
        plain
          ? isEstimate(g)
            ? h('span', { class: 'estimated' }, ' *')
            : null
          : h('small', { class: 'muted' }, ` ${KIND_LABEL[m.kind] || m.kind}${m.iso_clause ? ` · ISO ${m.iso_clause}` : ''}`),
      ),
      ...(otherFirst ? [otherCell, ownCell] : [ownCell, otherCell]),
      compareWith ? h('td', { class: 'num' }, other && has(m) ? formatDifference(m.value_mm - other.value_mm, unit) : '—') : null,
      onDelete
        ? h(
            'td',
            {},
            m.source === 'user'
              ? h(
                  'button',
                  {
                    class: 'icon danger-text',
                    title: `Delete ${m.label || m.name}`,
                    'aria-label': `Delete ${m.label || m.name}`,
                    onclick: (e) => {
                      e.stopPropagation();
                      onDelete(m);
                    },
                  },
                  '✕',
                )
              : null,
          )
        : null,
    );
    body.append(row);
  }
  return h('table', { class: 'measurements' }, caption ? h('caption', {}, caption) : null, h('thead', {}, head), body);
}

// "Bust girth" -> "bust_girth"; names the server stores (unique per scan here).
export function slug(text, taken = new Set()) {
  const base =
    text
      .normalize('NFKD')
      .replace(/[\u0300-\u036f]/g, '')
      .toLowerCase()
      .replace(/[^a-z0-9]+/g, '_')
      .replace(/^_+|_+$/g, '')
      .slice(0, 80) || 'measurement';
  let name = base;
  for (let i = 2; taken.has(name); i++) name = `${base}_${i}`;
  return name;
}
