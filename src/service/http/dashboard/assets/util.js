// Shared helpers of the dashboard: building DOM nodes, reading the JSON API, formatting
// numbers, times and statuses. No framework: plain modules the browser loads as they are.

/** An HTML element: h('a', {href: '/jobs', class: 'x', onclick: f}, 'text', child, ...). */
export function h(tag, attrs = {}, ...children) {
  const element = document.createElement(tag);
  setAttributes(element, attrs);
  append(element, children);
  return element;
}

export function setAttributes(element, attrs) {
  for (const [key, value] of Object.entries(attrs || {})) {
    if (value === null || value === undefined || value === false) continue;
    if (key.startsWith('on') && typeof value === 'function') {
      element.addEventListener(key.slice(2), value);
    } else if (key === 'value') {
      // The attribute (what the DOM shows) and, for inputs already typed into, the value.
      element.setAttribute('value', String(value));
      if ('value' in element) element.value = value;
    } else {
      element.setAttribute(key, value === true ? '' : String(value));
    }
  }
}

export function append(parent, children) {
  for (const child of children.flat(Infinity)) {
    if (child === null || child === undefined || child === false) continue;
    parent.append(child instanceof Node ? child : document.createTextNode(String(child)));
  }
  return parent;
}

/** Replaces the children of `parent`. */
export function replace(parent, ...children) {
  parent.replaceChildren();
  return append(parent, children);
}

/** An error answer of the API, carrying its problem document (RFC 9457). */
export class ApiProblem extends Error {
  constructor(status, problem) {
    super(problem && problem.detail ? problem.detail : `HTTP ${status}`);
    this.status = status;
    this.problem = problem || {};
  }
}

const TOKEN_KEY = 'chocmodal-token';

/** The bearer token given in this tab (a service with an auth file), or null. */
export function token() {
  try {
    return sessionStorage.getItem(TOKEN_KEY);
  } catch {
    return null;
  }
}

function authHeaders() {
  const value = token();
  return value ? {Authorization: `Bearer ${value}`} : {};
}

/**
 * After a 401: a form at the top of the page asks for the team's token, keeps it in
 * this tab's session storage (never in a URL, never in a cookie) and reloads.
 */
function askForToken() {
  if (document.getElementById('token-form')) return;
  const input = h('input', {type: 'password', id: 'token-input', autocomplete: 'off', size: 40,
    placeholder: 'bearer token', 'aria-label': 'bearer token'});
  const form = h('form', {id: 'token-form', class: 'card token', onsubmit: (event) => {
    event.preventDefault();
    const value = input.value.trim();
    if (!value) return;
    try {
      sessionStorage.setItem(TOKEN_KEY, value);
    } catch {
      return;
    }
    location.reload();
  }},
  h('h2', {}, 'This service needs a token'),
  h('p', {}, token() ? 'The token of this tab is not valid. ' : '',
    'Paste your team\'s bearer token: it is kept in this tab only, and sent with every request.'),
  input, ' ', h('button', {type: 'submit'}, 'Use it'));
  (document.getElementById('main') || document.body).prepend(form);
  input.focus();
}

/** GET (or any method) on the JSON API; resolves to the parsed body, rejects with ApiProblem. */
export async function api(path, options = {}) {
  const response = await fetch(path, {
    ...options,
    headers: {Accept: 'application/json', ...authHeaders(), ...(options.headers || {})},
  });
  if (response.status === 401) askForToken();
  const text = await response.text();
  let body = null;
  try {
    body = text ? JSON.parse(text) : null;
  } catch {
    body = {detail: text};
  }
  if (!response.ok) throw new ApiProblem(response.status, body);
  return body;
}

/** POSTs a JSON body; resolves to {status, location, body} whatever the status. */
export async function post(path, body) {
  const response = await fetch(path, {
    method: 'POST',
    headers: {Accept: 'application/json', 'Content-Type': 'application/json', ...authHeaders()},
    body: typeof body === 'string' ? body : JSON.stringify(body),
  });
  if (response.status === 401) askForToken();
  const text = await response.text();
  let parsed = null;
  try {
    parsed = text ? JSON.parse(text) : null;
  } catch {
    parsed = {detail: text};
  }
  return {status: response.status, location: response.headers.get('Location'), body: parsed};
}

