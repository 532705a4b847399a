// The operator's page: the rig at a glance, calibration, a scan for a new or
// returning customer, its progress live over the WebSocket (stage, progress,
// the time left, the cameras' previews, what the job asks the operator to do),
// cancel, and the result opening by itself when done.
//
// The scan goes to the customer named on the Start button, and the rig moves
// only after the operator confirms that name. A returning customer's pick is
// dropped whenever the search changes or the list is drawn again, so a tap on a
// row the list is about to replace never files a scan under someone else.
import { api, enc } from '../api.js';
import { overallFraction, stageText, timeLeftText } from '../progress.js';
import { ago, clear, confirmDialog, errorText, h, toast, when } from '../ui/dom.js';
import { postureCheckCard, wantedPostureCard } from '../viewer/posture.js';
import { formatDifference, formatLength, preferredUnit } from '../units.js';
import { shareDialog } from './share-dialog.js';

/** @typedef {import('../api.js').Job} Job */
/** @typedef {import('../api.js').RigStatus} RigStatus */
// The document leaves the cameras' fields open; these are the ones this page
// reads, as /api/rig sends them (error: a fault to show, when the server gives one).
/** @typedef {{ id: string, width: number, height: number, error?: string }} RigCamera */
/** @typedef {{ id: string, side: string, lens_held_out_rms_px: number, ray_spread_mm: number }} CalibratedCamera */

/**
 * @param {HTMLElement} container
 * @param {Record<string, string>} _params
 * @param {import('../main.js').PageContext} ctx
 */
