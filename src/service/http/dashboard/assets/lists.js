// The home page, the job list and the sweep list. Lists refresh themselves: every second
// while something in them is queued or running (progress bars move), every 5 s otherwise.

import {FINISHED, api, badge, card, errorBox, fmtElapsed, h, progressBar, progressCell, replace, shortId,
  sweepBadge, timeCell} from './util.js';

const STATUSES = ['accepted', 'running', 'successful', 'failed', 'dismissed'];

/** Re-renders with `load` now and then, faster while `busy(data)`. */
function refreshing(load, render, busy) {
  const tick = async () => {
    let data = null;
    try {
      data = await load();
      render(data);
    } catch (error) {
      render(null, error);
    }
    setTimeout(tick, data && busy(data) ? 1000 : 5000);
  };
  return tick();
}

function jobRow(job) {
  const sweep = job.sweepID
    ? h('a', {href: `/sweeps/${job.sweepID}`, title: job.sweepID}, shortId(job.sweepID)) : '';
  return h('tr', {'data-job': job.jobID, 'data-status': job.status},
    h('td', {}, h('a', {href: `/jobs/${job.jobID}`, title: job.jobID, class: 'mono'}, shortId(job.jobID))),
    // Labels (each a link to the jobs that have it) and the note under the process: no
    // column of their own, so that the table still fits 1280 px.
    h('td', {}, job.processID, (job.labels || []).length ? h('div', {class: 'labels'},
      job.labels.map((label) => h('a', {class: 'chip', 'data-label': label,
        href: `/jobs?label=${encodeURIComponent(label)}`}, label))) : null,
    job.note ? h('div', {class: 'message', title: job.note}, job.note) : null),
    h('td', {}, badge(job.status), job.message && (job.status === 'failed'
        || (job.status === 'successful' && job.message !== 'finished'))
      ? h('div', {class: 'message', title: job.message}, job.message) : null),
    h('td', {}, job.verdict ? h('span', {class: `badge ${job.verdict}`, 'data-verdict': job.verdict}, job.verdict) : ''),
    h('td', {}, progressCell(job)),
    h('td', {}, timeCell(job.created)),
    h('td', {}, timeCell(job.finished)),
    h('td', {class: 'muted'}, fmtElapsed(job.started, job.finished)),
    h('td', {}, sweep));
}

function jobTable(jobs) {
  if (!jobs.length) return h('p', {class: 'muted'}, 'No jobs yet. ', h('a', {href: '/ui/submit'}, 'Submit one.'));
  return h('div', {class: 'scroll'}, h('table', {class: 'list', 'data-list': 'jobs'},
    h('thead', {}, h('tr', {}, ['Job', 'Process', 'Status', 'Verdict', 'Progress', 'Created', 'Finished', 'Run time', 'Sweep']
      .map((c) => h('th', {}, c)))),
    h('tbody', {}, jobs.map(jobRow))));
}

function countsText(counts) {
  return STATUSES.filter((s) => counts[s]).map((s) => `${counts[s]} ${s === 'accepted' ? 'queued' : s}`).join(', ');
}

function sweepTable(sweeps) {
  if (!sweeps.length) return h('p', {class: 'muted'}, 'No sweeps yet.');
  return h('div', {class: 'scroll'}, h('table', {class: 'list', 'data-list': 'sweeps'},
    h('thead', {}, h('tr', {}, ['Sweep', 'Process', 'Design', 'Status', 'Progress', 'Runs', 'Created', 'Finished']
      .map((c) => h('th', {}, c)))),
    h('tbody', {}, sweeps.map((sweep) => h('tr', {'data-sweep': sweep.sweepID, 'data-status': sweep.status},
      h('td', {}, h('a', {href: `/sweeps/${sweep.sweepID}`, title: sweep.sweepID, class: 'mono'}, shortId(sweep.sweepID))),
      h('td', {}, sweep.processID),
      h('td', {}, sweep.design),
      h('td', {}, sweepBadge(sweep)),
      h('td', {}, FINISHED.has(sweep.status) ? '' : progressBar(sweep.progress, sweep.status)),
      h('td', {}, `${sweep.runs}`, h('div', {class: 'message'}, countsText(sweep.counts))),
      h('td', {}, timeCell(sweep.created)),
      h('td', {}, timeCell(sweep.finished)))))));
}

