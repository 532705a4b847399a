import assert from 'node:assert/strict';
import { test } from 'node:test';
import { drawMeasurement } from '../../src/viewer/measurement-table.js';

// A BodyView's drawing calls, recorded; the body's bounding box given.
function recordingView(box) {
  const calls = { paths: new Map(), markers: new Map(), cleared: [] };
  return {
    calls,
    modelBounds: () => box,
    clearOverlays: (prefix) => calls.cleared.push(prefix),
    showPath: (key, points, options) => calls.paths.set(key, { points, options }),
    showMarker: (key, p) => calls.markers.set(key, p),
  };
}

const BODY = { min: { x: -280, y: -20, z: -150 }, max: { x: 300, y: 1710, z: 140 } };

test('a height stands beside the body as a rule with its ends marked, not through the body', () => {
  const view = recordingView(BODY);
  // Stature: the crown above the floor, the vertical through the head.
  const stature = { name: 'stature', kind: 'height', geometry: { kind: 'height', path: [[2, -20, -10], [2, 1710, -10]] } };
  drawMeasurement(view, 'sel', stature);
  const rule = view.calls.paths.get('sel:path').points;
  assert.equal(rule.length, 2);
  for (const p of rule) assert.ok(p[0] > BODY.max.x, `the rule at x = ${p[0]} stands clear of the body (max x ${BODY.max.x})`);
  assert.deepEqual(rule.map((p) => p[1]).sort((a, b) => a - b), [-20, 1710], 'from the floor to the crown');
  assert.ok(view.calls.paths.get('sel:path').options.onTop, 'drawn over the body');
  assert.deepEqual(view.calls.markers.get('sel:top'), rule.find((p) => p[1] === 1710));
  assert.deepEqual(view.calls.markers.get('sel:foot'), rule.find((p) => p[1] === -20));
  // The leader runs level from the crown out to the rule.
  const leader = view.calls.paths.get('sel:leader').points;
  assert.deepEqual(leader[0], [2, 1710, -10]);
  assert.equal(leader[1][1], 1710);
  assert.ok(leader[1][0] > BODY.max.x);
  // Whichever way round the path is given.
  const flipped = recordingView(BODY);
  drawMeasurement(flipped, 'sel', { ...stature, geometry: { kind: 'height', path: [[2, 1710, -10], [2, -20, -10]] } });
  assert.deepEqual(flipped.calls.paths.get('sel:path').points, rule);
});

test('a girth is drawn where it was taken, closed', () => {
  const view = recordingView(BODY);
  const loop = [[0, 1000, 100], [100, 1000, 0], [0, 1000, -100], [-100, 1000, 0]];
  drawMeasurement(view, 'sel', { name: 'waist_girth', kind: 'girth', geometry: { kind: 'girth', path: loop, closed: true } });
  assert.deepEqual(view.calls.paths.get('sel:path').points, loop);
  assert.equal(view.calls.paths.get('sel:path').options.closed, true);
  assert.equal(view.calls.markers.size, 0);
});
