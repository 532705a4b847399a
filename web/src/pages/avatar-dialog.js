// An avatar for the pattern-making tools (CLO3D, Browzwear, Optitex): the scan's
// surface decimated on the server to the triangle budget the tool asks for, as an
// OBJ (mm or m) or a plain GLB (metres), with the measurement sheet beside it.
// The links are plain downloads: the browser saves what the server sends.
import { enc } from '../api.js';
import { h } from '../ui/dom.js';

/**
 * @param {string} scanId
 * @param {string} unit the sheet's unit, as the viewer shows it
 */
export function avatarDialog(scanId, unit) {
  const format = h('select', { name: 'format' }, h('option', { value: 'obj' }, 'OBJ'), h('option', { value: 'glb' }, 'GLB (glTF, no compression)'));
  const objUnit = h('select', { name: 'unit' }, h('option', { value: 'mm' }, 'millimetres'), h('option', { value: 'm' }, 'metres'));
  const triangles = h('input', { type: 'number', name: 'triangles', min: 1000, max: 5000000, step: 1000, value: '70000', required: true, class: 'short' });
  const unitField = h('label', { class: 'field inline' }, h('span', {}, 'Unit'), objUnit);
  const download = h('a', { class: 'button primary' }, 'Download avatar');
  const sheet = h('a', { class: 'button', href: `/api/scans/${enc(scanId)}/sheet.csv?unit=${enc(unit)}`, download: `${scanId}-measurements.csv` }, 'Download the sheet (CSV)');
  const note = h('p', { class: 'muted' });

  function update() {
    const glb = format.value === 'glb';
    unitField.hidden = glb;
    const n = Math.round(Number(triangles.value));
    const valid = Number.isFinite(n) && n >= 1000 && n <= 5000000;
    const query = `triangles=${valid ? n : 70000}` + (glb ? '' : `&unit=${objUnit.value}`);
    download.href = `/api/scans/${enc(scanId)}/avatar.${format.value}?${query}`;
    download.download = `${scanId}-avatar.${format.value}`;
    note.textContent = glb
      ? 'A glTF binary in metres, as glTF defines. The surface is closed; the measurements stay on the full scan.'
      : 'Tell the importer the unit: OBJ files carry none. The surface is closed; the measurements stay on the full scan.';
  }
  for (const el of [format, objUnit, triangles]) el.addEventListener('input', update);

  const dialog = h(
    'dialog',
    { class: 'dialog' },
    h(
      'form',
      { method: 'dialog', class: 'avatar-form' },
      h('h2', {}, 'Avatar for CAD'),
      h('p', {}, 'The body decimated to a triangle budget for draping in CLO3D, Browzwear or Optitex (CLO3D asks for about 70,000).'),
      h('label', { class: 'field inline' }, h('span', {}, 'Format'), format),
      h('label', { class: 'field inline' }, h('span', {}, 'Triangles'), triangles),
      unitField,
      note,
      h('div', { class: 'row wrap end' }, h('button', { type: 'submit', value: 'close' }, 'Close'), sheet, download),
    ),
  );
  update();
  dialog.addEventListener('close', () => dialog.remove());
  document.body.append(dialog);
  dialog.showModal();
  return dialog;
}
