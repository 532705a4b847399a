// Two scans of one customer side by side: the bodies turn together, the table
// gives both values and the change; a row draws its line on both bodies.
import { api, enc } from '../api.js';
import { preferredUnit } from '../units.js';
import { unitSelect } from '../ui/unit-select.js';
import { clear, errorText, h, when } from '../ui/dom.js';
import { BodyView } from '../viewer/body-view.js';
import { COLOURS, drawMeasurement, measurementTable, tableLegend } from '../viewer/measurement-table.js';

export async function mount(container, { a, b }) {
  let unit = preferredUnit();
  let selected = null;
  /** @type {import('../api.js').Scan[]} */
  let scans;
  try {
    scans = await Promise.all([a, b].map((id) => api.getScan(id)));
  } catch (e) {
    container.append(h('section', { class: 'page narrow' }, h('h1', {}, 'Scans not found'), h('p', {}, errorText(e))));
    return;
  }
  // Older first on the left.
  scans.sort((x, y) => (x.started_at < y.started_at ? -1 : 1));
  const [older, newer] = scans;
  const customer = await api.getCustomer(newer.customer_id).catch(() => null);
  const ports = scans.map(() => h('div', { class: 'viewport' }));
  const tableBox = h('div', { class: 'table-box' });
  container.append(
    h(
      'section',
      { class: 'page compare-page' },
      h(
        'div',
        { class: 'page-head' },
        h('h1', {}, `Compare: ${customer ? customer.name : ''}`),
        customer ? h('a', { href: `/customers/${enc(customer.id)}` }, 'All scans of this customer') : null,
        unitSelect(unit, (u) => {
          unit = u;
          render();
        }),
      ),
      older.customer_id !== newer.customer_id ? h('p', { class: 'form-error' }, 'These scans are of two different customers.') : null,
      h(
        'div',
        { class: 'compare-views' },
        scans.map((s, i) => h('figure', { class: 'compare-view' }, ports[i], h('figcaption', {}, h('a', { href: `/scans/${enc(s.id)}` }, when(s.started_at)), i === 0 ? ' (earlier)' : ' (later)'))),
      ),
      h('h2', {}, 'Measurements'),
      tableBox,
    ),
  );
  const views = ports.map((p) => new BodyView(p));
  // The cameras follow each other (the change event of one moves the other).
  let syncing = false;
  views.forEach((v, i) =>
    v.onCameraChange(() => {
      if (syncing) return;
      syncing = true;
      views[1 - i].copyCamera(v);
      syncing = false;
    }),
  );
  /** @type {[import('../api.js').StoredMeasurement[], import('../api.js').StoredMeasurement[]]} the earlier scan's, the later's */
  let sets = [[], []];
  function render() {
    // Every measurement of either scan, saved ones too: the later scan's, then
    // what only the earlier has (without a later value), the automatic set first.
    const laterNames = new Set(sets[1].map((m) => m.name));
    const rows = [...sets[1], ...sets[0].filter((m) => !laterNames.has(m.name)).map((m) => ({ ...m, value_mm: NaN, geometry: {} }))];
    rows.sort((x, y) => (x.source === y.source ? 0 : x.source === 'automatic' ? -1 : y.source === 'automatic' ? 1 : 0));
    clear(
      tableBox,
      measurementTable({
        measurements: rows,
        compareWith: sets[0],
        // In the order of the bodies above: the earlier on the left.
        columns: [`Earlier (${when(older.started_at)})`, `Later (${when(newer.started_at)})`],
        otherFirst: true,
        unit,
        selected,
        onSelect: (m) => {
          selected = selected === m.name ? null : m.name;
          views.forEach((v, i) => {
            v.clearOverlays('sel');
            const mine = sets[i].find((x) => x.name === selected);
            if (mine) drawMeasurement(v, 'sel', mine, i === 0 ? COLOURS.compare : COLOURS.selected);
          });
          render();
        },
      }),
      tableLegend(rows),
    );
  }
  try {
    const [m0, m1] = await Promise.all(scans.map((s) => api.getMeasurements(s.id)));
    sets = [m0.measurements, m1.measurements];
    render();
  } catch (e) {
    clear(tableBox, h('p', { class: 'form-error' }, errorText(e)));
  }
  scans.forEach((s, i) => views[i].loadMesh(`/api/scans/${enc(s.id)}/mesh.glb?version=${s.current_version}`).catch((e) => ports[i].append(h('p', { class: 'form-error overlay' }, errorText(e)))));
  return () => views.forEach((v) => v.dispose());
}