/** Calls `step` now and then every `interval` ms for as long as it resolves to true. */
export function poll(step, interval = 1000) {
  let stopped = false;
  const run = async () => {
    let again = false;
    try {
      again = await step();
    } catch (error) {
      console.error(error);
      again = true;
    }
    if (again && !stopped) setTimeout(run, interval);
  };
  run();
  return () => { stopped = true; };
}

export const FINISHED = new Set(['successful', 'partial', 'failed', 'dismissed']);

/** A number with `digits` significant digits, in exponent form when very small or large. */
export function fmt(value, digits = 4) {
  if (value === null || value === undefined) return '–';
  if (typeof value !== 'number') return String(value);
  if (!Number.isFinite(value)) return String(value);
  if (Number.isInteger(value) && Math.abs(value) < 1e6) return String(value);
  const magnitude = Math.abs(value);
  if (magnitude !== 0 && (magnitude < 1e-3 || magnitude >= 1e6)) {
    return value.toExponential(digits - 1).replace(/\.?0+e/, 'e');
  }
  return String(Number(value.toPrecision(digits)));
}

/** Whether a column (an axis pointer or a dotted metric) is a random generator's seed. */
export function isSeed(column) {
  return /(^|[/.])seed$/.test(String(column));
}

/** A value of a results column: a seed exactly as the integer it is (it names a draw:
 *  `573700123`, never `5.737e+8`), anything else as fmt does. */
export function fmtColumn(value, column, digits = 4) {
  if (isSeed(column) && Number.isInteger(value)) return String(value);
  return fmt(value, digits);
}

/** A number with its unit: fmt(v) + ' ' + unit. */
export function withUnit(value, unit, digits = 4) {
  return value === null || value === undefined ? '–' : `${fmt(value, digits)} ${unit}`;
}

const pad = (n) => String(n).padStart(2, '0');

/** An RFC 3339 time as local `YYYY-MM-DD HH:MM:SS`. */
export function fmtTime(text) {
  if (!text) return '–';
  const d = new Date(text);
  if (Number.isNaN(d.getTime())) return text;
  return `${d.getFullYear()}-${pad(d.getMonth() + 1)}-${pad(d.getDate())} ` +
    `${pad(d.getHours())}:${pad(d.getMinutes())}:${pad(d.getSeconds())}`;
}

/** An RFC 3339 time for a table cell: `MM-DD HH:MM:SS` in the current year (the full
 *  date and time as its tooltip), else as fmtTime. */
export function timeCell(text) {
  const full = fmtTime(text);
  const d = new Date(text);
  if (!text || Number.isNaN(d.getTime()) || d.getFullYear() !== new Date().getFullYear()) return full;
  return h('span', {title: full}, full.slice(5));
}

/** Seconds between two RFC 3339 times, as `1.23 s`, `4 min 05 s`, ... */
export function fmtElapsed(from, to) {
  if (!from || !to) return '';
  const seconds = (new Date(to) - new Date(from)) / 1000;
  if (!(seconds >= 0)) return '';
  if (seconds < 60) return `${fmt(seconds, 3)} s`;
  if (seconds < 3600) return `${Math.floor(seconds / 60)} min ${pad(Math.round(seconds % 60))} s`;
  return `${Math.floor(seconds / 3600)} h ${pad(Math.floor((seconds % 3600) / 60))} min`;
}

export function shortId(id) {
  return id ? id.slice(0, 8) : '';
}

/** A status badge: accepted, running, successful, failed, dismissed. */
export function badge(status) {
  const label = status === 'accepted' ? 'queued' : status;
  return h('span', {class: `badge ${status}`, 'data-status': status}, label);
}

/** The badge of a sweep: its status, with how many runs failed when some did
 *  (`partial: 2 of 32 failed`). */
export function sweepBadge(sweep) {
  const failed = (sweep.counts && sweep.counts.failed) || 0;
  const element = badge(sweep.status);
  if (failed > 0) element.textContent = `${element.textContent}: ${failed} of ${sweep.runs} failed`;
  element.setAttribute('data-failed', failed);
  return element;
}

