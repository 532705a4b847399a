// The server's REST API (docs/api.md): JSON in and out, the session cookie sent
// by the browser, the CSRF token on every state-changing call, and the server's
// error body turned into an ApiError whose message the UI can show as it is.
//
// Each call the UI makes is a function below, typed from the server's OpenAPI
// document through src/api-types.d.ts (made by `npm run gen:api-types`): its path
// must be one the document has, with the document's path parameters, and its
// query, body and answer are the document's. A path, parameter or field renamed
// in the document makes `npm run typecheck` fail where the UI still uses the old
// one.

/** @typedef {import('./api-types').paths} Paths */
/** @typedef {import('./api-types').components['schemas']} Schemas */
/** @typedef {Schemas['Session']} Session */
/** @typedef {Schemas['Role']} Role */
/** @typedef {Schemas['Account']} Account */
/** @typedef {Schemas['Job']} Job */
/** @typedef {Schemas['JobPrompt']} JobPrompt */
/** @typedef {Schemas['RigStatus']} RigStatus */
/** @typedef {Schemas['Customer']} Customer */
/** @typedef {Schemas['Consent']} Consent */
/** @typedef {Schemas['Scan']} Scan */
/** @typedef {Schemas['MeasureRequest']} MeasureRequest */
/** @typedef {Schemas['Measurement']} Measurement */
/** @typedef {Schemas['StoredMeasurement']} StoredMeasurement */
/** @typedef {Schemas['Share']} Share */
/** @typedef {Schemas['NewShare']} NewShare */
/** @typedef {Schemas['Posture']} Posture */
/** @typedef {Answer<'/api/share/{token}', 'get', 200>} ShareView */

/** @typedef {'get' | 'put' | 'post' | 'delete'} Method */

/**
 * The JSON the server answers method M on path P with, under status S.
 * @template {keyof Paths} P
 * @template {Method} M
 * @template {number} S
 * @typedef {Paths[P][M] extends { responses: Record<S, { content: { 'application/json': infer J } }> } ? J : never} Answer
 */

/**
 * The JSON body method M on path P takes.
 * @template {keyof Paths} P
 * @template {Method} M
 * @typedef {Paths[P][M] extends { requestBody: { content: { 'application/json': infer B } } } ? B : never} Body
 */

/**
 * The query parameters method M on path P takes.
 * @template {keyof Paths} P
 * @template {Method} M
 * @typedef {Paths[P][M] extends { parameters: { query?: infer Q } } ? Q : never} Query
 */

/**
 * The names of a path's parameters: `id` and `mid` of '/api/scans/{id}/measurements/{mid}'.
 * @template {string} T
 * @typedef {T extends `${string}{${infer K}}${infer Rest}` ? K | ParamNames<Rest> : never} ParamNames
 */

let csrfToken = null;

export function setCsrfToken(token) {
  csrfToken = token || null;
}

export class ApiError extends Error {
  /**
   * @param {number} status the HTTP status; 0 when the server did not answer
   * @param {string} code the server's error code, or 'error' or 'network'
   * @param {string} message
   * @param {number | null} [retryAfter] seconds, from Retry-After
   * @param {number | null} [triesLeft] a share link's wrong PIN: the tries left
   */
  constructor(status, code, message, retryAfter = null, triesLeft = null) {
    super(message);
    this.name = 'ApiError';
    this.status = status;
    this.code = code;
    this.retryAfter = retryAfter;
    this.triesLeft = triesLeft;
  }
}

/** @param {Response} response */
async function errorFrom(response) {
  let code = 'error';
  let message = `${response.status} ${response.statusText}`.trim();
  let triesLeft = null;
  try {
    /** @type {Schemas['Error']} */
    const body = await response.json();
    if (body && body.error) {
      code = body.error.code || code;
      message = body.error.message || message;
      triesLeft = body.error.tries_left ?? null;
    }
  } catch {
    // not JSON: keep the status line
  }
  const retry = response.headers.get('Retry-After');
  return new ApiError(response.status, code, message, retry ? Number(retry) : null, triesLeft);
}

// Called with every 401 from a staff call (the session ended): main.js sends the
// user to the login page.
/** @type {(error: ApiError) => void} */
let onUnauthorised = () => {};
/** @param {(error: ApiError) => void} fn */
export function setUnauthorisedHandler(fn) {
  onUnauthorised = fn;
}

