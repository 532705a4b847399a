import assert from 'node:assert/strict';
import { test } from 'node:test';
import { arcEndsMoved, drawMeasurement, sideShowing } from '../../src/viewer/measurement-table.js';

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

test('a measurement on the back or a side names the view that shows it; one round the body none', () => {
  const back = { kind: 'surface_length', geometry: { kind: 'surface_length', path: [[0, 1450, -120], [5, 1200, -135], [0, 1040, -110]] } };
  assert.equal(sideShowing(back, BODY), 'back');
  const leftArm = { kind: 'surface_length', geometry: { kind: 'surface_length', path: [[200, 1400, 0], [260, 1150, 10], [290, 900, 20]] } };
  assert.equal(sideShowing(leftArm, BODY), 'left');
  const rightArm = { kind: 'surface_length', geometry: { kind: 'surface_length', path: [[-200, 1400, 0], [-260, 1150, 10]] } };
  assert.equal(sideShowing(rightArm, BODY), 'right');
  const chestFront = { kind: 'distance', geometry: { kind: 'distance', from: [-80, 1300, 120], to: [80, 1300, 120] } };
  assert.equal(sideShowing(chestFront, BODY), 'front');
  // A girth goes round the body: its loop is closed, and any view shows it.
  const waist = { kind: 'girth', geometry: { kind: 'girth', closed: true, path: [[150, 1000, 0], [0, 1000, 120], [-150, 1000, 0], [0, 1000, -120]] } };
  assert.equal(sideShowing(waist, BODY), null);
  // A straight line across the middle of the body too.
  assert.equal(sideShowing({ kind: 'distance', geometry: { kind: 'distance', from: [-150, 1400, 5], to: [150, 1400, -5] } }, BODY), null);
  const stature = { kind: 'height', geometry: { kind: 'height', path: [[2, -20, -130], [2, 1710, -130]] } };
  assert.equal(sideShowing(stature, BODY), null, 'a height stands beside the body');
  assert.equal(sideShowing(back, null), null, 'no body yet');
});

test("an arc's ends the tape moved are drawn where they went, with leaders back to the taps", () => {
  // Tapped in a hollow at the small of the back: the tape's hull lies 72 mm out.
  const arc = { kind: 'arc', from: [-60, 1000, -60], to: [60, 1000, -128], path: [[-60, 1000, -132], [0, 1000, -136], [60, 1000, -131]] };
  const moved = arcEndsMoved(arc);
  assert.ok(moved);
  assert.deepEqual(moved.from, [-60, 1000, -132]);
  assert.ok(Math.abs(moved.moved[0] - 72) < 1e-9);
  assert.ok(Math.abs(moved.moved[1] - 3) < 1e-9);
  const view = recordingView(BODY);
  drawMeasurement(view, 'fresh', arc);
  assert.deepEqual(view.calls.markers.get('fresh:from'), [-60, 1000, -132], 'the end marker sits on the tape');
  assert.deepEqual(view.calls.markers.get('fresh:tapped-from'), [-60, 1000, -60], 'and the tap is still shown');
  assert.deepEqual(view.calls.paths.get('fresh:moved-from').points, [[-60, 1000, -60], [-60, 1000, -132]]);
  // Ends that stayed where they were tapped: drawn as before, nothing said.
  const kept = { kind: 'arc', from: [-60, 1000, -131], to: [60, 1000, -130], path: [[-60, 1000, -132], [60, 1000, -131]] };
  assert.equal(arcEndsMoved(kept), null);
  const plain = recordingView(BODY);
  drawMeasurement(plain, 'fresh', kept);
  assert.deepEqual(plain.calls.markers.get('fresh:from'), [-60, 1000, -131]);
  assert.equal(plain.calls.paths.has('fresh:moved-from'), false);
  assert.equal(arcEndsMoved({ kind: 'distance', from: [0, 0, 0], to: [1, 1, 1], path: [] }), null);
});