/** A progress bar for a percentage 0–100; `data-value` holds the fraction 0–1; `prefix`
 *  goes before the percent (`stopped at` for a run that ended early). */
export function progressBar(percent, status, prefix = '') {
  const fraction = Math.max(0, Math.min(1, (Number(percent) || 0) / 100));
  const label = `${prefix ? `${prefix} ` : ''}${Math.round(fraction * 100)} %`;
  const bar = h('div', {
    class: `progress ${status || ''}`,
    role: 'progressbar',
    'aria-valuemin': 0,
    'aria-valuemax': 100,
    'aria-valuenow': Math.round(fraction * 100),
    'data-value': fraction,
    title: label,
  }, h('div', {class: 'fill', style: `width: ${(fraction * 100).toFixed(1)}%`}));
  return h('span', {class: 'progress-cell'}, bar, h('span', {class: 'percent'}, label));
}

/** A job's progress: the bar while it is queued or running, and where a failed or
 *  dismissed run stopped. */
export function progressCell(job) {
  if (job.status === 'running' && job.estimatedFinish) {
    // The time left at the pace of the run so far (the job's estimatedFinish).
    const left = fmtElapsed(new Date().toISOString(), job.estimatedFinish) || '0 s';
    return h('span', {'data-estimated-finish': job.estimatedFinish},
      progressBar(job.progress, job.status), h('span', {class: 'muted'}, ` about ${left} left`));
  }
  if (job.status === 'running' || job.status === 'accepted') return progressBar(job.progress, job.status);
  if (job.status === 'successful') return h('span', {class: 'muted'}, '100 %');
  if (job.progress > 0) return progressBar(job.progress, job.status, 'stopped at');
  return h('span', {class: 'muted'}, job.status === 'failed' ? 'before its first step' : '');
}

/** A JSON pointer token (RFC 6901): `~` and `/` escaped. */
export function pointerToken(key) {
  return String(key).replaceAll('~', '~0').replaceAll('/', '~1');
}

/**
 * The leaves of a JSON value as [pointer, value] pairs; arrays longer than `maxItems`
 * are summarized as one pair holding `[n items]`.
 */
export function leaves(value, prefix = '', maxItems = 8) {
  if (Array.isArray(value)) {
    if (value.length > maxItems) return [[prefix, `[${value.length} items]`]];
    return value.flatMap((item, i) => leaves(item, `${prefix}/${i}`, maxItems));
  }
  if (value && typeof value === 'object') {
    return Object.entries(value).flatMap(([k, v]) => leaves(v, `${prefix}/${pointerToken(k)}`, maxItems));
  }
  return [[prefix, value]];
}

/** A two-column table of [label, value] rows. */
export function keyValueTable(rows, attrs = {}) {
  return h('table', {class: 'kv', ...attrs},
    h('tbody', {}, rows.map(([key, value]) => h('tr', {}, h('th', {}, key), h('td', {}, value)))));
}

/** A section card with a heading. */
export function card(title, ...children) {
  return h('section', {class: 'card'}, title ? h('h2', {}, title) : null, ...children);
}

/** A message box for an error (an ApiProblem or any Error). */
export function errorBox(error) {
  const problem = error && error.problem ? error.problem : {};
  return h('div', {class: 'error', role: 'alert'},
    h('strong', {}, problem.title || 'Error'), ' ', problem.detail || String(error.message || error));
}

/** Saves `blob` as a file called `filename` (the browser's download). */
export function saveBlob(blob, filename) {
  const url = URL.createObjectURL(blob);
  const link = h('a', {href: url, download: filename});
  document.body.append(link);
  link.click();
  link.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

/** A download link, saved as `filename`. */
export function download(href, filename) {
  // With a token, a plain link would go without it: fetch, then save the bytes.
  const save = (event) => {
    if (!token()) return;
    event.preventDefault();
    fetch(href, {headers: authHeaders()})
      .then((response) => {
        if (!response.ok) throw new ApiProblem(response.status, null);
        return response.blob();
      })
      .then((blob) => saveBlob(blob, filename))
      .catch((error) => window.alert(`Download failed: ${error.message}`));
  };
  return h('a', {class: 'download', href, download: filename, onclick: save}, filename);
}
