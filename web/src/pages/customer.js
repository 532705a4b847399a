// The customer's page, opened from a share link: that scan's model and the
// measurements staff chose, read-only. It calls only /api/share/{token}/…; the
// token is the whole of the customer's access, with the PIN the shop read out
// where the link has one (kept in this page only, never stored).
import { api, enc } from '../api.js';
import { preferredUnit } from '../units.js';
import { unitSelect } from '../ui/unit-select.js';
import { clear, errorText, h } from '../ui/dom.js';
import { customerLocale, customerWords, formatWhen } from '../i18n.js';
import { BodyView } from '../viewer/body-view.js';
import { COLOURS, drawMeasurement, isEstimate, measurementTable } from '../viewer/measurement-table.js';

export async function mount(container, { token }) {
  const t0 = performance.now();
  let unit = preferredUnit();
  /** @type {import('../api.js').ShareView} */
  let share;
  /** @type {string | undefined} */
  let pin;
  // Before the link opens, the shop's language is not known: this browser's choice,
  // else its own language.
  const early = customerWords(customerLocale(chosenLocale() || navigator.language));
  try {
    share = await api.getShare(token);
  } catch (e) {
    if (e.status === 401) {
      // The link asks for its PIN: the page asks, and opens once it is right.
      pin = await askPin(container, token, early);
      if (pin === undefined) return;
      share = await api.getShare(token, pin);
    } else {
      container.append(
        h(
          'section',
          { class: 'page narrow customer-page' },
          h('h1', {}, early.notOpen),
          h('p', {}, e.status === 404 ? early.expired : errorText(e)),
        ),
      );
      return;
    }
  }
  // The shop's language unless this browser chose the other; the plain labels
  // come from the server in the language shown.
  let locale = customerLocale(chosenLocale() || share.locale);
  /** @type {BodyView | null} */
  let view = null;
  const show = async () => {
    if (locale !== share.locale) share = await api.getShare(token, pin, locale);
    view?.dispose();
    clear(container);
    view = render(
      container,
      { token, pin, share, locale, t0, unit },
      // Rejects, with the page left in the language it was in, when the labels in
      // the other language do not load.
      async (next) => {
        const before = locale;
        locale = next;
        try {
          await show();
        } catch (e) {
          locale = before;
          throw e;
        }
        rememberLocale(next);
      },
      (u) => {
        unit = u;
      },
    );
  };
  await show();
  return () => view?.dispose();
}

const LOCALE_KEY = 'bodyscan.customer-locale';
const chosenLocale = () => globalThis.localStorage?.getItem(LOCALE_KEY) || undefined;
const rememberLocale = (locale) => globalThis.localStorage?.setItem(LOCALE_KEY, locale);

// The page in `locale`; returns its 3-D view. `onLocale` is called with a language
// the customer picks (the page says so if its promise rejects), `onUnit` with a unit.
/**
 * @param {HTMLElement} container
 * @param {{ token: string, pin: string | undefined, share: import('../api.js').ShareView, locale: import('../i18n.js').Locale, t0: number, unit: string }} state
 * @param {(locale: import('../i18n.js').Locale) => Promise<void>} onLocale
 * @param {(unit: string) => void} onUnit
 */