const busyJobs = (doc) => doc.jobs.some((job) => !FINISHED.has(job.status));
const busySweeps = (doc) => doc.sweeps.some((sweep) => !FINISHED.has(sweep.status));

function apiQuery() {
  const params = new URLSearchParams(location.search);
  params.delete('f');
  const text = params.toString();
  return text ? `?${text}` : '';
}

export async function home(main) {
  const jobs = h('div', {}, h('p', {class: 'muted'}, 'Loading…'));
  const sweeps = h('div', {}, h('p', {class: 'muted'}, 'Loading…'));
  replace(main,
    h('div', {class: 'intro'},
      h('h1', {}, 'chocmodal'),
      h('p', {}, 'Modal multi-contact dynamics of slender beam bundles, as jobs. ',
        h('a', {class: 'button', href: '/ui/submit'}, 'Submit a job or a sweep'))),
    card('Latest jobs', jobs, h('p', {}, h('a', {href: '/jobs'}, 'All jobs →'))),
    card('Latest sweeps', sweeps, h('p', {}, h('a', {href: '/sweeps'}, 'All sweeps →'))));
  refreshing(() => api('/jobs?limit=10'), (doc, error) => replace(jobs, error ? errorBox(error) : jobTable(doc.jobs)),
    busyJobs);
  refreshing(() => api('/sweeps?limit=5'),
    (doc, error) => replace(sweeps, error ? errorBox(error) : sweepTable(doc.sweeps)), busySweeps);
}

function filterBar(params, processes) {
  const link = (label, change) => {
    const next = new URLSearchParams(params);
    next.delete('cursor');
    next.delete('f');
    for (const [key, value] of Object.entries(change)) {
      if (value === null) next.delete(key); else next.set(key, value);
    }
    const text = next.toString();
    return `/jobs${text ? `?${text}` : ''}`;
  };
  const current = params.get('status') || '';
  const statusLinks = [['all', null], ...STATUSES.map((s) => [s === 'accepted' ? 'queued' : s, s])]
    .map(([label, value]) => h('a', {href: link(label, {status: value}),
      class: (value || '') === current ? 'chip current' : 'chip'}, label));
  const inSweep = params.get('inSweep');
  const sweepLinks = [['with sweep runs', null], ['without sweep runs', 'false'], ['sweep runs only', 'true']]
    .map(([label, value]) => h('a', {href: link(label, {inSweep: value}), 'data-in-sweep': value ?? 'any',
      class: (value || '') === (inSweep || '') ? 'chip current' : 'chip'}, label));
  const select = h('select', {'aria-label': 'Process',
    onchange: (event) => { location.href = link('', {processID: event.target.value || null}); }},
  h('option', {value: ''}, 'every process'),
  processes.map((p) => h('option', {value: p.id, selected: params.get('processID') === p.id}, p.id)));
  return h('div', {class: 'filters'}, statusLinks, select, h('span', {class: 'chips'}, sweepLinks));
}

export async function jobs(main) {
  const params = new URLSearchParams(location.search);
  const processes = await api('/processes').then((doc) => doc.processes).catch(() => []);
  const table = h('div', {}, h('p', {class: 'muted'}, 'Loading…'));
  const pager = h('p', {class: 'pager'});
  replace(main, h('h1', {}, 'Jobs'), filterBar(params, processes), card(null, table, pager));
  const query = apiQuery();
  refreshing(() => api(`/jobs${query}`), (doc, error) => {
    if (error) {
      replace(table, errorBox(error));
      return;
    }
    replace(table, jobTable(doc.jobs));
    const next = doc.links.find((l) => l.rel === 'next');
    replace(pager, params.has('cursor') ? h('a', {href: '/jobs'}, '← newest') : null, ' ',
      next ? h('a', {href: next.href}, 'older jobs →') : null);
  }, busyJobs);
}

export async function sweeps(main) {
  const table = h('div', {}, h('p', {class: 'muted'}, 'Loading…'));
  const pager = h('p', {class: 'pager'});
  replace(main, h('h1', {}, 'Sweeps'), card(null, table, pager));
  const query = apiQuery();
  refreshing(() => api(`/sweeps${query}`), (doc, error) => {
    if (error) {
      replace(table, errorBox(error));
      return;
    }
    replace(table, sweepTable(doc.sweeps));
    const next = doc.links.find((l) => l.rel === 'next');
    replace(pager, next ? h('a', {href: next.href}, 'older sweeps →') : null);
  }, busySweeps);
}
