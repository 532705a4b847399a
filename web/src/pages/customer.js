// The customer's page, opened from a share link: that scan's model and the
// measurements staff chose, read-only. It calls only /api/share/{token}/…; the
// token is the whole of the customer's access, with the PIN the shop read out
// where the link has one (kept in this page only, never stored).
import { api, enc } from '../api.js';
import { preferredUnit } from '../units.js';
import { unitSelect } from '../ui/unit-select.js';
import { clear, errorText, h, when } from '../ui/dom.js';
import { BodyView } from '../viewer/body-view.js';
import { COLOURS, drawMeasurement, measurementTable } from '../viewer/measurement-table.js';

export async function mount(container, { token }) {
  const t0 = performance.now();
  let unit = preferredUnit();
  let selected = null;
  /** @type {import('../api.js').ShareView} */
  let share;
  /** @type {string | undefined} */
  let pin;
  try {
    share = await api.getShare(token);
  } catch (e) {
    if (e.status === 401) {
      // The link asks for its PIN: the page asks, and opens once it is right.
      pin = await askPin(container, token);
      if (pin === undefined) return;
      share = await api.getShare(token, pin);
    } else {
      container.append(
        h(
          'section',
          { class: 'page narrow customer-page' },
          h('h1', {}, 'This link does not open a scan'),
          h('p', {}, e.status === 404 ? 'It may have expired or been withdrawn. Ask the shop for a new link.' : errorText(e)),
        ),
      );
      return;
    }
  }
  const viewport = h('div', { class: 'viewport', id: 'viewport' });
  const tableBox = h('div', { class: 'table-box' });
  container.append(
    h(
      'section',
      { class: 'page viewer-page customer-page' },
      h(
        'header',
        { class: 'customer-head' },
        h('h1', {}, 'Your body scan'),
        h('p', { class: 'muted' }, `Taken ${when(share.taken_at)} · this link works until ${when(new Date(share.expires_at * 1000).toISOString())}`),
      ),
      h('div', { class: 'viewer-main' }, viewport, h('p', { class: 'hint' }, 'Drag to turn, pinch or scroll to zoom. Tap a measurement to see it on the body.')),
      h(
        'aside',
        { class: 'viewer-side' },
        h(
          'div',
          { class: 'row' },
          h('h2', {}, 'Measurements'),
          unitSelect(unit, (u) => {
            unit = u;
            renderTable();
          }),
        ),
        tableBox,
      ),
    ),
  );
  const view = new BodyView(viewport, { label: 'Your body in 3-D' });

  function renderTable() {
    clear(
      tableBox,
      share.measurements.length
        ? measurementTable({
            measurements: share.measurements,
            unit,
            selected,
            groups: { automatic: 'Body measurements', user: 'Taken by the shop' },
            onSelect: (m) => {
              selected = selected === m.name ? null : m.name;
              view.clearOverlays('sel');
              if (selected) drawMeasurement(view, 'sel', m, COLOURS.selected);
              renderTable();
            },
          })
        : h('p', { class: 'muted' }, 'The shop shared no measurements with this link.'),
    );
  }
  renderTable();
  view.loadMesh(api.getShareModel(share.mesh || `/api/share/${enc(token)}/mesh.glb`, pin), { t0 }).catch((e) => {
    viewport.append(h('p', { class: 'form-error overlay' }, `The model did not load: ${errorText(e)}`));
  });
  return () => view.dispose();
}

// A form for the link's PIN; resolves with the right one, or undefined when the
// link stops opening (too many wrong tries withdraw it). The form goes once done.
/**
 * @param {HTMLElement} container
 * @param {string} token
 * @returns {Promise<string | undefined>}
 */
function askPin(container, token) {
  return new Promise((resolve) => {
    const input = h('input', { name: 'pin', inputmode: 'numeric', autocomplete: 'one-time-code', maxlength: 6, pattern: '[0-9]{6}', required: true, 'aria-label': 'PIN', class: 'pin-input' });
    const message = h('p', { class: 'form-error', role: 'alert' });
    const section = h(
      'section',
      { class: 'page narrow customer-page pin-page' },
      h('h1', {}, 'Your body scan'),
      h('p', {}, 'Enter the six-digit PIN the shop gave you.'),
      h(
        'form',
        {
          onsubmit: async (/** @type {SubmitEvent} */ e) => {
            e.preventDefault();
            try {
              await api.getShare(token, input.value.trim());
              section.remove();
              resolve(input.value.trim());
            } catch (err) {
              if (err.status === 401) {
                message.textContent = errorText(err);
                input.select();
                return;
              }
              clear(section, h('h1', {}, 'This link does not open a scan'), h('p', {}, err.status === 404 ? 'It was withdrawn after too many wrong PINs, or has expired. Ask the shop for a new link.' : errorText(err)));
              resolve(undefined);
            }
          },
        },
        h('div', { class: 'row' }, input, h('button', { class: 'primary', type: 'submit' }, 'Open')),
        message,
      ),
    );
    container.append(section);
    input.focus();
  });
}
