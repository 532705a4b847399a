// The workstation's event stream: one WebSocket at /api/events (staff only),
// reconnected with backoff when the network drops, its JSON messages handed to
// whoever listens (docs/api.md "Jobs and events").

export class EventStream {
  constructor(url = eventsUrl()) {
    this.url = url;
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

  setState(state) {
    this.state = state;
    for (const fn of this.listeners) fn({ type: 'connection', state });
  }

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