function render(container, { token, pin, share, locale, t0, unit }, onLocale, onUnit) {
  let selected = null;
  const words = customerWords(locale);
  document.documentElement.lang = locale;
  const languageError = h('p', { class: 'form-error', role: 'alert' });
  const languages = h(
    'select',
    {
      class: 'language',
      'aria-label': words.language,
      onchange: async (e) => {
        const picked = customerLocale(e.target.value);
        languageError.textContent = '';
        try {
          await onLocale(picked);
        } catch (err) {
          e.target.value = locale;
          languageError.textContent = `${customerWords(picked).languageFailed} ${errorText(err)}`;
        }
      },
    },
    h('option', { value: 'en', selected: locale === 'en', lang: 'en' }, 'English'),
    h('option', { value: 'de', selected: locale === 'de', lang: 'de' }, 'Deutsch'),
  );
  const viewport = h('div', { class: 'viewport', id: 'viewport' });
  const tableBox = h('div', { class: 'table-box' });
  const sheetError = h('p', { class: 'form-error', role: 'alert' });
  const sheetButton = h(
    'button',
    {
      type: 'button',
      class: 'sheet-button',
      onclick: async () => {
        sheetError.textContent = '';
        try {
          const blob = await api.getShareSheet(token, unit, locale, pin);
          const url = URL.createObjectURL(blob);
          const a = h('a', { href: url, download: 'body-measurements.pdf' });
          document.body.append(a);
          a.click();
          a.remove();
          setTimeout(() => URL.revokeObjectURL(url), 60_000);
        } catch (e) {
          sheetError.textContent = `${words.sheetFailed} ${errorText(e)}`;
        }
      },
    },
    words.sheet,
  );
  container.append(
    h(
      'section',
      { class: 'page viewer-page customer-page' },
      h(
        'header',
        { class: 'customer-head' },
        h('div', { class: 'row customer-top' }, share.shop ? h('p', { class: 'shop-name' }, share.shop) : h('span'), languages),
        h('h1', {}, words.title),
        languageError,
        h('p', { class: 'muted' }, words.taken(formatWhen(share.taken_at, locale), formatWhen(new Date(share.expires_at * 1000).toISOString(), locale))),
      ),
      h('div', { class: 'viewer-main' }, viewport, h('p', { class: 'hint' }, words.hint)),
      h(
        'aside',
        { class: 'viewer-side' },
        h(
          'div',
          { class: 'row' },
          h('h2', {}, words.measurements),
          unitSelect(
            unit,
            (u) => {
              unit = u;
              onUnit(u);
              renderTable();
            },
            words.unit,
          ),
        ),
        tableBox,
        h('div', { class: 'row' }, sheetButton),
        sheetError,
      ),
    ),
  );
  const view = new BodyView(viewport, { label: words.model });

  function renderTable() {
    clear(
      tableBox,
      share.measurements.length
        ? measurementTable({
            measurements: share.measurements,
            unit,
            selected,
            plain: true,
            locale,
            headings: [words.measurement, words.value],
            groups: words.groups,
            onSelect: (m) => {
              selected = selected === m.name ? null : m.name;
              view.clearOverlays('sel');
              if (selected) drawMeasurement(view, 'sel', m, COLOURS.selected);
              renderTable();
            },
          })
        : h('p', { class: 'muted' }, words.noMeasurements),
      share.measurements.some((m) => isEstimate(m.geometry || {})) ? h('p', { class: 'estimated-note' }, words.estimated) : null,
    );
  }
  renderTable();
  view.loadMesh(api.getShareModel(share.mesh || `/api/share/${enc(token)}/mesh.glb`, pin), { t0 }).catch((e) => {
    viewport.append(h('p', { class: 'form-error overlay' }, `${words.modelFailed} ${errorText(e)}`));
  });
  return view;
}

// A form for the link's PIN; resolves with the right one, or undefined when the
// link stops opening (too many wrong tries withdraw it). The form goes once done.
/**
 * @param {HTMLElement} container
 * @param {string} token
 * @param {ReturnType<typeof customerWords>} words
 * @returns {Promise<string | undefined>}
 */
function askPin(container, token, words) {
  return new Promise((resolve) => {
    const input = h('input', { name: 'pin', inputmode: 'numeric', autocomplete: 'one-time-code', maxlength: 6, pattern: '[0-9]{6}', required: true, 'aria-label': 'PIN', class: 'pin-input' });
    const message = h('p', { class: 'form-error', role: 'alert' });
    const section = h(
      'section',
      { class: 'page narrow customer-page pin-page' },
      h('h1', {}, words.title),
      h('p', {}, words.askPin),
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
                message.textContent = err.triesLeft === null ? errorText(err) : words.wrongPin(err.triesLeft);
                input.select();
                return;
              }
              clear(section, h('h1', {}, words.notOpen), h('p', {}, err.status === 404 ? words.withdrawn : errorText(err)));
              resolve(undefined);
            }
          },
        },
        h('div', { class: 'row' }, input, h('button', { class: 'primary', type: 'submit' }, words.open)),
        message,
      ),
    );
    container.append(section);
    input.focus();
  });
}
