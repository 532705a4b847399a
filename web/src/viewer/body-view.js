// A body in a canvas: the archived surface (glTF binary with Draco, metres,
// no normals) or the point cloud (Draco, metres), shown in mm in the scan frame
// (Y up, floor at 0), turned, zoomed and panned by touch or mouse, with the
// measurement lines drawn on it and picking through a BVH (three-mesh-bvh), so a
// tap on a 500k-triangle body answers at once.
//
// It renders on demand (a tablet's battery). What it costs is in the page's
// User Timing (DevTools, the benchmark): marks bodyscan:model-decoded,
// bodyscan:normals-done and bodyscan:first-frame, measures bodyscan:bvh and
// bodyscan:pick. The container's data-state / data-bounds / data-triangles /
// data-first-frame-ms tell the tests what was drawn.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { DRACOLoader } from 'three/addons/loaders/DRACOLoader.js';
import { Line2 } from 'three/addons/lines/Line2.js';
import { LineGeometry } from 'three/addons/lines/LineGeometry.js';
import { LineMaterial } from 'three/addons/lines/LineMaterial.js';
import { acceleratedRaycast, computeBoundsTree, disposeBoundsTree } from 'three-mesh-bvh';
import { computeNormals } from './normals.js';

THREE.BufferGeometry.prototype.computeBoundsTree = computeBoundsTree;
THREE.BufferGeometry.prototype.disposeBoundsTree = disposeBoundsTree;
THREE.Mesh.prototype.raycast = acceleratedRaycast;

let draco = null;
function dracoLoader() {
  if (!draco) {
    draco = new DRACOLoader();
    // The decoder is the `three` package's own, bundled as hashed assets.
    draco.setWorkerLimit(2);
    draco.preload();
  }
  return draco;
}

// A model decoded (Draco, in a worker) from a URL or from a promise of its
// bytes; needs no renderer, so it can run while the page builds one.
export class ModelDecoding {
  constructor(source) {
    const loader = new GLTFLoader();
    loader.setDRACOLoader(dracoLoader());
    this.gltf = typeof source === 'string' ? loader.loadAsync(source) : Promise.resolve(source).then((bytes) => loader.parseAsync(bytes, ''));
    this.gltf.catch(() => {}); // reported by loadMesh, if it is ever shown
  }
}

// The decoder's script and wasm start loading as soon as the viewer's code does.
dracoLoader();

/**
 * three.js's own test for a mesh (a Mesh or a subclass of it).
 * @param {THREE.Object3D} o
 * @returns {o is THREE.Mesh}
 */
const isMesh = (o) => /** @type {THREE.Mesh} */ (o).isMesh === true;

const SKIN = 0xd8b49c;
const VIEWS = {
  front: new THREE.Vector3(0, 0, 1),
  back: new THREE.Vector3(0, 0, -1),
  left: new THREE.Vector3(1, 0, 0),
  right: new THREE.Vector3(-1, 0, 0),
};

