// What a line drawn on screen means in the scan frame (thesis §3.3: the tailor
// draws across the body, the plane through the eye and that line cuts it).
// The server takes the line's two ends in mm and the view direction; the plane
// holding both is the plane the user sees edge-on. Pure: tested under node.
import { Plane, Ray, Vector3 } from 'three';

/** @typedef {import('../api.js').MeasureRequest} MeasureRequest */

// The ray from the camera through a point in normalised device coordinates.
export function rayThrough(camera, ndc) {
  camera.updateMatrixWorld();
  const origin = new Vector3().setFromMatrixPosition(camera.matrixWorld);
  const target = new Vector3(ndc.x, ndc.y, 0.5).unproject(camera);
  return new Ray(origin, target.sub(origin).normalize());
}

// The girth request for a screen line from `a` to `b` (NDC). Its ends are put at
// the depth of `depthPoint` (the skin under the line's middle, or the orbit
// centre): the server goes round the loop nearest the line's midpoint.
/**
 * @param {import('three').Camera} camera
 * @param {{ x: number, y: number }} a
 * @param {{ x: number, y: number }} b
 * @param {Vector3} depthPoint
 * @returns {MeasureRequest | null} null when the line does not meet that depth
 */
export function girthRequestFromScreenLine(camera, a, b, depthPoint) {
  const ra = rayThrough(camera, a);
  const rb = rayThrough(camera, b);
  const forward = camera.getWorldDirection(new Vector3());
  const plane = new Plane().setFromNormalAndCoplanarPoint(forward, depthPoint);
  const from = ra.intersectPlane(plane, new Vector3());
  const to = rb.intersectPlane(plane, new Vector3());
  if (!from || !to) return null;
  const mid = from.clone().add(to).multiplyScalar(0.5);
  const view = mid.sub(ra.origin).normalize();
  return { kind: 'girth', line: { from: mm(from), to: mm(to) }, view: unit(view) };
}

// The arc along the tape between two picked points: the plane holds both and
// the view direction (the tape the tailor would lay across what they see).
/**
 * @param {import('three').Camera} camera
 * @param {number[]} from [x, y, z] mm
 * @param {number[]} to [x, y, z] mm
 * @returns {MeasureRequest}
 */
export function arcRequest(camera, from, to) {
  const eye = new Vector3().setFromMatrixPosition(camera.matrixWorld);
  const mid = new Vector3().fromArray(from).add(new Vector3().fromArray(to)).multiplyScalar(0.5);
  const view = mid.sub(eye).normalize();
  return { kind: 'arc', line: { from, to }, view: unit(view), from, to };
}

// The cutting plane a girth request stands for: {point, normal} (unit normal).
/** @param {MeasureRequest} request */
export function requestPlane(request) {
  const from = new Vector3().fromArray(request.line.from);
  const to = new Vector3().fromArray(request.line.to);
  const normal = to.clone().sub(from).cross(new Vector3().fromArray(request.view)).normalize();
  return { point: from, normal };
}

const mm = (v) => [round3(v.x), round3(v.y), round3(v.z)];
const unit = (v) => [round6(v.x), round6(v.y), round6(v.z)];
const round3 = (x) => Math.round(x * 1000) / 1000;
const round6 = (x) => Math.round(x * 1e6) / 1e6;