/**
 * @typedef {object} RequestOptions
 * @property {string} [method]
 * @property {unknown} [body] sent as JSON
 * @property {AbortSignal} [signal]
 * @property {boolean} [raw] answer with the Response rather than its JSON
 * @property {boolean} [quiet401] a 401 is only thrown, not reported as the session's end
 * @property {Record<string, string>} [headers] sent besides the usual ones
 */

/**
 * @param {string} path
 * @param {RequestOptions} [options]
 * @returns {Promise<any>}
 */
async function request(path, { method = 'GET', body, signal, raw = false, quiet401 = false, headers: extra = {} } = {}) {
  /** @type {Record<string, string>} */
  const headers = { Accept: 'application/json', ...extra };
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  if (method !== 'GET' && method !== 'HEAD' && csrfToken) headers['X-CSRF-Token'] = csrfToken;
  let response;
  try {
    response = await fetch(path, {
      method,
      headers,
      body: body === undefined ? undefined : JSON.stringify(body),
      credentials: 'same-origin',
      signal,
    });
  } catch (e) {
    if (e.name === 'AbortError') throw e;
    throw new ApiError(0, 'network', 'the workstation does not answer; check the network');
  }
  if (!response.ok) {
    const error = await errorFrom(response);
    if (response.status === 401 && !quiet401) onUnauthorised(error);
    throw error;
  }
  if (raw) return response;
  if (response.status === 204) return null;
  return response.json();
}

/** @typedef {Omit<RequestOptions, 'method' | 'body'>} CallOptions */

/** @type {(path: string, opts?: CallOptions) => Promise<any>} */
const get = (path, opts) => request(path, { ...opts, method: 'GET' });
/** @type {(path: string, body?: unknown, opts?: CallOptions) => Promise<any>} */
const post = (path, body, opts) => request(path, { ...opts, method: 'POST', body: body ?? {} });
/** @type {(path: string, body: unknown, opts?: CallOptions) => Promise<any>} */
const put = (path, body, opts) => request(path, { ...opts, method: 'PUT', body });
/** @type {(path: string, opts?: CallOptions) => Promise<any>} */
const del = (path, opts) => request(path, { ...opts, method: 'DELETE' });

/**
 * A path of the document with its parameters filled in, each URI-encoded; a
 * path with parameters takes an object naming each of them.
 * @template {keyof Paths} P
 * @param {P} path
 * @param {[ParamNames<P>] extends [never] ? [] : [Record<ParamNames<P>, string | number>]} params
 * @returns {string}
 */
function at(path, ...params) {
  const [values] = params;
  return path.replace(/\{(\w+)\}/g, (_, name) => enc(String(values[name])));
}

// ---- session

/** @returns {Promise<Answer<'/api/session', 'get', 200>>} */
const getSession = () => get(at('/api/session'), { quiet401: true });

/**
 * @param {Body<'/api/login', 'post'>} credentials
 * @returns {Promise<Answer<'/api/login', 'post', 200>>}
 */
const login = (credentials) => post(at('/api/login'), credentials, { quiet401: true });

/** @returns {Promise<null>} */
const logout = () => post(at('/api/logout'), {}, { quiet401: true });

// ---- accounts

/** @returns {Promise<Answer<'/api/accounts', 'get', 200>>} */
const listAccounts = () => get(at('/api/accounts'));

/**
 * @param {Body<'/api/accounts', 'post'>} account
 * @returns {Promise<Answer<'/api/accounts', 'post', 201>>}
 */
const addAccount = (account) => post(at('/api/accounts'), account);

/**
 * @param {string} username
 * @param {Body<'/api/accounts/{username}', 'put'>} change
 * @returns {Promise<Answer<'/api/accounts/{username}', 'put', 200>>}
 */
const changeAccount = (username, change) => put(at('/api/accounts/{username}', { username }), change);

/**
 * @param {string} username
 * @returns {Promise<null>}
 */
const deleteAccount = (username) => del(at('/api/accounts/{username}', { username }));

// ---- the rig and its jobs

/** @returns {Promise<Answer<'/api/rig', 'get', 200>>} */
const getRig = () => get(at('/api/rig'));

