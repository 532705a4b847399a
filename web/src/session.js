// Who is logged in: the session from /api/session (or /api/login), its CSRF
// token handed to api.js, and what the role may do (as the server's
// x-bodyscan-access says; the server checks again on every call).
import { api, setCsrfToken } from './api.js';

export const can = {
  runRig: (role) => role === 'operator' || role === 'admin',
  saveMeasurements: (role) => role === 'tailor' || role === 'admin',
  deleteRecords: (role) => role === 'admin',
  reprocess: (role) => role === 'admin',
  manageAccounts: (role) => role === 'admin',
  share: (role) => role === 'operator' || role === 'tailor' || role === 'admin',
};

export function homeFor(role) {
  return can.runRig(role) ? '/station' : '/archive';
}

export class Session {
  constructor() {
    /** @type {import('./api.js').Session | null} */
    this.user = null;
    this.checked = false;
  }

  get role() {
    return this.user ? this.user.role : null;
  }

  set(user) {
    this.user = user;
    this.checked = true;
    setCsrfToken(user ? user.csrf_token : null);
  }

  async refresh() {
    try {
      this.set(await api.getSession());
    } catch (e) {
      if (e.status !== 401) throw e;
      this.set(null);
    }
    return this.user;
  }

  async login(username, password) {
    const user = await api.login({ username, password });
    this.set(user);
    return user;
  }

  async logout() {
    try {
      await api.logout();
    } finally {
      this.set(null);
    }
  }
}
