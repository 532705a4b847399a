// Staff accounts (admin): add, change role or password, delete (never the last
// admin; the server refuses).
import { api } from '../api.js';
import { clear, confirmDialog, errorText, formDialog, h, label, toast, when } from '../ui/dom.js';

/** @typedef {import('../api.js').Account} Account */

const ROLES = ['operator', 'tailor', 'admin'];

/**
 * @param {HTMLElement} container
 * @param {Record<string, string>} _params
 * @param {import('../main.js').PageContext} ctx
 */
export async function mount(container, _params, ctx) {
  const list = h('div', { class: 'results' });
  container.append(
    h(
      'section',
      { class: 'page narrow accounts-page' },
      h('div', { class: 'page-head' }, h('h1', {}, 'Staff accounts'), h('button', { class: 'primary', type: 'button', onclick: add }, 'Add account…')),
      h('p', { class: 'muted' }, 'Operators run the rig; tailors measure and save; admins also manage accounts and delete records.'),
      list,
    ),
  );

  async function load() {
    try {
      const { accounts } = await api.listAccounts();
      clear(
        list,
        h(
          'table',
          { class: 'list' },
          h('thead', {}, h('tr', {}, h('th', {}, 'User'), h('th', {}, 'Role'), h('th', {}, 'Since'), h('th', {}, ''))),
          h(
            'tbody',
            {},
            accounts.map((a) =>
              h(
                'tr',
                { dataset: { user: a.username } },
                h('td', {}, a.username, a.username === ctx.session.user.username ? h('small', { class: 'muted' }, ' (you)') : null),
                h(
                  'td',
                  {},
                  h(
                    'select',
                    { 'aria-label': `Role of ${a.username}`, onchange: (e) => change(a, { role: e.target.value }) },
                    ROLES.map((r) => h('option', { value: r, selected: r === a.role }, r)),
                  ),
                ),
                h('td', {}, when(a.created_at)),
                h(
                  'td',
                  { class: 'end' },
                  h('button', { type: 'button', class: 'small', onclick: () => password(a) }, 'New password…'),
                  h('button', { type: 'button', class: 'small danger', onclick: () => remove(a) }, 'Delete'),
                ),
              ),
            ),
          ),
        ),
      );
    } catch (e) {
      clear(list, h('p', { class: 'form-error' }, errorText(e)));
    }
  }

  async function add() {
    const data = await formDialog('Add a staff account', [
      label('Username', h('input', { name: 'username', required: true, pattern: '[A-Za-z0-9._\\-]{1,64}', autocomplete: 'off' }), 'letters, digits, . _ -'),
      label('Role', h('select', { name: 'role' }, ROLES.map((r) => h('option', { value: r }, r)))),
      label('Password', h('input', { name: 'password', type: 'password', required: true, minlength: 10, autocomplete: 'new-password' }), 'at least 10 characters'),
    ]);
    if (!data) return;
    try {
      await api.addAccount({ username: data.get('username'), role: data.get('role'), password: data.get('password') });
      toast(`Account ${data.get('username')} added.`, 'ok');
      load();
    } catch (e) {
      toast(errorText(e), 'error');
    }
  }

  /**
   * @param {Account} a
   * @param {Parameters<typeof api.changeAccount>[1]} body
   */
  async function change(a, body) {
    try {
      await api.changeAccount(a.username, body);
      toast(`${a.username} changed.`, 'ok');
    } catch (e) {
      toast(errorText(e), 'error');
    }
    load();
  }

  /** @param {Account} a */
  async function password(a) {
    const data = await formDialog(`New password for ${a.username}`, [
      label('Password', h('input', { name: 'password', type: 'password', required: true, minlength: 10, autocomplete: 'new-password' }), 'at least 10 characters; their sessions end'),
    ]);
    if (data) change(a, { password: data.get('password') });
  }

  /** @param {Account} a */
  async function remove(a) {
    if (!(await confirmDialog(`Delete the account ${a.username}?`, { confirm: 'Delete', danger: true }))) return;
    try {
      await api.deleteAccount(a.username);
      load();
    } catch (e) {
      toast(errorText(e), 'error');
    }
  }

  load();
}