/** @returns {Promise<Answer<'/api/rig/calibrate', 'post', 202>>} */
const calibrate = () => post(at('/api/rig/calibrate'), {});

/** @returns {Promise<Answer<'/api/rig/posture-check', 'post', 202>>} */
const checkPosture = () => post(at('/api/rig/posture-check'), {});

/**
 * @param {Body<'/api/scans', 'post'>} scan
 * @returns {Promise<Answer<'/api/scans', 'post', 202>>}
 */
const startScan = (scan) => post(at('/api/scans'), scan);

/**
 * @param {string} id the job's
 * @param {Body<'/api/jobs/{id}/prompt', 'post'>} answer
 * @returns {Promise<Answer<'/api/jobs/{id}/prompt', 'post', 202>>}
 */
const answerPrompt = (id, answer) => post(at('/api/jobs/{id}/prompt', { id }), answer);

/**
 * @param {string} id the job's
 * @returns {Promise<Answer<'/api/jobs/{id}/cancel', 'post', 202>>}
 */
const cancelJob = (id) => post(at('/api/jobs/{id}/cancel', { id }), {});

// ---- customers and scans

/**
 * The terms a customer agrees to before their first scan.
 * @returns {Promise<Answer<'/api/consent', 'get', 200>>}
 */
const getConsent = () => get(at('/api/consent'));

/**
 * @param {Query<'/api/customers', 'get'>} [params]
 * @returns {Promise<Answer<'/api/customers', 'get', 200>>}
 */
const findCustomers = (params = {}) => get(at('/api/customers') + query(params));

/**
 * @param {string} id
 * @returns {Promise<Answer<'/api/customers/{id}', 'get', 200>>}
 */
const getCustomer = (id) => get(at('/api/customers/{id}', { id }));

/**
 * @param {string} id
 * @returns {Promise<null>}
 */
const eraseCustomer = (id) => del(at('/api/customers/{id}', { id }));

/**
 * @param {Query<'/api/scans', 'get'>} [params]
 * @returns {Promise<Answer<'/api/scans', 'get', 200>>}
 */
const findScans = (params = {}) => get(at('/api/scans') + query(params));

/**
 * @param {string} id
 * @returns {Promise<Answer<'/api/scans/{id}', 'get', 200>>}
 */
const getScan = (id) => get(at('/api/scans/{id}', { id }));

/**
 * @param {string} id
 * @returns {Promise<null>}
 */
const deleteScan = (id) => del(at('/api/scans/{id}', { id }));

/**
 * @param {string} id
 * @returns {Promise<Answer<'/api/scans/{id}/reprocess', 'post', 202>>}
 */
const reprocess = (id) => post(at('/api/scans/{id}/reprocess', { id }), {});

// ---- measurements

/**
 * @param {string} id the scan's
 * @returns {Promise<Answer<'/api/scans/{id}/measurements', 'get', 200>>}
 */
const getMeasurements = (id) => get(at('/api/scans/{id}/measurements', { id }));

/**
 * The scan against its customer's earlier scan the same day: the values that
 * differ by more than the shop's repeatability.
 * @param {string} id
 * @returns {Promise<Answer<'/api/scans/{id}/repeat', 'get', 200>>}
 */
const getRepeat = (id) => get(at('/api/scans/{id}/repeat', { id }));

// ---- ISO 20685-1 validation: tape measurements and the report

/**
 * @param {string} id the scan's
 * @returns {Promise<Answer<'/api/scans/{id}/tape', 'get', 200>>}
 */
const getTape = (id) => get(at('/api/scans/{id}/tape', { id }));

/**
 * Enters (or replaces) the tape value of one automatic measurement.
 * @param {string} id the scan's
 * @param {string} name the measurement's
 * @param {Body<'/api/scans/{id}/tape/{name}', 'put'>} entry
 * @returns {Promise<Answer<'/api/scans/{id}/tape/{name}', 'put', 200>>}
 */
const putTape = (id, name, entry) => put(at('/api/scans/{id}/tape/{name}', { id, name }), entry);

/**
 * @param {string} id the scan's
 * @param {string} name the measurement's
 */
const deleteTape = (id, name) => del(at('/api/scans/{id}/tape/{name}', { id, name }));

/** @returns {Promise<Answer<'/api/validation', 'get', 200>>} */
const getValidation = () => get('/api/validation');

