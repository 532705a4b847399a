// Find scans by customer, text and date; open, or (admin) delete with
// confirmation.
import { api, enc, query } from '../api.js';
import { clear, confirmDialog, errorText, h, toast, when } from '../ui/dom.js';

/**
 * @param {HTMLElement} container
 * @param {Record<string, string>} _params
 * @param {import('../main.js').PageContext} ctx
 */
export async function mount(container, _params, ctx) {
  const params = new URLSearchParams(location.search);
  const q = h('input', { type: 'search', name: 'q', value: params.get('q') || '', placeholder: 'Customer name, contact, operator or scan id', 'aria-label': 'Search' });
  const from = h('input', { type: 'date', name: 'from', value: params.get('from') || '', 'aria-label': 'From' });
  const to = h('input', { type: 'date', name: 'to', value: params.get('to') || '', 'aria-label': 'To' });
  const results = h('div', { class: 'results', 'aria-live': 'polite' });
  const isAdmin = ctx.can.deleteRecords(ctx.session.role);
  container.append(
    h(
      'section',
      { class: 'page archive-page' },
      h('h1', {}, 'Archive'),
      h(
        'form',
        {
          class: 'card filters row wrap',
          role: 'search',
          onsubmit: (e) => {
            e.preventDefault();
            const next = `/archive${query({ q: q.value.trim(), from: from.value, to: to.value })}`;
            history.replaceState(null, '', next);
            load();
          },
        },
        h('label', { class: 'field grow' }, h('span', {}, 'Search'), q),
        h('label', { class: 'field' }, h('span', {}, 'From'), from),
        h('label', { class: 'field' }, h('span', {}, 'To'), to),
        h('button', { class: 'primary', type: 'submit' }, 'Find'),
      ),
      results,
    ),
  );

  async function load() {
    clear(results, h('p', { class: 'muted' }, 'Searching…'));
    try {
      // The server compares "to" as a prefix of the ISO 8601 time: the whole day counts.
      const [{ scans }, { customers }] = await Promise.all([
        api.findScans({ q: q.value.trim(), from: from.value, to: to.value, limit: 500 }),
        api.findCustomers(),
      ]);
      const names = new Map(customers.map((c) => [c.id, c]));
      if (!scans.length) {
        clear(results, h('p', { class: 'muted' }, 'No scan matches.'));
        return;
      }
      clear(
        results,
        h('p', { class: 'muted small' }, `${scans.length} scan${scans.length === 1 ? '' : 's'}`),
        h(
          'table',
          { class: 'list' },
          h('thead', {}, h('tr', {}, h('th', {}, 'Taken'), h('th', {}, 'Customer'), h('th', {}, 'Status'), h('th', {}, 'Operator'), h('th', {}, ''))),
          h(
            'tbody',
            {},
            scans.map((s) => {
              const c = names.get(s.customer_id);
              return h(
                'tr',
                { dataset: { scan: s.id } },
                h('td', {}, h('a', { href: `/scans/${enc(s.id)}` }, when(s.started_at))),
                h('td', {}, c ? h('a', { href: `/customers/${enc(c.id)}` }, c.name) : s.customer_id),
                h('td', {}, h('span', { class: `badge ${s.status}` }, s.status), s.current_version > 1 ? h('small', { class: 'muted' }, ` v${s.current_version}`) : null),
                h('td', {}, s.operator || '—'),
                h(
                  'td',
                  { class: 'end' },
                  h('a', { class: 'button small', href: `/scans/${enc(s.id)}` }, 'Open'),
                  isAdmin ? h('button', { type: 'button', class: 'small danger', onclick: () => remove(s, c) }, 'Delete') : null,
                ),
              );
            }),
          ),
        ),
      );
    } catch (e) {
      clear(results, h('p', { class: 'form-error' }, errorText(e)));
    }
  }

  /**
   * @param {import('../api.js').Scan} s
   * @param {import('../api.js').Customer | undefined} c its customer, when known
   */
  async function remove(s, c) {
    const who = c ? `${c.name}’s scan` : 'the scan';
    if (!(await confirmDialog(`Delete ${who} of ${when(s.started_at)}, with its model, measurements and share links? This cannot be undone.`, { title: 'Delete scan', confirm: 'Delete', danger: true }))) return;
    try {
      await api.deleteScan(s.id);
      toast('Scan deleted.', 'ok');
      load();
    } catch (e) {
      toast(errorText(e), 'error');
    }
  }

  load();
}
