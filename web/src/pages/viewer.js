// The tailor's page: one scan's body, its measurements, new ones drawn on it and
// evaluated by the server, saved by name, exported, shared with the customer.
import { api, enc } from '../api.js';
import { formatLength, preferredUnit } from '../units.js';
import { unitSelect } from '../ui/unit-select.js';
import { clear, confirmDialog, errorText, h, toast, when } from '../ui/dom.js';
import { BodyView, ModelDecoding } from '../viewer/body-view.js';
import { MeasureTool, TOOLS } from '../viewer/measure-tool.js';
import { arcEndsMoved, COLOURS, drawMeasurement, fillBoundText, isEstimate, KIND_LABEL, measurementTable, sideShowing, slug, tableLegend } from '../viewer/measurement-table.js';
import { postureCard } from '../viewer/posture.js';
import { avatarDialog } from './avatar-dialog.js';
import { shareDialog } from './share-dialog.js';
import { tapeDialog } from './tape-dialog.js';

/** @typedef {import('../api.js').Customer} Customer */
/** @typedef {import('../api.js').MeasureRequest} MeasureRequest */
/** @typedef {import('../api.js').Measurement} Measurement */
/** @typedef {import('../api.js').Posture} Posture */
/** @typedef {import('../api.js').Scan} Scan */
/** @typedef {import('../api.js').StoredMeasurement} StoredMeasurement */
/**
 * A measurement drawn and sent to the server: waiting for its answer, answered,
 * or refused.
 * @typedef {{ request: MeasureRequest, toolName: string, pending?: boolean, result?: Measurement, error?: string }} Fresh
 */

// The model's bytes, asked for at once (the current version, revalidated by its
// ETag), beside the scan's record rather than after it.
function fetchModel(id) {
  const bytes = fetch(`/api/scans/${enc(id)}/mesh.glb`, { credentials: 'same-origin' }).then((r) => {
    if (!r.ok) throw new Error(`the model is not available (${r.status})`);
    return r.arrayBuffer();
  });
  bytes.catch(() => {}); // a scan without a model never reads it
  return bytes;
}

// The server's export profiles for the CSV (GET /api/scans/{id}/sheet.csv?profile=).
const CSV_PROFILES = [
  ['sheet', 'the tailor'],
  ['iso8559', 'ISO 8559-1 systems'],
  ['mtm-order', 'a made-to-measure order'],
];

/**
 * @param {HTMLElement} container
 * @param {Record<string, string>} params
 * @param {import('../main.js').PageContext} ctx
 */