export async function mount(container, _params, ctx) {
  const state = {
    /** @type {RigStatus | null} */ rig: null,
    /** @type {Job | null} */ job: null,
    connection: 'connecting',
    customerMode: 'new',
    /** @type {{ id: string, name: string, consent: import('../api.js').Consent | null } | null} the returning customer picked */ picked: null,
    /** the newest customer search sent; older answers are dropped */ searchSeq: 0,
    /** @type {Map<string, string>} customer id to name, for the job card */ names: new Map(),
    /** @type {Map<string, HTMLImageElement>} */ previews: new Map(),
    /** @type {string | null} the job this page started */ myJob: null,
    /** @type {{ scanId: string, customerId: string, check: any } | null} this page's scan that differs from the customer's earlier one today */ repeat: null,
  };
  let disposed = false;
  const rigBox = h('div', { class: 'card rig-card', id: 'rig-status' });
  const jobBox = h('div', { class: 'card job-card', id: 'job', 'aria-live': 'polite' });
  const formBox = h('div', { class: 'card scan-card' });
  const recentBox = h('div', { class: 'card recent-card' });
  const conn = h('span', { class: 'conn' });
  const page = h(
    'section',
    { class: 'page station-page' },
    h('div', { class: 'page-head' }, h('h1', {}, 'Scan station'), conn),
    h('div', { class: 'station-grid' }, h('div', { class: 'col' }, formBox, jobBox), h('div', { class: 'col' }, rigBox, recentBox)),
  );
  container.append(page);

  // ---- rig status
  function renderRig() {
    const rig = state.rig;
    if (!rig) {
      clear(rigBox, h('h2', {}, 'Rig'), h('p', { class: 'muted' }, 'Reading the rig…'));
      return;
    }
    const cal = rig.calibration;
    const calByCamera = new Map(/** @type {CalibratedCamera[]} */ (cal?.cameras || []).map((c) => [c.id, c]));
    const busy = rig.busy || (state.job && state.job.state === 'running');
    const faulty = /** @type {RigCamera[]} */ (rig.cameras).filter((c) => c.error);
    // One state up front; the engineering figures stay one tap away.
    const [readiness, ready] = faulty.length
      ? [`Not ready: camera ${faulty.map((c) => c.id).join(', ')} has a fault`, 'fault']
      : busy
        ? ['Busy', 'busy']
        : cal
          ? ['Rig ready', 'ready']
          : ['Ready: the first scan calibrates first', 'ready'];
    const details = h('details', { class: 'rig-details', open: state.rigDetailsOpen || undefined, ontoggle: () => (state.rigDetailsOpen = details.open) }, h('summary', {}, 'Cameras and lasers'));
    clear(
      rigBox,
      h('h2', {}, `Rig: ${rig.rig}`, rig.simulated ? h('span', { class: 'badge' }, 'simulated') : null),
      h('p', { class: `rig-readiness ${ready}`, id: 'rig-readiness', dataset: { state: ready } }, h('span', { class: `dot ${ready === 'fault' ? 'bad' : 'good'}` }), ` ${readiness}`),
      h(
        'p',
        { class: cal ? 'muted small' : 'form-error', id: 'calibration-age' },
        cal ? `Calibrated ${ago(cal.age_s)} (${when(new Date(cal.calibrated_at * 1000).toISOString())})` : 'Not calibrated: the first scan calibrates first, or calibrate now.',
      ),
      details,
      h('button', { type: 'button', disabled: busy, onclick: calibrate }, 'Calibrate'),
    );
    details.append(
      h(
        'table',
        { class: 'compact' },
        h('thead', {}, h('tr', {}, h('th', {}, 'Camera'), h('th', {}, 'Side'), h('th', { class: 'num', title: 'lens correction, held-out points' }, 'Lens RMS'), h('th', { class: 'num', title: 'spread of the rays through the frame markers' }, 'Ray spread'))),
        h(
          'tbody',
          {},
          /** @type {RigCamera[]} */ (rig.cameras).map((c) => {
            const k = calByCamera.get(c.id);
            return h(
              'tr',
              { class: c.error ? 'fault' : '' },
              h('td', {}, h('span', { class: `dot ${c.error ? 'bad' : 'good'}`, title: c.error || 'connected' }), ` ${c.id} `, h('small', { class: 'muted' }, `${c.width}×${c.height}`)),
              h('td', {}, k ? k.side : '—'),
              h('td', { class: 'num' }, k ? `${k.lens_held_out_rms_px.toFixed(3)} px` : '—'),
              h('td', { class: 'num' }, k ? `${k.ray_spread_mm.toFixed(2)} mm` : '—'),
            );
          }),
        ),
      ),
      h('p', { class: 'lasers' }, 'Lasers: ', rig.lasers.map((l) => h('span', { class: `laser ${l.on === null ? 'job' : l.on ? 'on' : 'off'}`, title: l.on === null ? 'switched by the job' : l.on ? 'on' : 'off' }, `${l.id}: ${l.on === null ? 'job' : l.on ? 'ON' : 'off'}`))),
    );
  }

  async function calibrate() {
    try {
      const { job } = await api.calibrate();
      state.myJob = job.id;
      startedJob(job);
    } catch (e) {
      toast(errorText(e), 'error');
    }
  }

  // ---- the scan form
  const name = h('input', { name: 'name', autocomplete: 'off', placeholder: 'First and last name', maxlength: 200 });
  const contact = h('input', { name: 'contact', autocomplete: 'off', placeholder: 'Phone or e-mail (optional)', maxlength: 200 });
  const search = h('input', { type: 'search', placeholder: 'Search by name, contact or id', 'aria-label': 'Search customers' });
  const results = h('div', { class: 'pick-list', role: 'listbox', 'aria-label': 'Customers' });
  const startButton = h('button', { class: 'primary big start-scan', type: 'submit', id: 'start-scan' });
  // A quick sweep that reads how the customer stands, before the scan.
  const checkButton = h('button', { type: 'button', id: 'check-posture', onclick: checkPosture }, 'Check posture');
  const modeNew = h('div', { class: 'mode-new' }, h('label', { class: 'field' }, h('span', {}, 'Name'), name), h('label', { class: 'field' }, h('span', {}, 'Contact'), contact));
  const modeExisting = h('div', { class: 'mode-existing', hidden: true }, search, results);
  // Consent before a customer's first scan: the terms to read with them, and a
  // box the operator ticks once they agree. No scan starts without it; the
  // server records it with the time and the operator.
  const consentTerms = h('p', { class: 'consent-terms', id: 'consent-terms' }, 'Reading the terms…');
  const consentGiven = h('input', { type: 'checkbox', id: 'consent-given', name: 'consent' });
  const consentBox = h(
    'fieldset',
    { class: 'consent' },
    h('legend', {}, 'Consent'),
    consentTerms,
    h('label', { class: 'check' }, consentGiven, h('span', {}, 'The customer has read this and agrees')),
  );
  const consentOnRecord = h('p', { class: 'muted small consent-on-record', id: 'consent-on-record', hidden: true });
  api
    .getConsent()
    .then(({ terms }) => (consentTerms.textContent = terms))
    .catch((e) => (consentTerms.textContent = `The terms could not be read: ${errorText(e)}`));
  consentGiven.addEventListener('change', renderForm);

  // A consent to ask for: a new customer, or a returning one with none on record.
  function consentNeeded() {
    return state.customerMode === 'new' || !state.picked || !state.picked.consent;
  }
  let searchTimer = null;
  search.addEventListener('input', () => {
    dropPick();
    clearTimeout(searchTimer);
    searchTimer = setTimeout(findCustomers, 200);
  });
  name.addEventListener('input', renderForm);

  // A consent ticked is for the person it was ticked for: it goes with the pick.
  function dropPick() {
    state.picked = null;
    consentGiven.checked = false;
    for (const b of results.children) b.setAttribute('aria-selected', 'false');
    renderForm();
  }

  // Who the scan goes to, as the form stands: null until named or picked.
  function subject() {
    if (state.customerMode === 'new') return name.value.trim() || null;
    return state.picked ? state.picked.name : null;
  }

  async function findCustomers() {
    const seq = ++state.searchSeq;
    const q = search.value.trim();
    try {
      const { customers } = await api.findCustomers({ q });
      if (seq !== state.searchSeq) return;  // a newer search is on its way
      // The list changes under the operator's finger: nothing stays picked.
      dropPick();
      results.dataset.query = q;
      clear(
        results,
        customers.length
          ? customers.slice(0, 50).map((c) =>
              h(
                'button',
                {
                  type: 'button',
                  role: 'option',
                  class: 'pick',
                  'aria-selected': 'false',
                  dataset: { customer: c.id },
                  onclick: (/** @type {MouseEvent} */ e) => {
                    const row = /** @type {HTMLElement} */ (e.currentTarget);
                    state.picked = { id: c.id, name: c.name, consent: c.consent || null };
                    consentGiven.checked = false;
                    state.names.set(c.id, c.name);
                    for (const b of results.children) b.setAttribute('aria-selected', b === row ? 'true' : 'false');
                    renderForm();
                  },
                },
                h('strong', {}, c.name),
                h('small', { class: 'muted' }, ` ${c.contact || ''} · since ${when(c.created_at)}`),
              ),
            )
          : h('p', { class: 'muted' }, 'No customer matches.'),
      );
    } catch (e) {
      if (seq !== state.searchSeq) return;
      dropPick();
      clear(results, h('p', { class: 'form-error' }, errorText(e)));
    }
  }

  const modeSwitch = h(
    'div',
    { class: 'segmented', role: 'radiogroup', 'aria-label': 'Customer' },
    [
      ['new', 'New customer'],
      ['existing', 'Returning customer'],
    ].map(([v, t]) =>
      h(
        'button',
        {
          type: 'button',
          role: 'radio',
          'aria-checked': v === 'new' ? 'true' : 'false',
          onclick: (e) => {
            state.customerMode = v;
            for (const b of e.target.parentElement.children) b.setAttribute('aria-checked', b === e.target ? 'true' : 'false');
            modeNew.hidden = v !== 'new';
            modeExisting.hidden = v !== 'existing';
            dropPick();
            if (v === 'existing') {
              findCustomers();
              search.focus();
            } else name.focus();
          },
        },
        t,
      ),
    ),
  );

  formBox.append(
    h(
      'form',
      {
        onsubmit: async (e) => {
          e.preventDefault();
          const body = {};
          if (state.customerMode === 'new') {
            if (!name.value.trim()) {
              toast('Give the customer’s name.', 'error');
              name.focus();
              return;
            }
            body.customer = { name: name.value.trim(), ...(contact.value.trim() ? { contact: contact.value.trim() } : {}) };
          } else {
            if (!state.picked) {
              toast('Pick the customer from the list.', 'error');
              return;
            }
            body.customer_id = state.picked.id;
          }
          if (consentNeeded()) {
            if (!consentGiven.checked) {
              toast('Read the terms with the customer and tick their consent first.', 'error');
              consentGiven.focus();
              return;
            }
            body.consent = true;
          }
          const who = subject();
          const isNew = state.customerMode === 'new';
          // Named once more before the rig moves; the pick may not change meanwhile.
          const picked = state.picked;
          const sure = await confirmDialog(`${isNew ? 'A new customer' : 'A returning customer'}: ${who}${isNew && contact.value.trim() ? ` (${contact.value.trim()})` : ''}. The lasers and cameras start when you confirm.`, {
            title: `Scanning: ${who}`,
            confirm: `Scan ${who}`,
          });
          if (!sure) return;
          if (!isNew && state.picked !== picked) {
            toast('The pick changed; pick the customer again.', 'error');
            return;
          }
          startButton.disabled = true;
          try {
            const { job } = await api.startScan(body);
            state.myJob = job.id;
            // The job's events may have come first and drawn the card without the name.
            if (job.customer_id) state.names.set(job.customer_id, who);
            startedJob(job);
            renderJob();
            name.value = '';
            contact.value = '';
            consentGiven.checked = false;
          } catch (err) {
            toast(errorText(err), 'error');
          } finally {
            renderForm();
          }
        },
      },
      h('h2', {}, 'New scan'),
      modeSwitch,
      modeNew,
      modeExisting,
      consentOnRecord,
      consentBox,
      wantedPostureCard(),
      h('p', { class: 'muted small' }, 'Ask the customer to stand on the marks like the picture and to hold still for about two minutes.'),
      checkButton,
      startButton,
    ),
  );

  async function checkPosture() {
    checkButton.disabled = true;
    try {
      const { job } = await api.checkPosture();
      state.myJob = job.id;
      startedJob(job);
    } catch (e) {
      toast(errorText(e), 'error');
    } finally {
      renderForm();
    }
  }

  function renderForm() {
    const busy = (state.rig && state.rig.busy) || (state.job && state.job.state === 'running');
    const who = subject();
    const picked = state.customerMode === 'existing' ? state.picked : null;
    consentBox.hidden = !consentNeeded() || (state.customerMode === 'existing' && !picked);
    consentOnRecord.hidden = !(picked && picked.consent);
    if (picked && picked.consent) consentOnRecord.textContent = `Consent given ${when(picked.consent.given_at)}, recorded by ${picked.consent.recorded_by}.`;
    checkButton.disabled = !!busy;
    startButton.disabled = !!busy;
    clear(
      startButton,
      busy ? 'The rig is busy' : 'Start scan',
      h('small', { class: 'scan-subject', id: 'scan-subject' }, who ? `Scanning: ${who}` : state.customerMode === 'new' ? 'Give the customer’s name' : 'Pick the customer from the list'),
    );
  }

  // ---- the job
  const previewGrid = h('div', { class: 'previews' });
  // The answer to starting a job is older than any event about it that came
  // first (a prompt asked at once): it only shows a job not heard of yet.
  /** @param {Job} job */
  function startedJob(job) {
    if (!state.job || state.job.id !== job.id) setJob(job);
  }

  /** @param {Job} job */
  function setJob(job) {
    if (!state.job || state.job.id !== job.id) {
      state.lastFraction = 0;
      state.previews.clear();
      previewGrid.replaceChildren();
    }
    state.job = job;
    renderJob();
    renderForm();
    renderRig();
  }

  function renderJob() {
    const j = state.job;
    if (!j) {
      clear(jobBox, h('h2', {}, 'Progress'), h('p', { class: 'muted' }, 'No job is running.'));
      return;
    }
    const running = j.state === 'running';
    page.classList.toggle('job-running', running);
    const overall = overallFraction(j.kind, j.stage, j.fraction);
    // A stage the bar does not know keeps the last position rather than jumping.
    if (overall !== null) state.lastFraction = running ? Math.max(state.lastFraction || 0, overall) : overall;
    const pct = j.state === 'complete' ? 100 : Math.round((state.lastFraction || 0) * 100);
    const left = running ? timeLeftText(state.lastFraction || 0, (Date.now() - Date.parse(j.started_at || '')) / 1000) : null;
    let prompt = null;
    clear(
      jobBox,
      h('h2', {}, { calibrate: 'Calibration', reprocess: 'Reprocessing', posture_check: 'Posture check' }[j.kind] || 'Scan'),
      j.kind === 'scan' && j.customer_id ? h('p', { class: 'job-subject', id: 'job-subject' }, `Scanning: ${customerName(j.customer_id)}`) : null,
      h('p', { class: `job-state ${j.state}`, dataset: { state: j.state, stage: j.stage || '', job: j.id } }, running ? `${stageText(j.stage)}…` : { complete: 'Done', failed: 'Failed', cancelled: 'Cancelled' }[j.state] || j.state),
      h('progress', { max: 100, value: pct, 'aria-label': 'Progress' }),
      h('p', { class: 'muted small', id: 'job-figures' }, `${pct} %${j.frames ? ` · ${j.frames} frames` : ''}${left ? ` · ${left}` : ''}`),
      j.error ? h('p', { class: 'form-error' }, j.error) : null,
      running && j.prompt ? (prompt = promptBox(j)) : null,
      j.kind === 'posture_check' && j.state === 'complete' ? postureCheckCard(j.posture_check) : null,
      j.kind === 'scan' || j.kind === 'posture_check' ? previewGrid : null,
      // The lasers' stop stays in view wherever the page is scrolled.
      running ? h('div', { class: 'cancel-bar' }, h('button', { type: 'button', class: 'danger big', id: 'cancel-job', onclick: () => cancel(j) }, 'Cancel')) : null,
      !running && j.scan_id && j.state === 'complete' && state.repeat?.scanId === j.scan_id ? repeatCard(state.repeat) : null,
      !running && j.scan_id && j.state === 'complete' && state.repeat?.scanId !== j.scan_id ? h('a', { class: 'button primary', href: `/scans/${enc(j.scan_id)}` }, 'Open the result') : null,
    );
    // A new request to the person at the rig comes into view, wherever the page was.
    if (prompt && state.shownPrompt !== j.prompt.id) prompt.scrollIntoView({ block: 'center', behavior: 'smooth' });
    state.shownPrompt = prompt ? j.prompt.id : null;
  }

  // This station's scan is done: the result opens, unless it differs from the
  // customer's earlier scan today by more than the shop allows; then the station
  // stays, says which values, and offers another scan while the customer is here.
  async function finished(job) {
    let check = null;
    try {
      check = await api.getRepeat(job.scan_id);
    } catch {
      // The comparison is an aid: without it the result opens as before.
    }
    if (disposed) return;
    if (check?.earlier && check.beyond?.length) {
      state.repeat = { scanId: job.scan_id, customerId: job.customer_id, check };
      renderJob();
      document.getElementById('repeat-check')?.scrollIntoView({ block: 'center' });
      return;
    }
    toast('Scan done; opening the result.', 'ok');
    ctx.router.navigate(`/scans/${enc(job.scan_id)}`);
  }

  /** @param {{ scanId: string, customerId: string, check: any }} r */
  function repeatCard(r) {
    const unit = preferredUnit();
    const who = customerName(r.customerId);
    const at = new Date(r.check.earlier.started_at).toLocaleTimeString(undefined, { hour: '2-digit', minute: '2-digit' });
    const n = r.check.beyond.length;
    return h(
      'div',
      { class: 'repeat-check', id: 'repeat-check', role: 'alert', dataset: { beyond: String(n) } },
      h('h3', {}, `${n} of ${r.check.compared} values differ from ${who}’s scan at ${at}`),
      h(
        'p',
        {},
        `By more than the shop allows between two scans (${r.check.repeatability_mm ? formatLength(r.check.repeatability_mm, unit) : 'the ISO 20685-1 allowance'}): the customer may have moved or stood differently. Scan again while they are here?`,
      ),
      h(
        'table',
        { class: 'measurements compact' },
        h('thead', {}, h('tr', {}, h('th', { scope: 'col' }, 'Measurement'), h('th', { scope: 'col', class: 'num' }, 'Earlier'), h('th', { scope: 'col', class: 'num' }, 'Now'), h('th', { scope: 'col', class: 'num' }, 'Change (allowed)'))),
        h(
          'tbody',
          {},
          r.check.beyond.map((d) =>
            h(
              'tr',
              { dataset: { name: d.name } },
              h('td', {}, d.label || d.name),
              h('td', { class: 'num' }, formatLength(d.earlier_mm, unit)),
              h('td', { class: 'num' }, formatLength(d.value_mm, unit)),
              h('td', { class: 'num' }, `${formatDifference(d.difference_mm, unit)} (${formatLength(d.tolerance_mm, unit)})`),
            ),
          ),
        ),
      ),
      h(
        'div',
        { class: 'row' },
        h('button', { type: 'button', class: 'primary', id: 'scan-again', onclick: () => scanAgain(r.customerId, who) }, `Scan ${who} again`),
        h('a', { class: 'button', href: `/scans/${enc(r.scanId)}` }, 'Open the result'),
      ),
    );
  }

  // The customer picked for another scan, as a returning customer: the operator
  // then presses Start and confirms, as for anyone.
  async function scanAgain(customerId, who) {
    /** @type {HTMLElement} */ (modeSwitch.children[1]).click();
    search.value = who;
    await findCustomers();
    /** @type {HTMLElement | null} */ (results.querySelector(`[data-customer="${CSS.escape(customerId)}"]`))?.click();
    startButton.scrollIntoView({ block: 'center' });
    startButton.focus();
  }

  // The name of the customer a job scans; looked up once when this page did not
  // start it (another station, or a reload).
  /** @param {string} id */
  function customerName(id) {
    const known = state.names.get(id);
    if (known) return known;
    state.names.set(id, '…');
    api
      .getCustomer(id)
      .then((customer) => {
        state.names.set(id, customer.name || id);
        renderJob();
      })
      .catch(() => state.names.set(id, id));
    return '…';
  }

  // What the job waits for a person to do: hold the lens board before a camera,
  // or take it out of the rig. Confirming answers that very prompt; a newer one
  // (the picture could not be used) replaces it with the reason.
  /** @param {Job} j a job with a prompt */
  function promptBox(j) {
    const p = j.prompt;
    const title = p.kind === 'remove_dot_grid' ? 'Clear the rig' : `Lens board before camera ${p.camera}`;
    // Disabled once answered, even when another event redraws the card before the job moves on.
    const done = h('button', { type: 'button', class: 'primary', disabled: state.answered === `${j.id}/${p.id}`, dataset: { prompt: p.id }, onclick: () => answer(j, p, done) }, p.kind === 'remove_dot_grid' ? 'The rig is clear' : 'Holding it: take the picture');
    return h(
      'div',
      { class: 'prompt', role: 'alertdialog', 'aria-label': title, dataset: { kind: p.kind, camera: p.camera || '' } },
      h('h3', {}, title),
      p.why ? h('p', { class: 'form-error prompt-why' }, `The last picture could not be used: ${p.why}`) : null,
      h('p', {}, p.text),
      done,
    );
  }

  /**
   * @param {Job} j
   * @param {import('../api.js').JobPrompt} p
   * @param {HTMLButtonElement} button
   */
  async function answer(j, p, button) {
    button.disabled = true;
    state.answered = `${j.id}/${p.id}`;
    try {
      await api.answerPrompt(j.id, { prompt: p.id });
    } catch (e) {
      state.answered = null;
      button.disabled = false;
      toast(errorText(e), 'error');
    }
  }

  /** @param {Job} j */
  async function cancel(j) {
    try {
      await api.cancelJob(j.id);
    } catch (e) {
      toast(errorText(e), 'error');
    }
  }

  /** @param {Extract<import('../events.js').EventMessage, { type: 'preview' }>} p */
  function showPreview(p) {
    let img = state.previews.get(p.camera);
    if (!img) {
      img = h('img', { alt: `Camera ${p.camera}`, dataset: { camera: p.camera } });
      state.previews.set(p.camera, img);
      // A tap enlarges a preview to the card's width (to see how the customer
      // stands); another shrinks it.
      const figure = h('figure', {}, img, h('figcaption', {}, p.camera));
      figure.addEventListener('click', () => figure.classList.toggle('enlarged'));
      previewGrid.append(figure);
    }
    img.src = `data:image/png;base64,${p.png_base64}`;
  }

  /** @param {string} scanId */
  async function shareFromStation(scanId) {
    try {
      const { measurements } = await api.getMeasurements(scanId);
      await shareDialog(scanId, measurements, preferredUnit());
    } catch (e) {
      toast(`No link made: ${errorText(e)}`, 'error');
    }
  }

  async function renderRecent() {
    try {
      const [{ scans }, { customers }] = await Promise.all([api.findScans({ limit: 6 }), api.findCustomers()]);
      const names = new Map(customers.map((c) => [c.id, c.name]));
      clear(
        recentBox,
        h('h2', {}, 'Latest scans'),
        scans.length
          ? h(
              'ul',
              { class: 'plain recent-scans' },
              scans.map((s) =>
                h(
                  'li',
                  { dataset: { scan: s.id } },
                  h('a', { href: `/scans/${enc(s.id)}` }, names.get(s.customer_id) || s.customer_id),
                  ` · ${when(s.started_at)} · ${s.status} `,
                  // The link and its QR code handed over here, while the customer is still at the rig.
                  s.status === 'complete' && ctx.can.share(ctx.session.role)
                    ? h('button', { type: 'button', class: 'share-scan', onclick: () => shareFromStation(s.id) }, 'Share…')
                    : null,
                ),
              ),
            )
          : h('p', { class: 'muted' }, 'None yet.'),
      );
    } catch (e) {
      clear(recentBox, h('h2', {}, 'Latest scans'), h('p', { class: 'form-error' }, errorText(e)));
    }
  }

  // ---- events
  const stop = ctx.events().subscribe((msg) => {
    switch (msg.type) {
      case 'connection':
        state.connection = msg.state;
        conn.textContent = msg.state === 'open' ? '● live' : '○ reconnecting…';
        conn.className = `conn ${msg.state}`;
        break;
      case 'hello':
      case 'rig':
        state.rig = msg.rig;
        if (msg.rig.job && (!state.job || state.job.id === msg.rig.job.id || msg.rig.job.state === 'running')) state.job = msg.rig.job;
        renderRig();
        renderJob();
        renderForm();
        break;
      case 'job':
        if (!state.job || state.job.id === msg.job.id || msg.job.state === 'running') setJob(msg.job);
        break;
      case 'preview':
        if (state.job && msg.job === state.job.id) showPreview(msg);
        break;
      case 'scan_finished':
        setJob(msg.job);
        renderRecent();
        if (msg.job.state === 'complete' && msg.job.id === state.myJob && msg.job.scan_id) finished(msg.job);
        break;
      default:
    }
  });
  conn.textContent = ctx.events().state === 'open' ? '● live' : '○ connecting…';

  renderRig();
  renderJob();
  renderRecent();
  try {
    const rig = await api.getRig();
    state.rig = rig;
    if (rig.job) state.job = rig.job;
    renderRig();
    renderJob();
    renderForm();
  } catch (e) {
    toast(errorText(e), 'error');
  }
  return () => {
    disposed = true;
    stop();
    clearTimeout(searchTimer);
  };
}
