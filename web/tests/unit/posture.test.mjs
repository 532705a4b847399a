import assert from 'node:assert/strict';
import { test } from 'node:test';
import { postureLines } from '../../src/viewer/posture.js';

// A posture as GET /api/scans/{id}/measurements gives it (server/api/openapi.json, Posture).
const stood = {
  turn_deg: 21.4,
  position_mm: [120, -40],
  arm_abduction_deg: [23.7, 41.2],
  elbow_bend_deg: [12.3, 11.8],
  ankle_distance_mm: 229.2,
  head_tilt_deg: -1.2,
  head_side_tilt_deg: 0.4,
  ok: false,
  checks: [
    { part: 'arm_left', ok: false, message: 'the left arm hangs 24° from the body: raise it to 35–50°' },
    { part: 'arm_right', ok: true, message: '' },
    { part: 'feet', ok: false, message: 'the ankles are 229 mm apart: stand with them 300–450 mm apart' },
    { part: 'head', ok: true, message: '' },
    { part: 'turn', ok: true, message: '' },
  ],
};

test('the posture reads as one line a part, with what to ask where it is outside', () => {
  const lines = postureLines(stood);
  assert.deepEqual(lines.map((l) => l.part), ['arm_left', 'arm_right', 'feet', 'head', 'turn']);
  assert.equal(lines[0].text, 'Left arm 24° from the body, elbow bent 12°');
  assert.equal(lines[0].ok, false);
  assert.match(lines[0].message, /raise it/);
  assert.equal(lines[1].ok, true);
  assert.equal(lines[2].text, 'Ankles 23 cm apart');
  assert.equal(lines[3].text, 'Head level');
  assert.equal(lines[4].text, 'Turned 21° to their left from the front');
});

test('parts the server did not find are left out; no posture, no lines', () => {
  const lines = postureLines({ ...stood, arm_abduction_deg: [null, 40], ankle_distance_mm: null, head_tilt_deg: null });
  assert.deepEqual(lines.map((l) => l.part), ['arm_right', 'turn']);
  assert.deepEqual(postureLines(null), []);
  assert.equal(postureLines({ ...stood, turn_deg: -0.5 }).at(-1).text, 'Facing the front');
});
