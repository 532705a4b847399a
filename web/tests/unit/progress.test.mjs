import assert from 'node:assert/strict';
import { test } from 'node:test';
import { overallFraction, stageText, timeLeftText } from '../../src/progress.js';

test('a scan job fills one bar through calibration, the sweep and the reconstruction', () => {
  const steps = [
    ['starting', 0],
    ['calibration: lens', 0.5],
    ['calibration: frame lights', 0],
    ['calibration: lasers', 1],
    ['scan', 0],
    ['scan', 0.5],
    ['scan', 1],
    ['neighbours', 0],
    ['normals', 0],
    ['field', 0.5],
    ['mesh', 1],
    ['done', 1],
  ];
  let last = -1;
  for (const [stage, f] of steps) {
    const x = overallFraction('scan', stage, f);
    assert.ok(x >= last, `${stage} ${f}: ${x} after ${last}`);
    assert.ok(x >= 0 && x <= 1);
    last = x;
  }
  assert.equal(overallFraction('scan', 'scan', 0.5), 0.4);
  assert.ok(last > 0.95);
});

test('calibration and reprocessing jobs use the whole bar for their own stages', () => {
  assert.equal(overallFraction('calibrate', 'calibration: lens', 0), 0);
  assert.ok(Math.abs(overallFraction('calibrate', 'calibration: lasers', 1) - 1) < 1e-12);
  assert.ok(Math.abs(overallFraction('reprocess', 'neighbours', 0)) < 1e-12);
  assert.ok(overallFraction('reprocess', 'mesh', 1) > overallFraction('reprocess', 'field', 1));
  assert.ok(overallFraction('reprocess', 'done', 1) > 0.95);
});

test('an unknown stage keeps the bar where it was and reads as it is', () => {
  assert.equal(overallFraction('scan', 'something new', 0.3), null);
  assert.equal(stageText('something new'), 'something new');
  assert.match(stageText('scan'), /Scanning/);
  assert.equal(overallFraction('scan', 'scan', Number.NaN), 0.1);
  assert.equal(overallFraction('scan', 'scan', 7), 0.7);
});

test('the time left follows the bar: none before it has moved, seconds then minutes', () => {
  assert.equal(timeLeftText(0, 10), null);
  assert.equal(timeLeftText(0.04, 10), null);
  assert.equal(timeLeftText(0.5, Number.NaN), null, 'no start time');
  assert.equal(timeLeftText(1, 100), null, 'done');
  assert.equal(timeLeftText(0.5, 40), 'about 40 s left');
  assert.equal(timeLeftText(0.9, 9), 'about 5 s left');
  assert.equal(timeLeftText(0.25, 60), 'about 3 min left');
  assert.equal(timeLeftText(0.1, 60), 'about 9 min left');
});