export class BodyView {
  constructor(container, { label = 'The scanned body in 3-D' } = {}) {
    this.container = container;
    this.container.classList.add('viewport');
    this.container.dataset.state = 'empty';
    this.renderer = new THREE.WebGLRenderer({ antialias: true, powerPreference: 'high-performance' });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.outputColorSpace = THREE.SRGBColorSpace;
    this.canvas = this.renderer.domElement;
    this.canvas.setAttribute('role', 'img');
    this.canvas.setAttribute('aria-label', label);
    container.append(this.canvas);

    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xeef1f5);
    this.camera = new THREE.PerspectiveCamera(35, 1, 10, 30000);
    this.camera.position.set(0, 1000, 4000);
    this.scene.add(this.camera);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x8090a0, 1.6));
    const key = new THREE.DirectionalLight(0xffffff, 1.8);
    key.position.set(0.6, 0.8, 1);
    this.camera.add(key); // the light moves with the viewer: no dark side
    this.floor = new THREE.GridHelper(2000, 20, 0xb8c2cc, 0xd5dbe1);
    this.scene.add(this.floor);
    this.overlays = new THREE.Group();
    this.scene.add(this.overlays);
    this.overlayItems = new Map();

    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.enableDamping = false;
    this.controls.screenSpacePanning = true;
    this.controls.addEventListener('change', () => this.requestRender());

    this.mesh = null;
    this.points = null;
    this.mode = 'mesh';
    this.bvhReady = null;
    this.renderListeners = new Set();
    this.pending = false;
    this.disposed = false;
    this.resizeObserver = new ResizeObserver(() => this.resize());
    this.resizeObserver.observe(container);
    this.resize();
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth);
    const hgt = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, hgt, false);
    this.canvas.style.width = '100%';
    this.canvas.style.height = '100%';
    this.camera.aspect = w / hgt;
    this.camera.updateProjectionMatrix();
    const res = new THREE.Vector2();
    this.renderer.getDrawingBufferSize(res);
    for (const item of this.overlayItems.values()) if (item.material.isLineMaterial) item.material.resolution.copy(res);
    this.requestRender();
  }

  requestRender() {
    if (this.pending || this.disposed) return;
    this.pending = true;
    requestAnimationFrame(() => {
      this.pending = false;
      this.render();
    });
  }

  render() {
    // Nothing to show yet: the first draw (and its shader compiles) waits for
    // the model, so the main thread is free when the model's bytes arrive.
    if (this.disposed || (!this.mesh && !this.points)) return;
    this.renderer.render(this.scene, this.camera);
    for (const fn of this.renderListeners) fn();
  }

  onCameraChange(fn) {
    this.controls.addEventListener('change', fn);
    return () => this.controls.removeEventListener('change', fn);
  }

  // Shows the surface: `source` is a URL, a promise of the GLB's bytes, or a
  // ModelDecoding already under way. Resolves once its first frame is
  // drawn, with the time it took from `t0` (when the scan was opened).
  async loadMesh(source, { t0 = performance.now() } = {}) {
    this.container.dataset.state = 'loading';
    try {
      const gltf = await (source instanceof ModelDecoding ? source : new ModelDecoding(source)).gltf;
      if (this.disposed) return null;
      performance.mark('bodyscan:model-decoded');
      gltf.scene.updateMatrixWorld(true);
      /** @type {THREE.Mesh | null} */
      let found = null;
      gltf.scene.traverse((o) => {
        if (!found && isMesh(o)) found = o;
      });
      if (!found) throw new Error('the model holds no mesh');
      const geometry = found.geometry;
      geometry.applyMatrix4(new THREE.Matrix4().makeScale(1000, 1000, 1000).multiply(found.matrixWorld)); // m -> mm
      computeNormals(geometry);
      geometry.computeBoundingBox();
      geometry.computeBoundingSphere();
      performance.mark('bodyscan:normals-done');
      const material = new THREE.MeshStandardMaterial({
        color: SKIN,
        roughness: 0.75,
        metalness: 0,
        polygonOffset: true, // lines drawn on the skin stay in front of it
        polygonOffsetFactor: 1,
        polygonOffsetUnits: 1,
      });
      this.mesh = new THREE.Mesh(geometry, material);
      this.mesh.name = 'body';
      this.scene.add(this.mesh);
      this.setMode(this.mode);
      this.frame();
      const ms = await this.firstFrame(t0);
      this.describe(geometry);
      // The BVH is built after the first frame: the body shows at once, and
      // picking is ready a moment later (or built on the first pick).
      this.bvhReady = new Promise((resolve) => setTimeout(() => resolve(this.ensureBvh()), 0));
      return ms;
    } catch (e) {
      this.container.dataset.state = 'error';
      throw e;
    }
  }

  async loadPoints(url) {
    const geometry = await dracoLoader().loadAsync(url);
    if (this.disposed) return;
    geometry.scale(1000, 1000, 1000); // served in metres like the model (docs/archive.md)
    geometry.computeBoundingBox();
    // About the points' spacing on the skin (5 mm), so the cloud reads as a surface.
    const material = new THREE.PointsMaterial({ color: 0x2f6f9f, size: 6, sizeAttenuation: true });
    this.points = new THREE.Points(geometry, material);
    this.points.name = 'points';
    this.scene.add(this.points);
    if (!this.mesh) this.frame(geometry.boundingBox);
    this.setMode(this.mode);
  }

  // 'mesh' or 'points'.
  setMode(mode) {
    this.mode = mode;
    if (this.mesh) this.mesh.visible = mode === 'mesh';
    if (this.points) this.points.visible = mode === 'points';
    this.requestRender();
  }

  firstFrame(t0) {
    return new Promise((resolve) => {
      this.render();
      // The frame is on screen once the browser has composited it: the next
      // animation frame after the draw.
      requestAnimationFrame(() => {
        const ms = performance.now() - t0;
        performance.mark('bodyscan:first-frame', { detail: { ms } });
        this.container.dataset.firstFrameMs = ms.toFixed(0);
        this.container.dataset.state = 'ready';
        resolve(ms);
      });
    });
  }

  describe(geometry) {
    const b = geometry.boundingBox;
    this.container.dataset.bounds = JSON.stringify({ min: b.min.toArray().map(round1), max: b.max.toArray().map(round1) });
    const tris = geometry.index ? geometry.index.count / 3 : geometry.attributes.position.count / 3;
    this.container.dataset.triangles = String(tris);
  }

  ensureBvh() {
    if (this.mesh && !this.mesh.geometry.boundsTree) {
      const t = performance.now();
      this.mesh.geometry.computeBoundsTree();
      performance.measure('bodyscan:bvh', { start: t, end: performance.now() });
    }
    return true;
  }

  // The model's bounding box (mm): the surface's, else the cloud's; null before
  // either is shown.
  modelBounds() {
    const geometry = this.mesh?.geometry ?? this.points?.geometry;
    if (!geometry) return null;
    if (!geometry.boundingBox) geometry.computeBoundingBox();
    return geometry.boundingBox;
  }

  // Looks at the whole body from `view` (front, back, left, right).
  frame(box = this.mesh ? this.mesh.geometry.boundingBox : null, view = 'front') {
    if (!box) return;
    const centre = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3());
    const fov = THREE.MathUtils.degToRad(this.camera.fov);
    const fit = Math.max(size.y, size.x / this.camera.aspect, 300) / 2 / Math.tan(fov / 2);
    const distance = fit * 1.15 + size.z / 2;
    this.controls.target.copy(centre);
    this.camera.position.copy(centre).addScaledVector(VIEWS[view] || VIEWS.front, distance);
    this.camera.near = Math.max(10, distance / 100);
    this.camera.far = distance * 10;
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.requestRender();
  }

  setView(view) {
    const box = this.mesh ? this.mesh.geometry.boundingBox : this.points?.geometry.boundingBox;
    this.frame(box, view);
    this.container.dataset.view = view;
  }

  // Whether the camera looks at the body from within 60° of `view`'s side
  // (front, back, left, right), seen from above.
  facing(view) {
    const want = VIEWS[view];
    if (!want) return true;
    const from = this.camera.position.clone().sub(this.controls.target).setY(0);
    if (from.lengthSq() === 0) return true;
    return from.normalize().dot(want) >= 0.5;
  }

  copyCamera(other) {
    this.camera.position.copy(other.camera.position);
    this.camera.quaternion.copy(other.camera.quaternion);
    this.camera.near = other.camera.near;
    this.camera.far = other.camera.far;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(other.controls.target);
    this.requestRender();
  }

  // NDC of a client position on the canvas.
  ndc(clientX, clientY) {
    const r = this.canvas.getBoundingClientRect();
    return new THREE.Vector2(((clientX - r.left) / r.width) * 2 - 1, -((clientY - r.top) / r.height) * 2 + 1);
  }

  // The surface point under a client position, in mm, or null.
  pick(clientX, clientY) {
    if (!this.mesh || !this.mesh.visible) return null;
    this.ensureBvh();
    const raycaster = new THREE.Raycaster();
    raycaster.firstHitOnly = true;
    raycaster.setFromCamera(this.ndc(clientX, clientY), this.camera);
    const t = performance.now();
    const hit = raycaster.intersectObject(this.mesh, false)[0];
    performance.measure('bodyscan:pick', { start: t, end: performance.now() });
    return hit ? hit.point.clone() : null;
  }

  // Draws a polyline (mm) under `key`, replacing what was there.
  showPath(key, points, { closed = false, color = 0xd6336c, width = 3, onTop = false } = {}) {
    this.remove(key);
    if (!points || points.length < 2) return;
    const flat = [];
    for (const p of points) flat.push(p[0], p[1], p[2]);
    if (closed) flat.push(points[0][0], points[0][1], points[0][2]);
    const geometry = new LineGeometry();
    geometry.setPositions(flat);
    const material = new LineMaterial({ color, linewidth: width, depthTest: !onTop, transparent: onTop, opacity: onTop ? 0.9 : 1 });
    this.renderer.getDrawingBufferSize(material.resolution);
    const line = new Line2(geometry, material);
    line.computeLineDistances();
    line.renderOrder = onTop ? 10 : 1;
    this.overlays.add(line);
    this.overlayItems.set(key, line);
    this.requestRender();
  }

  showMarker(key, p, { color = 0x1f4e79, radius = 7 } = {}) {
    this.remove(key);
    const marker = new THREE.Mesh(new THREE.SphereGeometry(radius, 16, 12), new THREE.MeshBasicMaterial({ color, depthTest: false, transparent: true, opacity: 0.9 }));
    marker.position.set(p[0], p[1], p[2]);
    marker.renderOrder = 20;
    this.overlays.add(marker);
    this.overlayItems.set(key, marker);
    this.requestRender();
  }

  remove(key) {
    const item = this.overlayItems.get(key);
    if (!item) return;
    this.overlays.remove(item);
    item.geometry.dispose();
    item.material.dispose();
    this.overlayItems.delete(key);
    this.requestRender();
  }

  clearOverlays(prefix = '') {
    for (const key of [...this.overlayItems.keys()]) if (key.startsWith(prefix)) this.remove(key);
  }

  dispose() {
    this.disposed = true;
    this.resizeObserver.disconnect();
    this.controls.dispose();
    this.clearOverlays();
    for (const o of [this.mesh, this.points]) {
      if (!o) continue;
      if (o.geometry.boundsTree) o.geometry.disposeBoundsTree();
      o.geometry.dispose();
      o.material.dispose();
    }
    this.renderer.dispose();
    this.renderer.forceContextLoss();
    this.canvas.remove();
  }
}

function round1(v) {
  return Math.round(v * 10) / 10;
}
