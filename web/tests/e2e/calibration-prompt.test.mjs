// The station asking the person at the rig to hold the lens dot-grid board, in
// real headless Chromium against `bodyscan serve --operator-dot-grid` (staff
// training on the simulated rig: the calibration asks before every camera, as
// it does before real ones). Screenshots go to the artefacts folder.
import assert from 'node:assert/strict';
import { after, before, describe, it } from 'node:test';
import { ADMIN_PASSWORD, closeSuite, login, openSuite, shot } from './harness.mjs';

let server;
let page;
const suite = { errors: [] };

// The prompt on screen once it is one other than `last`: { id, kind, camera, title },
// or { ended } once the job ends. The card of `oldJob`, a job that ended before
// this one was started, is not this job's end: it stays until the new job shows.
async function nextPrompt(last, oldJob = null) {
  const handle = await page.waitForFunction(
    ([old, oldJobId]) => {
      /** @type {HTMLElement | null} */
      const done = document.querySelector('#job .job-state');
      if (done && done.dataset.job === oldJobId) return null;
      if (done && done.dataset.state !== 'running') return { ended: done.dataset.state };
      /** @type {HTMLButtonElement | null} */
      const b = document.querySelector('#job .prompt button[data-prompt]');
      if (!b || b.disabled || b.dataset.prompt === old) return null;
      /** @type {HTMLElement} */
      const box = b.closest('.prompt');
      return { id: b.dataset.prompt, kind: box.dataset.kind, camera: box.dataset.camera, title: box.querySelector('h3').textContent };
    },
    [last, oldJob],
    { timeout: 120000, polling: 50 },
  );
  return handle.jsonValue();
}

describe('the dot-grid prompt at the station', { timeout: 600_000 }, () => {
  before(async () => {
    await openSuite(suite, { serverOptions: { extraArgs: ['--operator-dot-grid'] }, contextOptions: { viewport: { width: 1024, height: 768 }, hasTouch: true } });
    ({ server, page } = suite);
  });

  after(() => closeSuite(suite, assert));

  it('asks for the board before each camera, then to clear the rig, and calibrates', async () => {
    await login(page, server.url, 'admin', ADMIN_PASSWORD);
    await page.goto(`${server.url}/station`);
    const cameras = await page.evaluate(async () => (await (await fetch('/api/rig')).json()).cameras.map((c) => c.id));
    assert.ok(cameras.length >= 3);
    await page.click('#rig-status button:has-text("Calibrate")');
    const asked = [];
    let last = null;
    for (;;) {
      const p = await nextPrompt(last);
      if (p.ended) {
        assert.equal(p.ended, 'complete');
        break;
      }
      asked.push(p);
      last = p.id;
      if (asked.length === 1) await shot(page, 'station-dot-grid-prompt');
      await page.click(`#job .prompt button[data-prompt="${p.id}"]`);
    }
    assert.deepEqual(
      asked.map((p) => [p.kind, p.camera]),
      [...cameras.map((c) => ['hold_dot_grid', c]), ['remove_dot_grid', '']],
    );
    assert.match(asked[0].title, new RegExp(cameras[0]));
    await page.locator('#calibration-age:has-text("Calibrated")').waitFor({ timeout: 30000 });
  });

  it('cancels a calibration that waits for the board, lasers off', async () => {
    // The finished calibration's card is still on screen when the new one starts.
    const previous = await page.locator('#job .job-state').getAttribute('data-job');
    assert.ok(previous, 'the first calibration is shown');
    await page.click('#rig-status button:has-text("Calibrate")');
    const p = await nextPrompt(null, previous);
    assert.equal(p.kind, 'hold_dot_grid');
    await page.click('#job button:has-text("Cancel")');
    await page.locator('#job .job-state[data-state=cancelled]').waitFor({ timeout: 30000 });
    assert.equal(await page.locator('#job .prompt').count(), 0, 'the prompt goes with the job');
    await page.waitForFunction(() => [...document.querySelectorAll('#rig-status .laser')].every((l) => l.classList.contains('off')), null, { timeout: 30000 });
  });
});
