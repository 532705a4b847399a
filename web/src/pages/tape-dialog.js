// Tape measurements for a scan (ISO 20685-1 validation): staff who measured the
// customer by hand enter their readings beside the scan's automatic values; the
// workstation's validation report (/validation) compares the two over every
// customer. A cleared field removes that reading.
import { api } from '../api.js';
import { convert, formatDifference, formatLength, UNITS } from '../units.js';
import { errorText, h, toast } from '../ui/dom.js';

/** @typedef {import('../api.js').StoredMeasurement} StoredMeasurement */

/**
 * @param {string} scanId
 * @param {StoredMeasurement[]} measurements the scan's; the automatic ones are offered
 * @param {string} unit as the viewer shows lengths
 * @param {string} username who measured, unless the scan has readings already
 */
export async function tapeDialog(scanId, measurements, unit, username) {
  const automatic = measurements.filter((m) => m.source === 'automatic');
  /** @type {Map<string, {value_mm: number, measured_by: string}>} */
  const entered = new Map();
  try {
    for (const t of (await api.getTape(scanId)).tape) entered.set(t.name, t);
  } catch (e) {
    toast(`The tape measurements did not load: ${errorText(e)}`, 'error');
    return null;
  }
  // Whoever took this scan's readings so far, else the user.
  const earlier = [...entered.values()].at(-1);
  const who = h('input', { name: 'measured_by', required: true, maxlength: 200, value: earlier ? earlier.measured_by : username, autocomplete: 'name' });
  const error = h('p', { class: 'form-error', role: 'alert' });
  const rows = automatic.map((m) => {
    const before = entered.get(m.name);
    const input = h('input', {
      type: 'number',
      name: m.name,
      class: 'short',
      // Any reading (a tape's 0.5 cm too); the server keeps it within 1 mm to 3 m.
      min: '0',
      max: String(convert(3000, unit)),
      step: 'any',
      inputmode: 'decimal',
      value: before ? convert(before.value_mm, unit).toFixed(UNITS[unit].digits) : '',
      'aria-label': `${m.label} by tape, ${UNITS[unit].label}`,
    });
    const difference = h('td', { class: 'num muted' });
    const update = () => {
      const tape = input.value === '' ? NaN : Number(input.value) / UNITS[unit].perMm;
      difference.textContent = Number.isFinite(tape) ? formatDifference(m.value_mm - tape, unit) : '';
    };
    input.addEventListener('input', update);
    update();
    const row = h('tr', { dataset: { name: m.name } }, h('th', { scope: 'row' }, m.label), h('td', { class: 'num' }, formatLength(m.value_mm, unit)), h('td', {}, input), difference);
    return { m, input, initial: input.value, before, row };
  });

  async function save() {
    error.textContent = '';
    const measuredBy = who.value.trim();
    // A row changed its reading, or keeps one now credited to someone else.
    const changes = rows.filter(({ input, initial, before }) => input.value !== initial || (input.value !== '' && before && before.measured_by !== measuredBy));
    let saved = 0;
    for (const { m, input, before } of changes) {
      try {
        if (input.value === '') {
          if (before) await api.deleteTape(scanId, m.name);
        } else {
          await api.putTape(scanId, m.name, { value_mm: Number(input.value) / UNITS[unit].perMm, measured_by: measuredBy });
        }
        saved += 1;
      } catch (e) {
        error.textContent = `${m.label}: ${errorText(e)}`;
        input.focus();
        return false;
      }
    }
    toast(saved ? `${saved} tape value${saved === 1 ? '' : 's'} saved.` : 'Nothing changed.', 'ok');
    return true;
  }

  const form = h(
    'form',
    {
      class: 'tape-form',
      onsubmit: async (e) => {
        e.preventDefault();
        if (!form.reportValidity()) return;
        if (await save()) dialog.close();
      },
    },
    h('h2', {}, 'Tape measurements'),
    h('p', {}, 'Enter what you measured on the customer by hand. The validation report compares them with the scanner over all customers (ISO 20685-1).'),
    h('label', { class: 'field inline' }, h('span', {}, 'Measured by'), who),
    h(
      'div',
      { class: 'table-box tape-table' },
      h(
        'table',
        { class: 'measurements' },
        h('thead', {}, h('tr', {}, h('th', { scope: 'col' }, 'Measurement'), h('th', { scope: 'col', class: 'num' }, 'Scan'), h('th', { scope: 'col' }, `Tape (${UNITS[unit].label})`), h('th', { scope: 'col', class: 'num' }, 'Scan − tape'))),
        h('tbody', {}, rows.map((r) => r.row)),
      ),
    ),
    error,
    h('div', { class: 'row wrap end' }, h('button', { type: 'button', onclick: () => dialog.close() }, 'Cancel'), h('button', { type: 'submit', class: 'primary' }, 'Save')),
  );
  const dialog = h('dialog', { class: 'dialog wide', 'aria-label': 'Tape measurements' }, form);
  dialog.addEventListener('close', () => dialog.remove());
  document.body.append(dialog);
  dialog.showModal();
  who.focus();
  return dialog;
}
