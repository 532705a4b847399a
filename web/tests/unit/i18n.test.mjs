import assert from 'node:assert/strict';
import { test } from 'node:test';
import { customerLocale, customerWords, formatWhen } from '../../src/i18n.js';

test('the customer side speaks English or German, English for anything else', () => {
  assert.equal(customerLocale('de'), 'de');
  assert.equal(customerLocale('de-AT'), 'de');
  assert.equal(customerLocale('fr'), 'en');
  assert.equal(customerLocale(undefined), 'en');
  // Both languages say every phrase the page uses.
  const en = customerWords('en');
  const de = customerWords('de');
  assert.deepEqual(Object.keys(de).sort(), Object.keys(en).sort());
  for (const [key, text] of Object.entries(de)) assert.notDeepEqual(text, en[key], `${key} is translated`);
});

test('dates and times follow the locale: day first, the 24-hour clock', () => {
  const iso = '2026-11-29T15:07:00Z';
  const local = new Date(iso);
  const hh = String(local.getHours()).padStart(2, '0');
  assert.match(formatWhen(iso, 'de'), new RegExp(`^29\\.11\\.2026, ${hh}:07$`));
  assert.match(formatWhen(iso, 'en'), new RegExp(`^29 Nov 2026, ${hh}:07$`));
  assert.equal(formatWhen('not a date', 'de'), 'not a date');
});
