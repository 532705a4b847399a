// What the browser tests stand on: a real `bodyscan serve` on a fresh data
// folder (simulated rig, a free port), Debian's Chromium driven by playwright-core
// (no browser download), screenshots kept as artefacts, and ground truth from the
// demo body the simulated rig scans.
import { execFileSync, spawn } from 'node:child_process';
import { cpSync, existsSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
export const REPO = resolve(here, '../../..');
export const ADMIN_PASSWORD = 'correct horse battery';

function required(name, fallback) {
  const v = process.env[name] || fallback;
  if (!v || !existsSync(v)) throw new Error(`${name} must name an existing path (got ${v || 'nothing'}); run the tests through ctest (deploy/run-tests.sh)`);
  return v;
}

export const BIN = () => required('BODYSCAN_BIN', join(REPO, 'build-test/app/bodyscan'));
export const WEB_ROOT = () => required('BODYSCAN_WEB_ROOT', join(REPO, 'build-test/web'));
export const CHROMIUM = () => {
  const p = process.env.CHROMIUM || '/usr/bin/chromium';
  if (!existsSync(p)) throw new Error(`no Chromium at ${p}: install it with deploy/install-deps.sh --browser`);
  return p;
};
export const ARTEFACTS = process.env.BODYSCAN_TEST_ARTIFACTS || join(REPO, 'web/test-results');
mkdirSync(ARTEFACTS, { recursive: true });

// The demo body the simulated rig scans (mm, Y up, soles on Y=0, facing +Z).
const DEMO_BODY = () => join(REPO, 'hw/sim/bodies/male_average.ply');

// A measurement of the automatic set (mm) as `bodyscan measure --auto` takes it on
// the true demo body.
export function demoBodyMeasurement(name) {
  const out = JSON.parse(execFileSync(BIN(), ['measure', DEMO_BODY(), '--auto'], { encoding: 'utf8' }));
  const m = out.measurements.find((x) => x.name === name);
  if (!m) throw new Error(`the demo body has no ${name}`);
  return m.value_mm;
}

export function demoBodyBounds() {
  const bytes = readFileSync(DEMO_BODY());
  const end = bytes.indexOf('end_header\n') + 'end_header\n'.length;
  const header = bytes.subarray(0, end).toString('latin1');
  if (!/format binary_little_endian/.test(header) || !/element vertex (\d+)\nproperty float x\nproperty float y\nproperty float z\n/.test(header))
    throw new Error('unexpected PLY layout for the demo body');
  const n = Number(/element vertex (\d+)/.exec(header)[1]);
  const min = [Infinity, Infinity, Infinity];
  const max = [-Infinity, -Infinity, -Infinity];
  const view = new DataView(bytes.buffer, bytes.byteOffset + end, n * 12);
  for (let i = 0; i < n; i++)
    for (let k = 0; k < 3; k++) {
      const v = view.getFloat32(i * 12 + k * 4, true);
      if (v < min[k]) min[k] = v;
      if (v > max[k]) max[k] = v;
    }
  return { min, max };
}

// The simulated rig (the thesis layout, the demo body) on pixels twice the size:
// half the width and height, as the C++ tests' half_resolution_rig, so that a
// calibration and a scan render a quarter of the pixels. The UI's behaviour does
// not depend on the resolution; the figures the suite judges keep to their
// tolerances. Written once, into the run's temporary folder.
let halfRig = null;
function halfResolutionRig() {
  if (halfRig) return halfRig;
  const source = join(REPO, 'hw/rigs/thesis.json');
  const rig = JSON.parse(readFileSync(source, 'utf8'));
  for (const c of rig.cameras) {
    c.width /= 2;
    c.height /= 2;
    c.pixel_size_um *= 2;
    c.blur_px = (c.blur_px ?? 0.7) / 2; // 0.7 px: the description's default (hw/rig_description.hpp)
  }
  rig.simulation.subject = resolve(dirname(source), rig.simulation.subject);
  const dir = mkdtempSync(join(tmpdir(), 'bodyscan-rig-'));
  process.on('exit', () => rmSync(dir, { recursive: true, force: true }));
  halfRig = join(dir, 'half-thesis.json');
  writeFileSync(halfRig, JSON.stringify(rig));
  return halfRig;
}

// `bodyscan serve` on a fresh data folder (or a copy of `seed`, an archive
// made before); resolves once it prints its URL.
export async function startServer({ every = 6, extraArgs = [], seed = null } = {}) {
  const data = mkdtempSync(join(tmpdir(), 'bodyscan-ui-'));
  if (seed) cpSync(seed, data, { recursive: true });
  const args = ['serve', '--address', '127.0.0.1', '--port', '0', '--data', data, '--rig', halfResolutionRig(), '--every', String(every), '--web', WEB_ROOT(), ...extraArgs];
  const proc = spawn(BIN(), args, {
    env: { ...process.env, BODYSCAN_ADMIN_PASSWORD: ADMIN_PASSWORD },
    stdio: ['ignore', 'pipe', 'pipe'],
  });
  let log = '';
  const url = await new Promise((resolveUrl, reject) => {
    const timer = setTimeout(() => reject(new Error(`bodyscan serve did not start:\n${log}`)), 30000);
    const onData = (chunk) => {
      log += chunk;
      const m = /open (https?:\/\/\S+?)\/?\s/.exec(log);
      if (m) {
        clearTimeout(timer);
        resolveUrl(m[1].replace('localhost', '127.0.0.1'));
      }
    };
    proc.stdout.on('data', onData);
    proc.stderr.on('data', onData);
    proc.on('exit', (code) => reject(new Error(`bodyscan serve exited (${code}):\n${log}`)));
  });
  return {
    url,
    data,
    log: () => log,
    async stop() {
      if (proc.exitCode !== null) return proc.exitCode;
      const exited = new Promise((r) => proc.on('exit', (code) => r(code)));
      proc.kill('SIGTERM');
      const code = await exited;
      // BODYSCAN_E2E_KEEP=1 keeps the data folder to look into after a failure.
      if (process.env.BODYSCAN_E2E_KEEP) console.log(`# kept the server's data folder: ${data}`);
      else rmSync(data, { recursive: true, force: true });
      return code;
    },
  };
}

// A suite's server, browser and page, set on `suite` ({ errors: [] } to start
// with: the page's errors collect there) as each comes up, so that closeSuite
// stops whatever started.
export async function openSuite(suite, { serverOptions = {}, contextOptions = {} } = {}) {
  suite.server = await startServer(serverOptions);
  suite.browser = await launchBrowser();
  suite.context = await suite.browser.newContext(contextOptions);
  suite.page = await newPage(suite.context, suite.errors);
}

// Closes the browser, stops the server (which must exit 0 on SIGTERM), and
// fails on any error a page threw or logged.
export async function closeSuite(suite, assert) {
  if (suite.browser) await suite.browser.close();
  if (suite.server) {
    const code = await suite.server.stop();
    assert.equal(code, 0, `bodyscan serve did not stop cleanly:\n${suite.server.log()}`);
  }
  assert.deepEqual(suite.errors, [], 'the pages threw or logged errors');
}

export async function launchBrowser() {
  return chromium.launch({
    executablePath: CHROMIUM(),
    args: [
      '--no-sandbox',
      '--disable-background-networking',
      '--disable-component-update',
      '--disable-sync',
      '--no-first-run',
      '--disable-quic',
      // WebGL in a headless machine without a GPU: ANGLE on SwiftShader.
      '--use-angle=swiftshader',
      '--enable-unsafe-swiftshader',
      '--ignore-gpu-blocklist',
    ],
  });
}

// A page that fails the test on any uncaught script error.
export async function newPage(context, errors) {
  const page = await context.newPage();
  page.on('pageerror', (e) => errors.push(`pageerror: ${e.message}`));
  page.on('console', (m) => {
    if (m.type() === 'error' && !/status of (401|404|409|422)/.test(m.text())) errors.push(`console: ${m.text()}`);
  });
  return page;
}

const AXE_SOURCE = readFileSync(createRequire(import.meta.url).resolve('axe-core/axe.min.js'), 'utf8');

// axe-core's check of the page as it stands against the WCAG 2.1 A and AA rules:
// the violations of serious or critical impact, each as "rule (impact): where".
// Evaluated through the DevTools protocol, so the page's Content-Security-Policy
// (no inline scripts) does not stop it.
export async function accessibilityProblems(page) {
  await page.evaluate(AXE_SOURCE);
  const violations = await page.evaluate(async () => {
    // @ts-ignore axe is the script just evaluated
    const result = await window.axe.run(document, { runOnly: { type: 'tag', values: ['wcag2a', 'wcag2aa', 'wcag21a', 'wcag21aa'] } });
    return result.violations.map((v) => ({ id: v.id, impact: v.impact, help: v.help, targets: v.nodes.map((n) => n.target.join(' ')) }));
  });
  return violations
    .filter((v) => v.impact === 'serious' || v.impact === 'critical')
    .map((v) => `${v.id} (${v.impact}, ${v.help}): ${v.targets.slice(0, 6).join(', ')}`);
}

export async function shot(page, name) {
  await page.screenshot({ path: join(ARTEFACTS, `${name}.png`) });
}

export async function login(page, base, username, password) {
  await page.goto(`${base}/login`);
  await page.fill('input[name=username]', username);
  await page.fill('input[name=password]', password);
  await Promise.all([page.waitForURL((u) => !u.pathname.startsWith('/login')), page.click('form.login button[type=submit]')]);
}

export async function logout(page) {
  await Promise.all([page.waitForURL('**/login'), page.click('#who button')]);
}

// The share of the viewport's pixels that differ from its background, read from
// a real screenshot (what the compositor shows, not the WebGL buffer); the
// floor grid's faint lines do not count.
export async function coverage(page, selector) {
  const png = (await page.locator(selector).screenshot()).toString('base64');
  return page.evaluate(async (b64) => {
    const img = new Image();
    img.src = `data:image/png;base64,${b64}`;
    await img.decode();
    const c = document.createElement('canvas');
    c.width = img.width;
    c.height = img.height;
    const g = c.getContext('2d');
    g.drawImage(img, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    const bg = [d[0], d[1], d[2]]; // a corner is background
    let differ = 0;
    for (let i = 0; i < d.length; i += 4) if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 100) differ++;
    return differ / (d.length / 4);
  }, png);
}

export function removeDir(dir) {
  rmSync(dir, { recursive: true, force: true });
}
