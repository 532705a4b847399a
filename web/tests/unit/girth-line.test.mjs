// The girth line drawn on screen becomes the plane the user sees edge-on.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { PerspectiveCamera, Vector2, Vector3 } from 'three';
import { arcRequest, girthRequestFromScreenLine, requestPlane } from '../../src/viewer/girth-line.js';

function camera(position, target, aspect = 4 / 3) {
  const c = new PerspectiveCamera(35, aspect, 10, 30000);
  c.position.copy(position);
  c.lookAt(target);
  c.updateMatrixWorld();
  c.updateProjectionMatrix();
  return c;
}

const project = (cam, p) => new Vector3().fromArray(p).project(cam);

test('a level line through the middle of a level view cuts a horizontal plane at that height', () => {
  const cam = camera(new Vector3(0, 1000, 3500), new Vector3(0, 1000, 0));
  const r = girthRequestFromScreenLine(cam, new Vector2(-0.4, 0), new Vector2(0.4, 0), new Vector3(0, 1000, 0));
  assert.equal(r.kind, 'girth');
  assert.ok(Math.abs(r.line.from[1] - 1000) < 1e-3 && Math.abs(r.line.to[1] - 1000) < 1e-3);
  assert.ok(Math.abs(r.line.from[2]) < 1e-3, 'the ends sit at the depth asked for');
  const { normal } = requestPlane(r);
  assert.ok(Math.abs(Math.abs(normal.y) - 1) < 1e-6, `normal ${normal.toArray()}`);
});

test('any line drawn in any view: the plane holds the eye, and its ends project back onto the line', () => {
  const eye = new Vector3(1800, 1900, 2400);
  const cam = camera(eye, new Vector3(50, 900, -30), 1.5);
  const a = new Vector2(-0.31, 0.22);
  const b = new Vector2(0.44, -0.13);
  const depth = new Vector3(120, 1100, 80);
  const r = girthRequestFromScreenLine(cam, a, b, depth);
  const { point, normal } = requestPlane(r);
  // The plane through the line and the view direction passes through the eye:
  // what the user sees as a line is the plane seen edge-on.
  assert.ok(Math.abs(eye.clone().sub(point).dot(normal)) < 0.05, `eye off the plane by ${eye.clone().sub(point).dot(normal)} mm`);
  const pa = project(cam, r.line.from);
  const pb = project(cam, r.line.to);
  assert.ok(Math.hypot(pa.x - a.x, pa.y - a.y) < 1e-5 && Math.hypot(pb.x - b.x, pb.y - b.y) < 1e-5);
  // Both ends at the depth of `depth` along the view.
  const forward = cam.getWorldDirection(new Vector3());
  for (const p of [r.line.from, r.line.to]) assert.ok(Math.abs(new Vector3().fromArray(p).sub(depth).dot(forward)) < 1e-2);
  assert.ok(Math.abs(Math.hypot(...r.view) - 1) < 1e-5);
});

test('a depth behind the camera gives no request', () => {
  const cam = camera(new Vector3(0, 1000, 3000), new Vector3(0, 1000, 0));
  assert.equal(girthRequestFromScreenLine(cam, new Vector2(-0.2, 0), new Vector2(0.2, 0), new Vector3(0, 1000, 5000)), null);
});

test('an arc between two picked points lies in the plane of those points and the eye', () => {
  const eye = new Vector3(0, 1200, 3000);
  const cam = camera(eye, new Vector3(0, 1000, 0));
  const r = arcRequest(cam, [-150, 1000, 120], [160, 990, 110]);
  assert.equal(r.kind, 'arc');
  assert.deepEqual(r.from, [-150, 1000, 120]);
  const { point, normal } = requestPlane(r);
  assert.ok(Math.abs(eye.clone().sub(point).dot(normal)) < 0.05);
});
