// Staff log in with the account an admin gave them; the server limits failures
// (429 with Retry-After), which the form shows as a wait.
import { ApiError } from '../api.js';
import { homeFor } from '../session.js';
import { h } from '../ui/dom.js';

/**
 * @param {HTMLElement} container
 * @param {Record<string, string>} _params
 * @param {import('../main.js').PageContext} ctx
 */
export function mount(container, _params, ctx) {
  const next = new URLSearchParams(location.search).get('next');
  const message = h('p', { class: 'form-error', role: 'alert', hidden: true });
  const username = h('input', { name: 'username', autocomplete: 'username', required: true, autocapitalize: 'none', spellcheck: false });
  const password = h('input', { name: 'password', type: 'password', autocomplete: 'current-password', required: true });
  const button = h('button', { class: 'primary wide', type: 'submit' }, 'Log in');
  const form = h(
    'form',
    {
      class: 'card login',
      onsubmit: async (e) => {
        e.preventDefault();
        button.disabled = true;
        message.hidden = true;
        try {
          const user = await ctx.session.login(username.value.trim(), password.value);
          const target = next && next.startsWith('/') && !next.startsWith('//') && !next.startsWith('/login') ? next : homeFor(user.role);
          ctx.router.navigate(target, { replace: true });
        } catch (err) {
          message.hidden = false;
          if (err instanceof ApiError && err.status === 429)
            message.textContent = `Too many failed attempts. Try again in ${Math.ceil((err.retryAfter || 60) / 60)} min.`;
          else if (err instanceof ApiError && err.status === 401) message.textContent = 'Wrong username or password.';
          else message.textContent = err.message;
          password.select();
        } finally {
          button.disabled = false;
        }
      },
    },
    h('h1', {}, 'bodyscan'),
    h('p', { class: 'muted' }, 'Staff log-in'),
    h('label', { class: 'field' }, h('span', {}, 'Username'), username),
    h('label', { class: 'field' }, h('span', {}, 'Password'), password),
    message,
    button,
  );
  container.append(h('section', { class: 'page login-page' }, form));
  username.focus();
}
