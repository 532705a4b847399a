// The customer's side in the shop's language (the share view's `locale`, set by
// `bodyscan serve --locale`): English and German. Staff pages stay English.
// Numbers and dates follow the locale: a decimal comma and the 24-hour clock in
// German.

/** @typedef {'en' | 'de'} Locale */

const WORDS = {
  en: {
    title: 'Your body scan',
    taken: (day, until) => `Taken ${day} · this link works until ${until}`,
    measurements: 'Measurements',
    measurement: 'Measurement',
    value: 'Value',
    hint: 'Drag to turn, pinch or scroll to zoom. Tap a measurement to see it on the body.',
    model: 'Your body in 3-D',
    noMeasurements: 'The shop shared no measurements with this link.',
    estimated: '* Estimated: the cameras could not see all of this line, so part of it is filled in. The shop can check it with a tape measure.',
    sheet: 'Your sheet (PDF)',
    sheetFailed: 'The sheet did not load:',
    languageFailed: 'The page could not change to English:',
    modelFailed: 'The model did not load:',
    unit: 'Unit',
    language: 'Language',
    groups: { automatic: 'Body measurements', user: 'Taken by the shop' },
    notOpen: 'This link does not open a scan',
    expired: 'It may have expired or been withdrawn. Ask the shop for a new link.',
    withdrawn: 'It was withdrawn after too many wrong PINs, or has expired. Ask the shop for a new link.',
    askPin: 'Enter the six-digit PIN the shop gave you.',
    open: 'Open',
    wrongPin: (left) => `Wrong PIN: ${left} ${left === 1 ? 'try' : 'tries'} left before the link is withdrawn.`,
  },
  de: {
    title: 'Ihr Körperscan',
    taken: (day, until) => `Aufgenommen am ${day} · dieser Link gilt bis ${until}`,
    measurements: 'Maße',
    measurement: 'Maß',
    value: 'Wert',
    hint: 'Ziehen zum Drehen, mit zwei Fingern oder dem Mausrad zoomen. Tippen Sie auf ein Maß, um es am Körper zu sehen.',
    model: 'Ihr Körper in 3-D',
    noMeasurements: 'Das Geschäft hat mit diesem Link keine Maße geteilt.',
    estimated: '* Geschätzt: Die Kameras konnten diese Linie nicht ganz sehen, ein Teil ist ergänzt. Das Geschäft kann sie mit dem Maßband nachmessen.',
    sheet: 'Ihr Maßblatt (PDF)',
    sheetFailed: 'Das Maßblatt konnte nicht geladen werden:',
    languageFailed: 'Die Seite konnte nicht auf Deutsch umgestellt werden:',
    modelFailed: 'Das Modell konnte nicht geladen werden:',
    unit: 'Einheit',
    language: 'Sprache',
    groups: { automatic: 'Körpermaße', user: 'Vom Geschäft gemessen' },
    notOpen: 'Dieser Link öffnet keinen Scan',
    expired: 'Er ist vielleicht abgelaufen oder zurückgezogen. Bitten Sie das Geschäft um einen neuen Link.',
    withdrawn: 'Er wurde nach zu vielen falschen PINs zurückgezogen oder ist abgelaufen. Bitten Sie das Geschäft um einen neuen Link.',
    askPin: 'Geben Sie die sechsstellige PIN ein, die Sie im Geschäft bekommen haben.',
    open: 'Öffnen',
    wrongPin: (left) => `Falsche PIN: noch ${left} ${left === 1 ? 'Versuch' : 'Versuche'}, dann wird der Link zurückgezogen.`,
  },
};

/**
 * The locale the server names, English for anything else.
 * @param {string | undefined} tag
 * @returns {Locale}
 */
export function customerLocale(tag) {
  return tag && tag.toLowerCase().startsWith('de') ? 'de' : 'en';
}

/** @param {Locale} locale */
export function customerWords(locale) {
  return WORDS[locale] || WORDS.en;
}

/**
 * A day and time as the locale writes them: "29 Nov 2026, 14:05", "29.11.2026, 14:05".
 * @param {string} iso
 * @param {Locale} locale
 */
export function formatWhen(iso, locale) {
  const d = new Date(iso);
  if (Number.isNaN(d.getTime())) return iso;
  return d.toLocaleString(locale === 'de' ? 'de-DE' : 'en-GB', {
    day: 'numeric',
    month: locale === 'de' ? '2-digit' : 'short',
    year: 'numeric',
    hour: '2-digit',
    minute: '2-digit',
    hour12: false,
  });
}
