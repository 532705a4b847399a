import assert from 'node:assert/strict';
import { test } from 'node:test';
import { slug } from '../../src/viewer/measurement-table.js';

test('a saved measurement gets a stable name from its label, never one the scan has', () => {
  assert.equal(slug('Jacket waist'), 'jacket_waist');
  assert.equal(slug('  Épaule → coude (gauche) '), 'epaule_coude_gauche');
  assert.equal(slug('!!!'), 'measurement');
  assert.equal(slug('Waist girth', new Set(['waist_girth', 'waist_girth_2'])), 'waist_girth_3');
  assert.ok(slug('x'.repeat(300)).length <= 80);
});
