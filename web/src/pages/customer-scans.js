// A customer: their consent (the terms they agreed to, when, recorded by whom),
// their scans, two of them compared side by side, and (admin) the customer
// erased with everything stored about them.
import { api, enc } from '../api.js';
import { clear, confirmDialog, errorText, h, toast, when } from '../ui/dom.js';

/**
 * @param {HTMLElement} container
 * @param {Record<string, string>} params
 * @param {import('../main.js').PageContext} ctx
 */
export async function mount(container, { id }, ctx) {
  /** @type {import('../api.js').Customer} */
  let customer;
  try {
    customer = await api.getCustomer(id);
  } catch (e) {
    container.append(h('section', { class: 'page narrow' }, h('h1', {}, 'Customer not found'), h('p', {}, errorText(e)), h('a', { href: '/archive' }, 'Back to the archive')));
    return;
  }
  const chosen = new Set();
  const compare = h('button', { type: 'button', class: 'primary', disabled: true }, 'Compare the two chosen');
  compare.addEventListener('click', () => {
    const [a, b] = [...chosen];
    ctx.router.navigate(`/compare/${enc(a)}/${enc(b)}`);
  });
  const scans = customer.scans || [];
  const rows = scans.map((s) => {
    const box = h('input', {
      type: 'checkbox',
      'aria-label': `Choose the scan of ${when(s.started_at)} to compare`,
      disabled: s.status !== 'complete',
      onchange: (e) => {
        if (e.target.checked) chosen.add(s.id);
        else chosen.delete(s.id);
        if (chosen.size > 2) {
          const first = [...chosen][0];
          chosen.delete(first);
          /** @type {HTMLInputElement | null} */
          const other = container.querySelector(`input[data-scan="${CSS.escape(first)}"]`);
          if (other) other.checked = false;
        }
        compare.disabled = chosen.size !== 2;
      },
    });
    box.dataset.scan = s.id;
    return h(
      'tr',
      {},
      h('td', {}, box),
      h('td', {}, h('a', { href: `/scans/${enc(s.id)}` }, when(s.started_at))),
      h('td', {}, h('span', { class: `badge ${s.status}` }, s.status), s.status_reason ? h('small', { class: 'muted' }, ` ${s.status_reason}`) : null),
      h('td', {}, s.operator || '—'),
    );
  });
  container.append(
    h(
      'section',
      { class: 'page narrow customer-scans' },
      h('p', {}, h('a', { href: '/archive' }, '← Archive')),
      h('h1', {}, customer.name),
      h('p', { class: 'muted' }, `${customer.contact ? `${customer.contact} · ` : ''}customer since ${when(customer.created_at)} · ${customer.id}`),
      customer.consent
        ? h(
            'details',
            { class: 'consent-record', id: 'consent-record' },
            h('summary', {}, `Consent given ${when(customer.consent.given_at)}, recorded by ${customer.consent.recorded_by}`),
            h('p', { class: 'consent-terms' }, customer.consent.terms),
          )
        : h('p', { class: 'form-error', id: 'consent-record' }, 'No consent on record: the next scan asks for it.'),
      scans.length
        ? h('table', { class: 'list' }, h('thead', {}, h('tr', {}, h('th', {}, h('span', { class: 'sr-only' }, 'Compare')), h('th', {}, 'Taken'), h('th', {}, 'Status'), h('th', {}, 'Operator'))), h('tbody', {}, rows))
        : h('p', { class: 'muted' }, 'No scans yet.'),
      scans.length > 1 ? h('div', { class: 'row' }, compare) : null,
      ctx.can.deleteRecords(ctx.session.role)
        ? h(
            'div',
            { class: 'danger-zone' },
            h('h2', {}, 'Erase this customer'),
            h('p', { class: 'muted' }, 'Removes the customer, their consent, every scan, model, measurement and share link, and the audit entries naming them (a customer’s right to erasure).'),
            h(
              'button',
              {
                type: 'button',
                class: 'danger',
                onclick: async () => {
                  if (!(await confirmDialog(`Erase ${customer.name} and all ${scans.length} scan(s)? This cannot be undone.`, { title: 'Erase customer', confirm: 'Erase', danger: true }))) return;
                  try {
                    await api.eraseCustomer(id);
                    toast(`${customer.name} erased.`, 'ok');
                    ctx.router.navigate('/archive');
                  } catch (e) {
                    toast(errorText(e), 'error');
                  }
                },
              },
              'Erase customer…',
            ),
          )
        : null,
    ),
  );
  return () => clear(container);
}
