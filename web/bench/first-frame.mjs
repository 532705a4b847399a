// Time from opening a scan to its first rendered frame, in headless Chromium on
// localhost, for each archive given (label=DATA_DIR): the newest complete scan.
// With label=DATA_DIR=MODEL.glb, that GLB is served as the scan's model instead
// (the whole surface beside the display mesh the archive serves). Every row's
// model is served the same way, from the browser's network layer, so that the rows
// differ in the model alone.
//   node bench/first-frame.mjs [--runs N] [--json OUT.json] label=DIR[=MODEL.glb] [...]
// Per run, in a fresh browser context (empty cache): log in, open /scans/ID as a
// page load, and read the page's User Timing: first frame after navigation start
// and after the viewer mounted, the model fetched and decoded (Draco, in a
// worker), normals computed, then the BVH build and 12 picks (taps on the body).
// Then the same scan again from the archive page inside the app (warm: the
// bundles and the immutable model come from the cache). Prints a markdown table
// of medians (--json: its rows as a JSON array, for bench/tables.py). The renderer is SwiftShader (no GPU here): drawing costs more than
// on a tablet's GPU.
import { readFileSync, writeFileSync } from 'node:fs';
import { ADMIN_PASSWORD, launchBrowser, login, startServer } from '../tests/e2e/harness.mjs';

const args = process.argv.slice(2);
let runs = 5;
let jsonOut = '';
const archives = [];
for (let i = 0; i < args.length; i++) {
  if (args[i] === '--runs') runs = Number(args[++i]);
  else if (args[i] === '--json') jsonOut = args[++i];
  else if (args[i].includes('=')) {
    const [label, dir, model] = args[i].split('=');
    archives.push({ label, dir, model });
  } else throw new Error(`unknown argument ${args[i]}`);
}
if (!archives.length) throw new Error('usage: node bench/first-frame.mjs [--runs N] label=DATA_DIR ...');

const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length ? (s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2) : NaN;
};

async function timings(page) {
  return page.evaluate(() => {
    const mark = (n) => performance.getEntriesByName(n).at(-1)?.startTime ?? NaN;
    const open = mark('bodyscan:open-scan');
    return {
      loadToFrame: mark('bodyscan:first-frame'),
      openToFrame: mark('bodyscan:first-frame') - open,
      openToDecoded: mark('bodyscan:model-decoded') - open,
      openToPicking: (() => {
        const b = performance.getEntriesByName('bodyscan:bvh').at(-1);
        return b ? b.startTime + b.duration - open : NaN;
      })(),
      normalsMs: mark('bodyscan:normals-done') - mark('bodyscan:model-decoded'),
      drawMs: mark('bodyscan:first-frame') - mark('bodyscan:normals-done'),
      triangles: Number(/** @type {HTMLElement} */ (document.querySelector('#viewport')).dataset.triangles),
    };
  });
}

const browser = await launchBrowser();
const rows = [];
for (const { label, dir, model } of archives) {
  const server = await startServer({ seed: dir });
  /** @type {Buffer | null} the model every run is served */
  let modelBytes = model ? readFileSync(model) : null;
  try {
    const cold = [];
    const warm = [];
    const bvh = [];
    const picks = [];
    let scanId = null;
    let glbBytes = 0;
    for (let r = 0; r < runs; r++) {
      const context = await browser.newContext({ viewport: { width: 1366, height: 1024 } });
      const page = await context.newPage();
      await login(page, server.url, 'admin', ADMIN_PASSWORD);
      if (!scanId) {
        const { scans } = await page.evaluate(async () => (await fetch('/api/scans')).json());
        const scan = scans.find((s) => s.status === 'complete');
        if (!scan) throw new Error(`${dir}: no complete scan`);
        scanId = scan.id;
        if (!modelBytes) modelBytes = Buffer.from(await (await page.request.get(`${server.url}/api/scans/${scanId}/mesh.glb`)).body());
        glbBytes = modelBytes.length;
      }
      const served = modelBytes;
      await context.route('**/api/scans/*/mesh.glb*', (route) =>
        route.fulfill({ body: served, contentType: 'model/gltf-binary', headers: { 'Cache-Control': 'private, max-age=31536000, immutable' } }),
      );
      await page.goto(`${server.url}/scans/${scanId}`);
      await page.locator('#viewport[data-state=ready]').waitFor({ timeout: 120000 });
      cold.push(await timings(page));
      // Picking: the BVH (built after the first frame), then taps in distance mode.
      await page.waitForFunction(() => performance.getEntriesByName('bodyscan:bvh').length > 0, null, { timeout: 60000 });
      bvh.push(await page.evaluate(() => performance.getEntriesByName('bodyscan:bvh')[0].duration));
      cold.at(-1).openToPicking = (await timings(page)).openToPicking;
      await page.click('.segmented button[data-value=distance]');
      const box = await page.locator('#viewport canvas').boundingBox();
      for (let k = 0; k < 12; k++) {
        await page.mouse.click(box.x + box.width * (0.46 + 0.08 * (k % 2)), box.y + box.height * (0.3 + 0.035 * k));
        await page.waitForTimeout(50);
      }
      picks.push(...(await page.evaluate(() => performance.getEntriesByName('bodyscan:pick').map((e) => e.duration))));
      // Warm: back to the archive, open the scan inside the app.
      await page.goto(`${server.url}/archive`);
      await page.locator(`tr[data-scan="${scanId}"] a.button`).click();
      await page.locator('#viewport[data-state=ready]').waitFor({ timeout: 120000 });
      warm.push(await timings(page));
      await context.close();
    }
    const m = (xs, k) => median(xs.map((x) => x[k]));
    rows.push({
      label,
      triangles: cold[0].triangles,
      glbKB: glbBytes / 1024,
      loadToFrame: m(cold, 'loadToFrame'),
      openToFrame: m(cold, 'openToFrame'),
      decoded: m(cold, 'openToDecoded'),
      normals: m(cold, 'normalsMs'),
      draw: m(cold, 'drawMs'),
      warm: m(warm, 'openToFrame'),
      bvh: median(bvh),
      picking: m(cold, 'openToPicking'),
      pick: median(picks),
      pickMax: Math.max(...picks),
    });
  } finally {
    await server.stop();
  }
}
await browser.close();

if (jsonOut)
  writeFileSync(jsonOut, `${JSON.stringify(rows.map((r) => ({ ...r, runs, chromium: browser.version() })), null, 1)}\n`);
const f = (x, d = 0) => (Number.isFinite(x) ? x.toFixed(d) : '—');
console.log(`\nmedians of ${runs} runs; headless Chromium ${browser.version()} (SwiftShader), localhost\n`);
console.log('| body | triangles | GLB | page load → first frame | scan opened → first frame | of which fetch + Draco decode | normals | first draw | scan opened → picking ready | BVH build | opened again in the app | pick (median / max) |');
console.log('|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|');
for (const r of rows)
  console.log(
    `| ${r.label} | ${r.triangles.toLocaleString('en')} | ${f(r.glbKB)} KB | ${f(r.loadToFrame)} ms | ${f(r.openToFrame)} ms | ${f(r.decoded)} ms | ${f(r.normals)} ms | ${f(r.draw)} ms | ${f(r.picking)} ms | ${f(r.bvh)} ms | ${f(r.warm)} ms | ${f(r.pick, 2)} / ${f(r.pickMax, 2)} ms |`,
  );
