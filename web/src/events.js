// The workstation's event stream: one WebSocket at /api/events (staff only),
// reconnected with backoff when the network drops, its JSON messages handed to
// whoever listens (docs/api.md "Jobs and events").

/** @typedef {import('./api.js').Job} Job */
/** @typedef {import('./api.js').RigStatus} RigStatus */
/**
 * A message of the stream, as the document's /api/events lists them (in words:
 * a WebSocket's messages have no schema there), or the stream's own news of its
 * connection.
 * @typedef {{ type: 'hello' | 'rig', rig: RigStatus }
 *   | { type: 'job' | 'scan_finished', job: Job }
 *   | { type: 'preview', job: string, camera: string, frame_id: number, png_base64: string }
 *   | { type: 'connection', state: string }} EventMessage
 */
/** @typedef {(msg: EventMessage) => void} Listener */

export class EventStream {
  constructor(url = eventsUrl()) {
    this.url = url;
    /** @type {Set<Listener>} */
    this.listeners = new Set();
    this.socket = null;
    this.closed = false;
    this.retryMs = 500;
    this.state = 'connecting';
  }

  start() {
    this.closed = false;
    this.open();
    return this;
  }

  open() {
    const ws = new WebSocket(this.url);
    this.socket = ws;
    ws.onopen = () => {
      this.retryMs = 500;
      this.setState('open');
    };
    ws.onmessage = (m) => {
      let msg;
      try {
        msg = JSON.parse(m.data);
      } catch {
        return;
      }
      for (const fn of this.listeners) fn(msg);
    };
    ws.onclose = () => {
      if (this.socket !== ws) return;
      this.socket = null;
      if (this.closed) return;
      this.setState('reconnecting');
      setTimeout(() => !this.closed && this.open(), this.retryMs);
      this.retryMs = Math.min(this.retryMs * 2, 8000);
    };
  }

  /** @param {string} state */
  setState(state) {
    this.state = state;
    for (const fn of this.listeners) fn({ type: 'connection', state });
  }

  /**
   * @param {Listener} fn
   * @returns {() => void} stops the listening
   */
  subscribe(fn) {
    this.listeners.add(fn);
    return () => this.listeners.delete(fn);
  }

  stop() {
    this.closed = true;
    if (this.socket) this.socket.close();
    this.socket = null;
  }
}

export function eventsUrl(loc = window.location) {
  return `${loc.protocol === 'https:' ? 'wss:' : 'ws:'}//${loc.host}/api/events`;
}
