// The UI is built and tested with the Node.js a user's Debian 12 has (nodejs
// 18.20): every package the lockfile installs must accept that version, and so
// must the project's own `engines` field. A dependency bumped to one that needs
// a newer Node fails here, on any machine, before it fails on a user's.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { test } from 'node:test';

const DEBIAN_NODE = '18.20.4'; // Debian 12 (bookworm): nodejs 18.20.4+dfsg-1~deb12u1

const parse = (v) => {
  const parts = v.replace(/^[v=]/, '').split('-')[0].split('.');
  return [0, 1, 2].map((i) => (parts[i] === undefined || /^[x*]$/i.test(parts[i]) ? null : Number(parts[i])));
};
const compare = (a, b) => {
  for (let i = 0; i < 3; i++) if ((a[i] ?? 0) !== (b[i] ?? 0)) return (a[i] ?? 0) < (b[i] ?? 0) ? -1 : 1;
  return 0;
};

// One comparator of a node-semver range: >=, >, <=, <, =, ^, ~ or an x-range.
function satisfiesComparator(version, comparator) {
  const m = /^(>=|<=|>|<|=|\^|~)?\s*(.+)$/.exec(comparator);
  const [, op = '', rest] = m;
  const want = parse(rest);
  const c = compare(version, want);
  switch (op) {
    case '>=': return c >= 0;
    case '>': return c > 0;
    case '<=': return c <= 0;
    case '<': return c < 0;
    case '^': {
      // ^X.Y.Z admits up to, not including, the next change of the first non-zero part.
      const i = want.findIndex((p, k) => (p ?? 0) !== 0 || k === 2 || want[k + 1] === null);
      const upper = want.map((p, k) => (k < i ? p ?? 0 : k === i ? (p ?? 0) + 1 : 0));
      return c >= 0 && compare(version, upper) < 0;
    }
    case '~': {
      const i = want[1] === null ? 0 : 1;
      const upper = want.map((p, k) => (k < i ? p ?? 0 : k === i ? (p ?? 0) + 1 : 0));
      return c >= 0 && compare(version, upper) < 0;
    }
    default: // = or an x-range: the given parts match
      return want.every((p, k) => p === null || p === version[k]);
  }
}

export function satisfies(version, range) {
  const v = parse(version);
  return range.split('||').some((set) => {
    const comparators = set.trim().replace(/(>=|<=|>|<|=|\^|~)\s+/g, '$1').split(/\s+/).filter(Boolean);
    return comparators.every((c) => c === '*' || satisfiesComparator(v, c));
  });
}

test('the range reader reads the forms npm packages use', () => {
  assert.ok(satisfies('18.20.4', '>=18'));
  assert.ok(!satisfies('18.20.4', '>=20.19'));
  assert.ok(!satisfies('18.20.4', '^20.19.0 || >=22.12.0'));
  assert.ok(satisfies('18.20.4', '^18.0.0 || ^20.0.0 || >=22.0.0'));
  assert.ok(satisfies('18.20.4', '^10 || ^12 || ^13.7 || ^14 || >=15.0.1'));
  assert.ok(!satisfies('13.6.0', '^10 || ^12 || ^13.7 || ^14 || >=15.0.1'));
  assert.ok(!satisfies('18.20.4', '^18.21'));
  assert.ok(satisfies('18.20.4', '~18.20.1'));
  assert.ok(!satisfies('18.20.4', '18.x <18.20'));
  assert.ok(satisfies('18.20.4', '>= 16 < 19'));
  assert.ok(!satisfies('0.3.9', '^0.3.10'));
  assert.ok(!satisfies('0.4.0', '^0.3.10'));
});

test("every package the UI installs runs on Debian 12's Node.js", () => {
  const pkg = JSON.parse(readFileSync(new URL('../../package.json', import.meta.url), 'utf8'));
  const lock = JSON.parse(readFileSync(new URL('../../package-lock.json', import.meta.url), 'utf8'));
  assert.ok(satisfies(DEBIAN_NODE, pkg.engines.node), `package.json's engines.node is ${pkg.engines.node}`);
  const entries = Object.entries(lock.packages).filter(([path]) => path !== '');
  assert.ok(entries.length > 10, 'the lockfile lists the installed packages');
  const refused = entries
    .filter(([, p]) => p.engines && typeof p.engines === 'object' && p.engines.node)
    .filter(([, p]) => !satisfies(DEBIAN_NODE, p.engines.node))
    .map(([path, p]) => `${path.replace(/^.*node_modules\//, '')}@${p.version} needs node ${p.engines.node}`);
  assert.deepEqual(refused, [], `these need a Node.js newer than Debian's ${DEBIAN_NODE}`);
});
