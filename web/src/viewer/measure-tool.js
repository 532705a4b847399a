// The viewer's tools: draw a girth line across the body, or tap two points for a
// distance, an arc along the tape or a length over the skin. Each ends in a
// request (docs/api.md, "Evaluating") handed to `onRequest`; the server measures.
//
// Rotate: one finger or the left button turns, two fingers or the wheel zoom,
// right button / two-finger drag pans (OrbitControls). Girth: one finger or the
// left button draws the line; two fingers, the wheel and the right button still
// zoom and pan. Two-tap tools: a tap picks, a drag turns.
import { MOUSE, TOUCH } from 'three';
import { arcRequest, girthRequestFromScreenLine } from './girth-line.js';

export const TOOLS = {
  rotate: { label: 'Rotate', hint: 'Drag to turn the body, pinch or scroll to zoom, two fingers to move.' },
  girth: { label: 'Girth', hint: 'Draw a line across the body where the tape goes (two fingers still zoom and move).' },
  distance: { label: 'Distance', hint: 'Tap two points: the straight distance.' },
  arc: { label: 'Arc', hint: 'Tap two points: the length along the tape between them.' },
  surface: { label: 'Over skin', hint: 'Tap two points: the shortest path over the skin.' },
};

const TAP_PX = 8;
const MIN_LINE_PX = 24;

export class MeasureTool {
  /**
   * @param {import('./body-view.js').BodyView} view
   * @param {object} handlers
   * @param {(request: import('../api.js').MeasureRequest, toolName: string) => void} handlers.onRequest
   * @param {(hint: string) => void} [handlers.onHint]
   */
  constructor(view, { onRequest, onHint = () => {} }) {
    this.view = view;
    this.onRequest = onRequest;
    this.onHint = onHint;
    this.mode = 'rotate';
    this.picked = [];
    this.down = null;
    this.svg = document.createElementNS('http://www.w3.org/2000/svg', 'svg');
    this.svg.classList.add('draw-layer');
    this.line = document.createElementNS('http://www.w3.org/2000/svg', 'line');
    this.svg.append(this.line);
    this.svg.style.display = 'none';
    view.container.append(this.svg);
    const c = view.canvas;
    this.handlers = {
      pointerdown: (e) => this.pointerDown(e),
      pointermove: (e) => this.pointerMove(e),
      pointerup: (e) => this.pointerUp(e),
      pointercancel: () => this.cancelDrag(),
    };
    for (const [k, fn] of Object.entries(this.handlers)) c.addEventListener(k, fn);
  }

  setMode(mode) {
    if (!TOOLS[mode]) throw new Error(`unknown tool ${mode}`);
    this.mode = mode;
    this.picked = [];
    this.view.clearOverlays('pick:');
    // In girth mode a one-finger or left-button drag is the line, not a turn.
    const controls = this.view.controls;
    controls.mouseButtons.LEFT = mode === 'girth' ? null : MOUSE.ROTATE;
    controls.touches.ONE = mode === 'girth' ? null : TOUCH.ROTATE;
    this.view.canvas.style.cursor = mode === 'girth' ? 'crosshair' : mode === 'rotate' ? 'grab' : 'pointer';
    this.onHint(TOOLS[mode].hint);
  }

  pointerDown(e) {
    if (!e.isPrimary) {
      this.cancelDrag();
      return;
    }
    this.down = { x: e.clientX, y: e.clientY, t: performance.now() };
    if (this.mode === 'girth') {
      this.view.canvas.setPointerCapture(e.pointerId);
      this.drawLine(e);
      this.svg.style.display = '';
    }
  }

  pointerMove(e) {
    if (this.down && this.mode === 'girth' && e.isPrimary) this.drawLine(e);
  }

  pointerUp(e) {
    const down = this.down;
    this.down = null;
    if (!down || !e.isPrimary) return;
    const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
    if (this.mode === 'girth') {
      this.svg.style.display = 'none';
      if (moved < MIN_LINE_PX) {
        this.onHint('Draw a longer line across the body.');
        return;
      }
      this.girthFromLine(down, { x: e.clientX, y: e.clientY });
    } else if (this.mode !== 'rotate' && moved < TAP_PX) {
      this.tap(e.clientX, e.clientY);
    }
  }

  cancelDrag() {
    this.down = null;
    this.svg.style.display = 'none';
  }

  drawLine(e) {
    const r = this.view.canvas.getBoundingClientRect();
    const d = this.down;
    this.line.setAttribute('x1', String(d.x - r.left));
    this.line.setAttribute('y1', String(d.y - r.top));
    this.line.setAttribute('x2', String(e.clientX - r.left));
    this.line.setAttribute('y2', String(e.clientY - r.top));
  }

  girthFromLine(a, b) {
    const view = this.view;
    const mid = view.pick((a.x + b.x) / 2, (a.y + b.y) / 2);
    const depth = mid || view.controls.target.clone();
    const request = girthRequestFromScreenLine(view.camera, view.ndc(a.x, a.y), view.ndc(b.x, b.y), depth);
    if (!request) {
      this.onHint('That line does not cross the body; draw it across.');
      return;
    }
    this.onRequest(request, 'Girth');
  }

  // Girth from a line given in client pixels (the tests and keyboard users).
  drawGirth(x1, y1, x2, y2) {
    this.girthFromLine({ x: x1, y: y1 }, { x: x2, y: y2 });
  }

  tap(x, y) {
    const p = this.view.pick(x, y);
    if (!p) {
      this.onHint('Tap on the body.');
      return;
    }
    const point = [p.x, p.y, p.z].map((v) => Math.round(v * 1000) / 1000);
    this.picked.push(point);
    this.view.showMarker(`pick:${this.picked.length}`, point);
    if (this.picked.length < 2) {
      this.onHint('Now tap the second point.');
      return;
    }
    const [from, to] = this.picked;
    this.picked = [];
    /** @type {import('../api.js').MeasureRequest} */
    const request =
      this.mode === 'arc' ? arcRequest(this.view.camera, from, to) : { kind: this.mode === 'surface' ? 'surface' : 'distance', from, to };
    this.onRequest(request, TOOLS[this.mode].label);
    this.onHint(TOOLS[this.mode].hint);
  }

  dispose() {
    for (const [k, fn] of Object.entries(this.handlers)) this.view.canvas.removeEventListener(k, fn);
    this.svg.remove();
  }
}
