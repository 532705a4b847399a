// Lengths as staff read them: the server speaks mm; the UI shows mm, cm or
// inches, the choice kept per browser.

export const UNITS = {
  mm: { label: 'mm', perMm: 1, digits: 0 },
  cm: { label: 'cm', perMm: 0.1, digits: 1 },
  in: { label: 'in', perMm: 1 / 25.4, digits: 2 },
};

export function convert(mm, unit) {
  const u = UNITS[unit];
  if (!u) throw new Error(`unknown unit ${unit}`);
  return mm * u.perMm;
}

// "934 mm", "93.5 cm", "36.81 in"; an em dash for a missing value. With a
// `locale`, its decimal mark ("93,5 cm" in German), no grouping.
/**
 * @param {number | null | undefined} mm
 * @param {string} unit
 * @param {{ withUnit?: boolean, locale?: string }} [options]
 */
export function formatLength(mm, unit, { withUnit = true, locale } = {}) {
  if (mm === null || mm === undefined || !Number.isFinite(mm)) return '—';
  const u = UNITS[unit];
  if (!u) throw new Error(`unknown unit ${unit}`);
  const value = convert(mm, unit);
  const text = locale
    ? value.toLocaleString(locale, { minimumFractionDigits: u.digits, maximumFractionDigits: u.digits, useGrouping: false })
    : value.toFixed(u.digits);
  return withUnit ? `${text} ${u.label}` : text;
}

// A signed difference: "+12 mm", "−0.4 cm" (true minus sign), "±0 mm".
export function formatDifference(mm, unit) {
  if (!Number.isFinite(mm)) return '—';
  const u = UNITS[unit];
  const text = Math.abs(convert(mm, unit)).toFixed(u.digits);
  if (Number(text) === 0) return `±${text} ${u.label}`;
  return `${mm > 0 ? '+' : '−'}${text} ${u.label}`;
}

const STORAGE_KEY = 'bodyscan.unit';

/** @typedef {Pick<Storage, 'getItem' | 'setItem'>} UnitStore the browser's localStorage, or a stand-in */

/** @param {UnitStore} [storage] */
export function preferredUnit(storage = globalThis.localStorage) {
  const u = storage?.getItem(STORAGE_KEY);
  return u && UNITS[u] ? u : 'cm';
}

/**
 * @param {string} unit
 * @param {UnitStore} [storage]
 */
export function setPreferredUnit(unit, storage = globalThis.localStorage) {
  if (!UNITS[unit]) throw new Error(`unknown unit ${unit}`);
  storage?.setItem(STORAGE_KEY, unit);
}
