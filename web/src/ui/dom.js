// Small DOM helpers: elements from a tag, attributes and children (text is
// always set as text, never parsed as HTML), a confirmation dialog, toasts.

export function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) {
    if (v === undefined || v === null || v === false) continue;
    if (k.startsWith('on') && typeof v === 'function') el.addEventListener(k.slice(2).toLowerCase(), v);
    else if (k === 'class') el.className = v;
    else if (k === 'dataset') Object.assign(el.dataset, v);
    else if (k === 'style' && typeof v === 'object') Object.assign(el.style, v);
    else if (k in el && typeof v !== 'string') el[k] = v;
    else el.setAttribute(k, v === true ? '' : v);
  }
  append(el, children);
  return el;
}

function append(el, children) {
  for (const c of children.flat(Infinity)) {
    if (c === null || c === undefined || c === false) continue;
    el.append(c instanceof Node ? c : document.createTextNode(String(c)));
  }
}

export function clear(el, ...children) {
  el.replaceChildren();
  append(el, children);
  return el;
}

// A modal question; resolves true when confirmed. `danger` styles the button red.
export function confirmDialog(message, { title = 'Are you sure?', confirm = 'Confirm', danger = false } = {}) {
  return new Promise((resolve) => {
    const ok = h('button', { class: danger ? 'danger' : 'primary', value: 'ok', type: 'submit' }, confirm);
    const dialog = h(
      'dialog',
      { class: 'dialog', 'aria-labelledby': 'dlg-title' },
      h(
        'form',
        { method: 'dialog' },
        h('h2', { id: 'dlg-title' }, title),
        h('p', {}, message),
        h('div', { class: 'row end' }, h('button', { value: 'cancel', type: 'submit' }, 'Cancel'), ok),
      ),
    );
    dialog.addEventListener('close', () => {
      resolve(dialog.returnValue === 'ok');
      dialog.remove();
    });
    document.body.append(dialog);
    dialog.showModal();
    ok.focus();
  });
}

// A modal form: `fields` are elements; resolves with the FormData, or null.
export function formDialog(title, fields, { submit = 'Save' } = {}) {
  return new Promise((resolve) => {
    const form = h(
      'form',
      { method: 'dialog' },
      h('h2', {}, title),
      fields,
      h(
        'div',
        { class: 'row end' },
        h('button', { value: 'cancel', type: 'submit', formnovalidate: true }, 'Cancel'),
        h('button', { class: 'primary', value: 'ok', type: 'submit' }, submit),
      ),
    );
    const dialog = h('dialog', { class: 'dialog' }, form);
    dialog.addEventListener('close', () => {
      resolve(dialog.returnValue === 'ok' ? new FormData(form) : null);
      dialog.remove();
    });
    document.body.append(dialog);
    dialog.showModal();
  });
}

export function toast(message, kind = 'info', ms = 5000) {
  const box = document.getElementById('toasts');
  if (!box) return;
  const t = h('div', { class: `toast ${kind}`, role: kind === 'error' ? 'alert' : 'status' }, message);
  box.append(t);
  setTimeout(() => t.remove(), ms);
}

export function errorText(e) {
  return e && e.message ? e.message : String(e);
}

// "just now", "3 min ago", "2 h ago", "5 days ago".
export function ago(seconds) {
  if (!Number.isFinite(seconds)) return '—';
  if (seconds < 10) return 'just now';
  if (seconds < 90) return `${Math.round(seconds)} s ago`;
  if (seconds < 5400) return `${Math.round(seconds / 60)} min ago`;
  if (seconds < 2 * 86400) return `${Math.round(seconds / 3600)} h ago`;
  return `${Math.round(seconds / 86400)} days ago`;
}

// An ISO 8601 UTC time in the browser's zone: "22 Nov 2026, 14:03".
export function when(iso) {
  if (!iso) return '—';
  const d = new Date(iso);
  if (Number.isNaN(d.getTime())) return iso;
  return d.toLocaleString(undefined, { day: 'numeric', month: 'short', year: 'numeric', hour: '2-digit', minute: '2-digit' });
}

export function label(text, control, hint) {
  return h('label', { class: 'field' }, h('span', {}, text), control, hint ? h('small', {}, hint) : null);
}
