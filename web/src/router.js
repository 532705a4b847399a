// Client-side routes over the History API. The server answers every path
// without a file extension with index.html, so links can be opened directly.
// A page is `mount(container, params, ctx)` returning an optional cleanup.

export class Router {
  constructor(routes, container, ctx) {
    this.routes = routes.map((r) => ({ ...r, re: r.notFound ? null : compile(r.path) }));
    this.container = container;
    this.ctx = ctx;
    this.cleanup = null;
    this.seq = 0;
    window.addEventListener('popstate', () => this.render());
    document.addEventListener('click', (e) => {
      /** @type {HTMLAnchorElement | null} */
      const a = e.target instanceof Element ? e.target.closest('a[href]') : null;
      if (!a || a.target || a.hasAttribute('download') || e.defaultPrevented || e.button !== 0) return;
      if (e.metaKey || e.ctrlKey || e.shiftKey || e.altKey) return;
      const url = new URL(a.href, window.location.href);
      if (url.origin !== window.location.origin || url.pathname.startsWith('/api/')) return;
      e.preventDefault();
      this.navigate(url.pathname + url.search);
    });
  }

  navigate(path, { replace = false } = {}) {
    if (replace) history.replaceState(null, '', path);
    else if (path !== location.pathname + location.search) history.pushState(null, '', path);
    return this.render();
  }

  match(pathname) {
    for (const r of this.routes) {
      const m = r.re && r.re.exec(pathname);
      if (m) return { route: r, params: { ...m.groups } };
    }
    return null;
  }

  async render() {
    const seq = ++this.seq;
    if (this.cleanup) {
      try {
        this.cleanup();
      } catch (e) {
        console.error(e);
      }
      this.cleanup = null;
    }
    const found = this.match(location.pathname);
    const params = found ? found.params : {};
    for (const k of Object.keys(params)) params[k] = decodeURIComponent(params[k]);
    const route = found ? found.route : this.routes.find((r) => r.notFound);
    // The page's code loads while the session is checked.
    const loading = Promise.resolve().then(() => route.load());
    loading.catch(() => {});
    const allowed = await this.ctx.guard(route);
    if (seq !== this.seq) return;
    if (allowed !== true) {
      if (typeof allowed === 'string') this.navigate(allowed, { replace: true });
      return;
    }
    this.container.replaceChildren();
    document.title = route.title ? `${route.title} · bodyscan` : 'bodyscan';
    this.ctx.onRoute(route);
    let page;
    try {
      page = await loading;
    } catch (e) {
      // A new version was installed while the page was open: its old chunks are gone.
      this.container.textContent = `This page could not load (${e.message}). Reload the page.`;
      return;
    }
    if (seq !== this.seq) return;
    const cleanup = await page.mount(this.container, params, this.ctx);
    if (seq !== this.seq) {
      if (typeof cleanup === 'function') cleanup();
      return;
    }
    this.cleanup = typeof cleanup === 'function' ? cleanup : null;
  }
}

function compile(pattern) {
  const source = pattern.replace(/\/:(\w+)/g, '/(?<$1>[^/]+)');
  return new RegExp(`^${source}/?$`);
}
