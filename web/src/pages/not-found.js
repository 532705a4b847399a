import { h } from '../ui/dom.js';

export function mount(container) {
  container.append(h('section', { class: 'page narrow' }, h('h1', {}, 'Not found'), h('p', {}, 'There is no page here. '), h('a', { href: '/' }, 'Go to the start page')));
}
