import assert from 'node:assert/strict';
import { test } from 'node:test';
import { BufferGeometry, Float32BufferAttribute, SphereGeometry, TorusKnotGeometry } from 'three';
import { computeNormals } from '../../src/viewer/normals.js';

test("the viewer's normals are three's computeVertexNormals, faster", () => {
  for (const g of [new TorusKnotGeometry(100, 30, 200, 32), new SphereGeometry(500, 64, 48)]) {
    const ours = computeNormals(g.clone()).attributes.normal.array;
    const ref = g.clone();
    ref.computeVertexNormals();
    const theirs = ref.attributes.normal.array;
    assert.equal(ours.length, theirs.length);
    let worst = 0;
    for (let i = 0; i < ours.length; i++) worst = Math.max(worst, Math.abs(ours[i] - theirs[i]));
    assert.ok(worst < 1e-5, `differs by ${worst}`);
  }
});

test('a lone triangle, indexed or not, faces the way its winding says', () => {
  const g = new BufferGeometry();
  g.setAttribute('position', new Float32BufferAttribute([0, 0, 0, 1, 0, 0, 0, 1, 0], 3));
  assert.deepEqual([...computeNormals(g).attributes.normal.array], [0, 0, 1, 0, 0, 1, 0, 0, 1]);
  g.setIndex([0, 2, 1]);
  assert.deepEqual([...computeNormals(g).attributes.normal.array], [0, 0, -1, 0, 0, -1, 0, 0, -1]);
});
