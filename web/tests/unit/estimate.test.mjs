import assert from 'node:assert/strict';
import { test } from 'node:test';
import { fillBoundText, isEstimate } from '../../src/viewer/measurement-table.js';

test('a value is an estimate when the server says so, else (older scans) when its line crosses filled skin', () => {
  assert.equal(isEstimate({ estimated: true, crosses_filled_hole: true }), true);
  // Crosses a filled stretch too small to move it past the threshold: not marked.
  assert.equal(isEstimate({ estimated: false, crosses_filled_hole: true }), false);
  assert.equal(isEstimate({ crosses_filled_hole: true }), true);
  assert.equal(isEstimate({ crosses_filled_hole: false }), false);
  assert.equal(isEstimate({}), false);
});

test('how far the fill could move a value reads in the chosen unit, or as unknown', () => {
  assert.equal(fillBoundText({ fill_bound_mm: 6.2 }, 'mm'), '±6 mm');
  assert.equal(fillBoundText({ fill_bound_mm: 6.2 }, 'cm'), '±0.6 cm');
  assert.equal(fillBoundText({ fill_bound_mm: null }, 'cm'), '±?');
  assert.equal(fillBoundText({}, 'cm'), '±?');
});