/**
 * @param {string} id the scan's
 * @param {Body<'/api/scans/{id}/measure', 'post'>} measureRequest
 * @returns {Promise<Answer<'/api/scans/{id}/measure', 'post', 200>>}
 */
const measure = (id, measureRequest) => post(at('/api/scans/{id}/measure', { id }), measureRequest);

/**
 * @param {string} id the scan's
 * @param {Body<'/api/scans/{id}/measurements', 'post'>} measurement
 * @returns {Promise<Answer<'/api/scans/{id}/measurements', 'post', 201>>}
 */
const saveMeasurement = (id, measurement) => post(at('/api/scans/{id}/measurements', { id }), measurement);

/**
 * @param {string} id the scan's
 * @param {number} mid the measurement's
 * @returns {Promise<null>}
 */
const deleteMeasurement = (id, mid) => del(at('/api/scans/{id}/measurements/{mid}', { id, mid }));

// ---- share links

/**
 * @param {string} id the scan's
 * @returns {Promise<Answer<'/api/scans/{id}/shares', 'get', 200>>}
 */
const listShares = (id) => get(at('/api/scans/{id}/shares', { id }));

/**
 * @param {string} id the scan's
 * @param {Body<'/api/scans/{id}/shares', 'post'>} share
 * @returns {Promise<Answer<'/api/scans/{id}/shares', 'post', 201>>}
 */
const makeShare = (id, share) => post(at('/api/scans/{id}/shares', { id }), share);

/**
 * @param {string} id the share's
 * @returns {Promise<null>}
 */
const withdrawShare = (id) => del(at('/api/shares/{id}', { id }));

/**
 * The customer's view of a share link; a 401 here is not a staff session's end
 * but a link that asks for its PIN (or was given a wrong one).
 * @param {string} token
 * @param {string} [pin] the PIN the shop read out, for a link that has one
 * @param {string} [locale] the plain labels' language (en, de); the shop's by default
 * @returns {Promise<Answer<'/api/share/{token}', 'get', 200>>}
 */
const getShare = (token, pin, locale) =>
  get(at('/api/share/{token}', { token }) + query({ locale }), { quiet401: true, headers: pin ? { 'X-Share-PIN': pin } : {} });

/**
 * The model a share link shows, as bytes (a link with a PIN sends it too).
 * @param {string} url
 * @param {string} [pin]
 * @returns {Promise<ArrayBuffer>}
 */
const getShareModel = async (url, pin) => (await request(url, { raw: true, quiet401: true, headers: pin ? { 'X-Share-PIN': pin } : {} })).arrayBuffer();

/**
 * The customer's sheet for a share link (PDF), as a Blob.
 * @param {string} token
 * @param {string} unit
 * @param {string} [locale] its language; the shop's by default
 * @param {string} [pin]
 * @returns {Promise<Blob>}
 */
const getShareSheet = async (token, unit, locale, pin) =>
  (await request(at('/api/share/{token}/sheet.pdf', { token }) + query({ unit, locale }), { raw: true, quiet401: true, headers: pin ? { 'X-Share-PIN': pin } : {} })).blob();

// Every call, as `api.getScan(id)` and so on.
export const api = {
  getSession,
  login,
  logout,
  listAccounts,
  addAccount,
  changeAccount,
  deleteAccount,
  getRig,
  calibrate,
  checkPosture,
  startScan,
  answerPrompt,
  cancelJob,
  getConsent,
  findCustomers,
  getCustomer,
  eraseCustomer,
  findScans,
  getScan,
  deleteScan,
  reprocess,
  getMeasurements,
  measure,
  saveMeasurement,
  deleteMeasurement,
  listShares,
  makeShare,
  withdrawShare,
  getShare,
  getShareModel,
  getShareSheet,
  getRepeat,
  getTape,
  putTape,
  deleteTape,
  getValidation,
};

// A query string from an object, skipping empty values.
/** @param {Record<string, string | number | boolean | null | undefined>} params */
export function query(params) {
  const q = new URLSearchParams();
  for (const [k, v] of Object.entries(params)) if (v !== undefined && v !== null && v !== '') q.set(k, String(v));
  const s = q.toString();
  return s ? `?${s}` : '';
}

export const enc = encodeURIComponent;
