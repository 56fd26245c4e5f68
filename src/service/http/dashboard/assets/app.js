// Entry point of the dashboard: the server says which page this is (`data-page` on the
// body); the page's module fills `<main>` from the JSON API.

import {errorBox, replace} from './util.js';

const pages = {
  home: () => import('./lists.js').then((m) => m.home),
  jobs: () => import('./lists.js').then((m) => m.jobs),
  sweeps: () => import('./lists.js').then((m) => m.sweeps),
  signals: () => import('./signals.js').then((m) => m.signals),
  signal: () => import('./signals.js').then((m) => m.signal),
  job: () => import('./job.js').then((m) => m.job),
  sweep: () => import('./sweep.js').then((m) => m.sweep),
  submit: () => import('./submit.js').then((m) => m.submit),
};

async function start() {
  const page = document.body.dataset.page;
  const main = document.getElementById('main');
  for (const link of document.querySelectorAll('nav a[data-nav]')) {
    if (link.dataset.nav === page || `${link.dataset.nav}` === `${page}s`) link.classList.add('current');
  }
  try {
    const render = await pages[page]();
    await render(main, decodeURIComponent(location.pathname.split('/')[2] || ''));
  } catch (error) {
    console.error(error);
    replace(main, errorBox(error));
  }
}

start();