export async function mount(container, { id }, ctx) {
  const t0 = performance.now();
  performance.mark('bodyscan:open-scan');
  const bytes = fetchModel(id);
  const record = api.getScan(id);
  record.catch(() => {});
  // The model decodes in a worker while the page and its renderer are built:
  // wait (briefly) for its bytes, then one task more, so that the decoder's
  // worker has its job before the renderer's context takes the main thread.
  const model = new ModelDecoding(bytes);
  const nextTask = () => new Promise((r) => setTimeout(r, 0));
  await Promise.race([bytes.then(nextTask, () => {}), new Promise((r) => setTimeout(r, 250))]);
  const role = ctx.session.role;
  const state = {
    unit: preferredUnit(),
    /** @type {string | null} the name of the measurement drawn on the body */ selected: null,
    /** @type {Fresh | null} */ fresh: null,
    /** @type {StoredMeasurement[]} */ measurements: [],
    /** @type {Posture | null} */ posture: null,
    /** @type {Scan | null} */ scan: null,
    /** @type {Customer | null} */ customer: null,
    /** the CSV's layout: an export profile of the server's (docs/archive.md) */ profile: 'sheet',
  };

  const viewport = h('div', { class: 'viewport', id: 'viewport' });
  const hint = h('p', { class: 'hint', role: 'status' }, TOOLS.rotate.hint);
  const toolbar = h('div', { class: 'viewer-toolbar', role: 'toolbar', 'aria-label': 'Viewer' });
  const heading = h('div', { class: 'scan-heading' }, h('h1', {}, 'Scan'));
  const resultBox = h('div', { class: 'result card', hidden: true, 'aria-live': 'polite' });
  const tableBox = h('div', { class: 'table-box' });
  const postureBox = h('div', { class: 'posture-box' });
  const actions = h('div', { class: 'actions' });
  const side = h('aside', { class: 'viewer-side' }, heading, postureBox, h('h2', {}, 'Measurements'), tableBox, h('h2', {}, 'Sheet and sharing'), actions);
  // The result of a line just drawn sits on the 3-D view's top corner (beside the
  // head, where the view is empty), in sight however far the side panel is
  // scrolled, and without resizing the view under the user's fingers.
  viewport.append(resultBox);
  const page = h('section', { class: 'page viewer-page' }, h('div', { class: 'viewer-main' }, toolbar, viewport, hint), side);
  container.append(page);

  const view = new BodyView(viewport);
  const tool = new MeasureTool(view, { onRequest: (r, name) => evaluate(r, name), onHint: (t) => (hint.textContent = t) });
  let stopEvents = null;
  let disposed = false;

  // ---- toolbar
  const segmented = (name, options, current, onPick) => {
    const group = h('div', { class: 'segmented', role: 'radiogroup', 'aria-label': name });
    for (const [value, text] of options) {
      const b = h('button', { type: 'button', role: 'radio', 'aria-checked': value === current ? 'true' : 'false', dataset: { value } }, text);
      b.addEventListener('click', () => {
        for (const other of group.children) other.setAttribute('aria-checked', other === b ? 'true' : 'false');
        onPick(value);
      });
      group.append(b);
    }
    return group;
  };
  const viewGroup = segmented('View', [['front', 'Front'], ['left', 'Side'], ['back', 'Back']], 'front', (v) => view.setView(v));
  let pointsLoaded = false;
  toolbar.append(
    segmented('Show', [['mesh', 'Surface'], ['points', 'Points']], 'mesh', async (mode) => {
      if (mode === 'points' && !pointsLoaded) {
        pointsLoaded = true;
        try {
          await view.loadPoints(`/api/scans/${enc(id)}/points.drc?version=${state.scan.current_version}`);
        } catch (e) {
          toast(`The point cloud did not load: ${errorText(e)}`, 'error');
        }
      }
      view.setMode(mode);
      if (mode === 'points' && tool.mode !== 'rotate') hint.textContent = 'Measuring works on the surface; switch back to it.';
    }),
    viewGroup,
    segmented('Tool', Object.entries(TOOLS).map(([k, t]) => [k, t.label]), 'rotate', (m) => tool.setMode(m)),
    unitSelect(state.unit, (u) => {
      state.unit = u;
      renderTable();
      renderResult();
      renderActions();
    }),
  );

  // ---- data
  async function loadCustomer() {
    try {
      state.customer = await api.getCustomer(state.scan.customer_id);
    } catch {
      state.customer = null;
    }
    renderHeading();
  }

  async function loadMeasurements() {
    const m = await api.getMeasurements(id);
    state.measurements = m.measurements;
    state.posture = m.posture || null;
    clear(postureBox, postureCard(state.posture, state.measurements));
    renderTable();
    renderActions();
  }

  function renderHeading() {
    const s = state.scan;
    const others = (state.customer?.scans || []).filter((x) => x.id !== s.id && x.status === 'complete');
    clear(
      heading,
      h('h1', {}, state.customer ? state.customer.name : 'Scan'),
      h(
        'p',
        { class: 'muted' },
        `Scanned ${when(s.started_at)} by ${s.operator || '—'} · version ${s.current_version}`,
        s.status !== 'complete' ? h('span', { class: `badge ${s.status}` }, s.status) : null,
      ),
      s.status_reason ? h('p', { class: 'form-error' }, s.status_reason) : null,
      h(
        'p',
        { class: 'links' },
        state.customer ? h('a', { href: `/customers/${enc(s.customer_id)}` }, 'All scans of this customer') : null,
        others.length ? h('a', { href: `/compare/${enc(s.id)}/${enc(others[0].id)}` }, 'Compare with the previous scan') : null,
      ),
    );
  }

  function renderTable() {
    clear(
      tableBox,
      state.measurements.length
        ? [
            measurementTable({
              measurements: state.measurements,
              unit: state.unit,
              selected: state.selected,
              onSelect: (m) => select(m),
              onDelete: ctx.can.saveMeasurements(role) ? (m) => removeMeasurement(m) : null,
            }),
            tableLegend(state.measurements),
          ]
        : h('p', { class: 'muted' }, 'No measurements yet.'),
    );
  }

  /** @param {StoredMeasurement} m */
  function select(m) {
    state.selected = state.selected === m.name ? null : m.name;
    view.clearOverlays('sel');
    if (state.selected) {
      drawMeasurement(view, 'sel', m, COLOURS.selected);
      // One on the back or a side is turned to.
      const showing = sideShowing(m, view.modelBounds());
      if (showing && !view.facing(showing)) {
        view.setView(showing);
        for (const b of viewGroup.children) b.setAttribute('aria-checked', /** @type {HTMLElement} */ (b).dataset.value === showing ? 'true' : 'false');
      }
    }
    for (const row of tableBox.querySelectorAll('tr[data-name]')) {
      const on = row.dataset.name === state.selected;
      row.classList.toggle('selected', on);
      row.setAttribute('aria-selected', on ? 'true' : 'false');
    }
  }

  // ---- a new measurement, evaluated by the server
  let evaluating = 0;
  /**
   * @param {MeasureRequest} request
   * @param {string} toolName
   */
  async function evaluate(request, toolName) {
    const seq = ++evaluating;
    state.fresh = { request, toolName, pending: true };
    renderResult();
    try {
      const result = await api.measure(id, request);
      if (seq !== evaluating || disposed) return;
      state.fresh = { request, toolName, result };
      view.clearOverlays('pick:');
      drawMeasurement(view, 'fresh', result, COLOURS.fresh);
    } catch (e) {
      if (seq !== evaluating || disposed) return;
      state.fresh = { request, toolName, error: e.status === 422 ? `Nothing to measure there: ${e.message}` : errorText(e) };
      view.clearOverlays('pick:');
    }
    renderResult();
  }

  function renderResult() {
    const f = state.fresh;
    resultBox.hidden = !f;
    if (!f) return;
    if (f.pending) {
      clear(resultBox, h('p', { class: 'muted' }, `Measuring the ${f.toolName.toLowerCase()}…`));
      return;
    }
    if (f.error) {
      clear(resultBox, h('p', { class: 'form-error' }, f.error), h('button', { onclick: discard }, 'Close'));
      return;
    }
    const r = f.result;
    const name = h('input', { name: 'label', required: true, maxlength: 100, placeholder: 'e.g. Jacket chest', 'aria-label': 'Name' });
    const canSave = ctx.can.saveMeasurements(role);
    clear(
      resultBox,
      h('p', { class: 'result-value', dataset: { valueMm: String(r.value_mm) } }, h('strong', {}, formatLength(r.value_mm, state.unit)), ` ${KIND_LABEL[r.kind] || r.kind}`),
      isEstimate(r) ? h('p', { class: 'badge warn' }, `an estimate: skin the cameras did not see could move it ${fillBoundText(r, state.unit)}`) : null,
      arcNote(r),
      canSave
        ? h(
            'form',
            {
              class: 'row',
              onsubmit: async (e) => {
                e.preventDefault();
                await save(name.value.trim(), f.request);
              },
            },
            name,
            h('button', { class: 'primary', type: 'submit' }, 'Save'),
            h('button', { type: 'button', onclick: discard }, 'Discard'),
          )
        : h('div', { class: 'row' }, h('button', { type: 'button', onclick: discard }, 'Close')),
    );
    if (canSave) name.focus({ preventScroll: true });
  }

  // An arc whose ends the tape moved says so: by how much, and why it can be
  // shorter than the straight distance between the same taps.
  function arcNote(r) {
    const moved = arcEndsMoved(r);
    if (!moved) return null;
    const [a, b] = moved.moved.map((mm) => formatLength(mm, state.unit));
    return h(
      'p',
      { class: 'note arc-ends' },
      `The ends moved ${a} and ${b} onto the tape (a tape bridges hollows; the small dots are where you tapped), so the arc can be shorter than the straight distance.`,
    );
  }

  function discard() {
    state.fresh = null;
    view.clearOverlays('fresh');
    renderResult();
  }

  /**
   * @param {string} labelText
   * @param {MeasureRequest} request
   */
  async function save(labelText, request) {
    if (!labelText) return;
    const taken = new Set(state.measurements.map((m) => m.name));
    try {
      const saved = await api.saveMeasurement(id, { name: slug(labelText, taken), label: labelText, request });
      toast(`Saved “${saved.label}”: ${formatLength(saved.value_mm, state.unit)}`, 'ok');
      discard();
      await loadMeasurements();
      select(state.measurements.find((m) => m.id === saved.id) || saved);
    } catch (e) {
      toast(`Not saved: ${errorText(e)}`, 'error');
    }
  }

  /** @param {StoredMeasurement} m */
  async function removeMeasurement(m) {
    if (!(await confirmDialog(`Delete the saved measurement “${m.label || m.name}”?`, { confirm: 'Delete', danger: true }))) return;
    try {
      await api.deleteMeasurement(id, m.id);
      if (state.selected === m.name) select(m);
      await loadMeasurements();
    } catch (e) {
      toast(errorText(e), 'error');
    }
  }

  // ---- sheets, sharing, admin
  function renderActions() {
    const u = state.unit;
    clear(
      actions,
      h(
        'div',
        { class: 'row wrap' },
        h(
          'label',
          { class: 'field inline' },
          h('span', {}, 'CSV for'),
          h(
            'select',
            { name: 'profile', 'aria-label': 'CSV layout', onchange: (e) => ((state.profile = e.target.value), renderActions()) },
            CSV_PROFILES.map(([value, label]) => h('option', { value, selected: value === state.profile }, label)),
          ),
        ),
        h('a', { class: 'button', href: `/api/scans/${enc(id)}/sheet.csv?unit=${u}&profile=${state.profile}`, download: `${id}-${state.profile === 'sheet' ? 'measurements' : state.profile}.csv` }, 'Export CSV'),
        h('a', { class: 'button', href: `/api/scans/${enc(id)}/sheet.pdf?unit=${u}`, download: `${id}-measurements.pdf` }, 'Export PDF'),
        h('button', { type: 'button', onclick: () => avatarDialog(id, state.unit) }, 'Avatar for CAD…'),
        ctx.can.share(role) ? h('button', { type: 'button', onclick: () => shareDialog(id, state.measurements, state.unit) }, 'Share with customer…') : null,
        h('button', { type: 'button', onclick: () => tapeDialog(id, state.measurements, state.unit, ctx.session.user.username) }, 'Tape measurements…'),
      ),
      ctx.can.deleteRecords(role)
        ? h(
            'div',
            { class: 'row wrap admin-actions' },
            ctx.can.reprocess(role) ? h('button', { type: 'button', onclick: reprocess }, 'Reprocess') : null,
            h('button', { type: 'button', class: 'danger', onclick: deleteScan }, 'Delete scan…'),
          )
        : null,
    );
  }

  async function reprocess() {
    if (!(await confirmDialog('Process this scan again from its raw record? It becomes a new version; the old one is kept.', { confirm: 'Reprocess' }))) return;
    try {
      await api.reprocess(id);
      toast('Reprocessing; the new version opens when it is done.', 'ok');
      watchJob();
    } catch (e) {
      toast(errorText(e), 'error');
    }
  }

  async function deleteScan() {
    if (!(await confirmDialog('Delete this scan, its model, measurements and share links? This cannot be undone.', { title: 'Delete scan', confirm: 'Delete', danger: true }))) return;
    try {
      await api.deleteScan(id);
      toast('Scan deleted.', 'ok');
      ctx.router.navigate(state.scan?.customer_id ? `/customers/${enc(state.scan.customer_id)}` : '/archive');
    } catch (e) {
      toast(errorText(e), 'error');
    }
  }

  // A scan or reprocess still running: reload when it ends.
  function watchJob() {
    if (stopEvents) return;
    stopEvents = ctx.events().subscribe((msg) => {
      if (msg.type === 'scan_finished' && msg.job && msg.job.scan_id === id) {
        stopEvents();
        stopEvents = null;
        ctx.router.render();
      }
    });
  }

  // ---- open
  try {
    state.scan = await record;
    renderHeading();
  } catch (e) {
    clear(page, h('div', { class: 'page narrow' }, h('h1', {}, 'Scan not found'), h('p', {}, errorText(e)), h('a', { href: '/archive' }, 'Back to the archive')));
    view.dispose();
    return () => {};
  }
  loadCustomer();
  if (state.scan.status === 'running') {
    hint.textContent = 'This scan is still being made; it opens when it is done.';
    watchJob();
  } else if (state.scan.status === 'complete' || state.scan.current_version > 0) {
    Promise.all([view.loadMesh(model, { t0 }), loadMeasurements()]).catch((e) => {
      if (!disposed) toast(`The model did not load: ${errorText(e)}`, 'error');
    });
  } else {
    hint.textContent = 'This scan has no model.';
  }

  return () => {
    disposed = true;
    if (stopEvents) stopEvents();
    tool.dispose();
    view.dispose();
  };
}
