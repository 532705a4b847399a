// Proof of accuracy in the shop (ISO 20685-1): per measurement, how far the
// scanner's values lie from the tape measurements staff entered (each scan's
// "Tape measurements…"), over every customer measured both ways. Differences are
// in millimetres, the standard's unit.
import { api } from '../api.js';
import { clear, errorText, h } from '../ui/dom.js';

const mm = (v) => (v === null || v === undefined ? '—' : `${v > 0 ? '+' : v < 0 ? '−' : '±'}${Math.abs(v).toFixed(1)}`);

const VERDICT = {
  within: ['within', 'complete'],
  more_subjects: ['', 'warn'],
  outside: ['mean outside the allowance', 'failed'],
  too_few: ['', ''],
};

/** @param {{verdict: string, more_subjects: number}} row */
function verdictText(row) {
  const customers = (n) => `${n} more customer${n === 1 ? '' : 's'}`;
  if (row.verdict === 'more_subjects') return `needs ${customers(row.more_subjects)}`;
  if (row.verdict === 'too_few') return `needs ${customers(row.more_subjects)} for an interval`;
  return VERDICT[row.verdict]?.[0] || row.verdict;
}

/**
 * @param {HTMLElement} container
 */
export async function mount(container) {
  const body = h('div', { class: 'validation-body', 'aria-live': 'polite' }, h('p', { class: 'muted' }, 'Loading…'));
  container.append(
    h(
      'section',
      { class: 'page validation-page' },
      h('h1', {}, 'Validation against tape'),
      h(
        'p',
        {},
        'ISO 20685-1 judges a body scanner by the same customers measured by hand: per measurement, the mean of scan minus tape and its 95 % confidence interval must lie within the allowance (9 mm for the large girths; 4 mm for the small girths, heights and breadths; 5 mm for lengths). Enter tape values from a scan’s page (“Tape measurements…”). Each customer counts once per measurement, with their newest scan that has a tape value.',
      ),
      body,
    ),
  );
  let report;
  try {
    report = await api.getValidation();
  } catch (e) {
    clear(body, h('p', { class: 'form-error' }, `The report did not load: ${errorText(e)}`));
    return;
  }
  const rows = report.measurements;
  clear(
    body,
    h(
      'p',
      { class: 'row wrap' },
      h('span', { class: 'summary' }, `${report.customers} customer${report.customers === 1 ? '' : 's'}, ${report.tape_values} tape value${report.tape_values === 1 ? '' : 's'}.`),
      h('a', { class: 'button', href: '/api/validation.pdf', download: 'validation-iso-20685-1.pdf' }, 'Report (PDF)'),
    ),
    rows.length
      ? h(
          'div',
          { class: 'table-box' },
          h(
            'table',
            { class: 'measurements validation' },
            h(
              'thead',
              {},
              h(
                'tr',
                {},
                ['Measurement', 'Customers', 'Mean, mm', '95 % interval, mm', 'Allowed, mm', 'Verdict', 'Tape by'].map((t, i) => h('th', { scope: 'col', class: i >= 1 && i <= 4 ? 'num' : '' }, t)),
              ),
            ),
            h(
              'tbody',
              {},
              rows.map((r) =>
                h(
                  'tr',
                  { dataset: { name: r.name, verdict: r.verdict } },
                  h('th', { scope: 'row' }, r.label, h('small', { class: 'muted' }, ` ${r.iso_clause}`)),
                  h('td', { class: 'num' }, String(r.subjects)),
                  h('td', { class: 'num' }, mm(r.mean_difference_mm)),
                  h('td', { class: 'num' }, r.ci_low_mm === null ? '—' : `${mm(r.ci_low_mm)} to ${mm(r.ci_high_mm)}`),
                  h('td', { class: 'num' }, `±${r.allowance_mm}`),
                  h('td', {}, h('span', { class: `badge ${VERDICT[r.verdict]?.[1] || ''}` }, verdictText(r))),
                  h('td', {}, r.measured_by.join(', ')),
                ),
              ),
            ),
          ),
        )
      : h('p', { class: 'muted' }, 'No tape measurements entered yet.'),
  );
}
