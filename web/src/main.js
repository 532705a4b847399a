// The UI's entry: the session, the top bar, the routes and who may open them.
import './styles.css';
import { setUnauthorisedHandler } from './api.js';
import { EventStream } from './events.js';
import { Router } from './router.js';
import { Session, can, homeFor } from './session.js';
import { clear, h, toast } from './ui/dom.js';

const staff = ['operator', 'tailor', 'admin'];
const routes = [
  { path: '/login', title: 'Log in', public: true, bare: true, load: () => import('./pages/login.js') },
  { path: '/s/:token', title: 'Your scan', public: true, bare: true, load: () => import('./pages/customer.js') },
  { path: '/', roles: staff, load: () => ({ mount: (_c, _p, ctx) => ctx.router.navigate(homeFor(ctx.session.role), { replace: true }) }) },
  { path: '/station', title: 'Scan station', roles: ['operator', 'admin'], nav: 'Station', load: () => import('./pages/station.js') },
  { path: '/archive', title: 'Archive', roles: staff, nav: 'Archive', load: () => import('./pages/archive.js') },
  { path: '/customers/:id', title: 'Customer', roles: staff, navActive: 'Archive', load: () => import('./pages/customer-scans.js') },
  { path: '/scans/:id', title: 'Scan', roles: staff, navActive: 'Archive', load: () => import('./pages/viewer.js') },
  { path: '/compare/:a/:b', title: 'Compare scans', roles: staff, navActive: 'Archive', load: () => import('./pages/compare.js') },
  { path: '/validation', title: 'Validation', roles: staff, nav: 'Validation', load: () => import('./pages/validation.js') },
  { path: '/accounts', title: 'Accounts', roles: ['admin'], nav: 'Accounts', load: () => import('./pages/accounts.js') },
  { path: '*', notFound: true, title: 'Not found', public: true, load: () => import('./pages/not-found.js') },
];

const session = new Session();
let events = null;

// What every page's mount() is handed.
/** @typedef {typeof ctx} PageContext */
const ctx = {
  session,
  can,
  /** @type {Router} */
  router: null,
  // The event stream, opened on first use by a staff page and closed at logout.
  events() {
    if (!events) events = new EventStream().start();
    return events;
  },
  async guard(route) {
    if (!session.checked) {
      try {
        await session.refresh();
      } catch (e) {
        toast(e.message, 'error');
      }
    }
    if (route.public) return true;
    if (!session.user) return `/login?next=${encodeURIComponent(location.pathname + location.search)}`;
    if (route.roles && !route.roles.includes(session.role)) return homeFor(session.role);
    return true;
  },
  onRoute(route) {
    renderTopbar(route);
  },
  async logout() {
    await session.logout();
    if (events) events.stop();
    events = null;
    ctx.router.navigate('/login');
  },
};

function renderTopbar(route) {
  const bar = document.getElementById('topbar');
  bar.hidden = !!route.bare || !session.user;
  if (bar.hidden) return;
  const active = route.nav || route.navActive;
  clear(
    document.getElementById('topnav'),
    routes
      .filter((r) => r.nav && r.roles.includes(session.role))
      .map((r) => h('a', { href: r.path, class: r.nav === active ? 'active' : '', 'aria-current': r.nav === active ? 'page' : null }, r.nav)),
  );
  clear(
    document.getElementById('who'),
    h('span', { class: 'user' }, session.user.username, h('small', {}, session.role)),
    h('button', { class: 'link', onclick: () => ctx.logout() }, 'Log out'),
  );
}

setUnauthorisedHandler(() => {
  if (!session.user) return;
  session.set(null);
  toast('Your session ended; please log in again.', 'error');
  ctx.router.navigate(`/login?next=${encodeURIComponent(location.pathname)}`);
});

ctx.router = new Router(routes, document.getElementById('app'), ctx);
ctx.router.render();
