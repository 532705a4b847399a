import assert from 'node:assert/strict';
import { test } from 'node:test';
import { convert, formatDifference, formatLength, preferredUnit, setPreferredUnit } from '../../src/units.js';

test('lengths read as staff expect in mm, cm and inches', () => {
  assert.equal(formatLength(934.92, 'mm'), '935 mm');
  assert.equal(formatLength(934.92, 'cm'), '93.5 cm');
  assert.equal(formatLength(934.92, 'in'), '36.81 in');
  assert.equal(formatLength(25.4, 'in', { withUnit: false }), '1.00');
  assert.equal(formatLength(null, 'cm'), '—');
  assert.equal(formatLength(Number.NaN, 'cm'), '—');
  assert.ok(Math.abs(convert(1000, 'in') - 39.3700787) < 1e-6);
  assert.throws(() => formatLength(1, 'furlong'), /unknown unit/);
});

test('differences carry their sign, and zero reads as ±0', () => {
  assert.equal(formatDifference(12.3, 'mm'), '+12 mm');
  assert.equal(formatDifference(-4, 'cm'), '−0.4 cm');
  assert.equal(formatDifference(0.02, 'cm'), '±0.0 cm');
});

test('the unit choice is kept per browser, cm when none or a bad one is stored', () => {
  const store = new Map();
  const storage = { getItem: (k) => store.get(k) ?? null, setItem: (k, v) => store.set(k, v) };
  assert.equal(preferredUnit(storage), 'cm');
  setPreferredUnit('in', storage);
  assert.equal(preferredUnit(storage), 'in');
  store.set('bodyscan.unit', 'cubit');
  assert.equal(preferredUnit(storage), 'cm');
  assert.throws(() => setPreferredUnit('cubit', storage));
});

test("the customer's locale writes its own decimal mark, without grouping", () => {
  assert.equal(formatLength(934.4, 'cm', { locale: 'de' }), '93,4 cm');
  assert.equal(formatLength(12345.6, 'mm', { locale: 'de' }), '12346 mm');
  assert.equal(formatLength(934.4, 'cm', { locale: 'en' }), '93.4 cm');
  assert.equal(formatLength(254, 'in', { locale: 'de', withUnit: false }), '10,00');
});
