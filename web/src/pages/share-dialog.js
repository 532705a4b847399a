// A customer share link: which measurements the customer sees, how long the link
// lasts, the head, a PIN; the link is shown once (the server keeps only its
// hash), with a QR code the customer scans with their phone, so that it is handed
// over rather than typed. The scan's other links are listed with their expiry and
// can be withdrawn.
import QRCode from 'qrcode';
import { api } from '../api.js';
import { formatLength, preferredUnit } from '../units.js';
import { clear, errorText, h, toast, when } from '../ui/dom.js';

/**
 * @param {string} scanId
 * @param {import('../api.js').StoredMeasurement[]} measurements the scan's, to choose from
 * @param {string} unit
 */
export async function shareDialog(scanId, measurements, unit) {
  const list = h('div', { class: 'share-list' });
  const checks = measurements.map((m) =>
    h('label', { class: 'check' }, h('input', { type: 'checkbox', name: 'measurement', value: m.name, checked: false }), ` ${m.label || m.name} `, h('small', { class: 'muted' }, formatLength(m.value_mm, unit))),
  );
  const days = h('input', { type: 'number', name: 'days', min: 1, max: 365, value: '7', required: true, class: 'short' });
  // The head is left out of the model the link serves unless staff include it.
  const head = h('input', { type: 'checkbox', name: 'include_head' });
  const pin = h('input', { type: 'checkbox', name: 'pin' });
  const made = h('div', { class: 'share-made', hidden: true });
  const form = h(
    'form',
    { class: 'share-form' },
    h('h2', {}, 'Share with the customer'),
    h('p', { class: 'muted' }, 'The customer sees the model without the head and the measurements ticked here, nothing else, until the link expires or is withdrawn.'),
    h('div', { class: 'row' }, h('button', { type: 'button', onclick: () => checks.forEach((c) => (c.querySelector('input').checked = true)) }, 'All'), h('button', { type: 'button', onclick: () => checks.forEach((c) => (c.querySelector('input').checked = false)) }, 'None')),
    h('div', { class: 'check-list' }, checks),
    h('label', { class: 'check' }, head, h('span', {}, 'Show the head in the model (the customer asked for it)')),
    h('label', { class: 'check' }, pin, h('span', {}, 'Protect with a PIN that you read out to the customer')),
    h('label', { class: 'field inline' }, h('span', {}, 'Valid for (days)'), days),
    h('div', { class: 'row end' }, h('button', { type: 'button', value: 'close', onclick: () => dialog.close() }, 'Close'), h('button', { class: 'primary', type: 'submit' }, 'Make link')),
    made,
    h('h3', {}, 'Links of this scan'),
    list,
  );
  const dialog = h('dialog', { class: 'dialog wide' }, form);

  async function refresh() {
    try {
      const { shares } = await api.listShares(scanId);
      const now = Date.now() / 1000;
      clear(
        list,
        shares.length
          ? h(
              'ul',
              { class: 'plain' },
              shares.map((s) =>
                h(
                  'li',
                  {},
                  `${when(s.created_at)} by ${s.created_by} · ${s.measurements.length} measurements · `,
                  s.revoked ? h('span', { class: 'badge' }, 'withdrawn') : s.expires_at < now ? h('span', { class: 'badge' }, 'expired') : `until ${when(new Date(s.expires_at * 1000).toISOString())} `,
                  !s.revoked && s.expires_at >= now
                    ? h(
                        'button',
                        {
                          type: 'button',
                          class: 'link danger-text',
                          onclick: async () => {
                            try {
                              await api.withdrawShare(s.id);
                              refresh();
                            } catch (e) {
                              toast(errorText(e), 'error');
                            }
                          },
                        },
                        'Withdraw',
                      )
                    : null,
                ),
              ),
            )
          : h('p', { class: 'muted' }, 'None yet.'),
      );
    } catch (e) {
      clear(list, h('p', { class: 'form-error' }, errorText(e)));
    }
  }

  form.addEventListener('submit', async (e) => {
    e.preventDefault();
    const names = checks.map((c) => c.querySelector('input')).filter((i) => i.checked).map((i) => i.value);
    try {
      const share = await api.makeShare(scanId, { days: Number(days.value), measurements: names, include_head: head.checked, pin: pin.checked });
      const url = share.url && /^https?:/.test(share.url) ? share.url : `${location.origin}/s/${share.token}`;
      const field = h('input', { readonly: true, value: url, class: 'share-url', 'aria-label': 'Share link', onfocus: (ev) => ev.target.select() });
      const qr = h('canvas', { class: 'share-qr', role: 'img', 'aria-label': 'QR code of the link, for the customer to scan with their phone' });
      clear(
        made,
        h('p', {}, 'Give the customer this link (it is shown only now):'),
        h(
          'div',
          { class: 'row' },
          field,
          h(
            'button',
            {
              type: 'button',
              onclick: async () => {
                try {
                  await navigator.clipboard.writeText(url);
                  toast('Link copied.', 'ok');
                } catch {
                  field.select();
                }
              },
            },
            'Copy',
          ),
        ),
        qr,
        share.pin_code ? h('p', { class: 'share-pin' }, 'Read out the PIN (shown only now): ', h('strong', { class: 'pin-code' }, share.pin_code)) : null,
        h(
          'button',
          {
            type: 'button',
            class: 'customer-sheet',
            title: "The customer's sheet to print: their name, these measurements under plain names, the link's QR code",
            onclick: async () => {
              try {
                const blob = await api.getShareSheet(share.token, preferredUnit(), undefined, share.pin_code);
                window.open(URL.createObjectURL(blob), '_blank', 'noopener');
              } catch (err) {
                toast(`No sheet: ${errorText(err)}`, 'error');
              }
            },
          },
          'Customer sheet (PDF)',
        ),
      );
      await QRCode.toCanvas(qr, url, { errorCorrectionLevel: 'M', margin: 4, width: 240 });
      made.hidden = false;
      refresh();
    } catch (err) {
      toast(`No link made: ${errorText(err)}`, 'error');
    }
  });
  dialog.addEventListener('close', () => dialog.remove());
  document.body.append(dialog);
  dialog.showModal();
  refresh();
  return dialog;
}
