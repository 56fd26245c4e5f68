// The submit page: a job or a sweep from a template (a shipped example, a past job's
// inputs, a past sweep's definition), edited as a form or as JSON. A refused request's
// problem document is shown field by field: each error sits next to the field its JSON
// pointer names (or the nearest enclosing group), and all are listed at the top.
//
// Query: `?example=<file>`, `?process=<id>`, `?from=<jobId>` (its inputs; if the job was
// refused as invalid, its errors are shown), `?sweep=<sweepId>` (its definition).

import {api, errorBox, h, pointerToken, post, replace} from './util.js';
import {fieldInfo, schemaAt, taggedVariants} from './schema.js';

/** The schema of a request body of `process`: its `inputs` (from the process description). */
const bodySchemas = new Map();
function bodySchema(process) {
  if (!bodySchemas.has(process)) {
    bodySchemas.set(process, api(`/processes/${process}`).then((description) => ({properties: {inputs: {properties:
      Object.fromEntries(Object.entries(description.inputs || {}).map(([name, input]) => [name, input.schema]))}}}))
      .catch(() => null));
  }
  return bodySchemas.get(process);
}

export async function submit(main) {
  const params = new URLSearchParams(location.search);
  const [examples, processes] = await Promise.all([
    api('/ui/examples.json'),
    api('/processes').then((doc) => doc.processes),
  ]);
  const state = {kind: 'job', process: processes[0] ? processes[0].id : '', body: {inputs: {}}};
  let pending = null;
  const example = (file) => examples.find((e) => e.file === file);
  const useExample = (e) => {
    state.kind = e.kind;
    state.process = e.process || e.body.process;
    state.body = structuredClone(e.body);
    state.file = e.file;
  };
  if (params.has('from')) {
    const id = params.get('from');
    const [status, body] = await Promise.all([api(`/jobs/${id}`), api(`/jobs/${id}/inputs`)]);
    Object.assign(state, {kind: 'job', process: status.processID, body});
    if (status.status === 'failed') {
      pending = await api(`/jobs/${id}/results`).then(() => null).catch((error) => error.problem);
    }
  } else if (params.has('sweep')) {
    const status = await api(`/sweeps/${params.get('sweep')}`);
    const d = status.definition;
    const body = {process: d.process, inputs: d.inputs, axes: d.axes, design: d.design};
    for (const key of ['samples', 'seed', 'policy', 'invalid_runs']) if (d[key] !== null && d[key] !== undefined) body[key] = d[key];
    Object.assign(state, {kind: 'sweep', process: d.process, body});
  } else if (params.has('example') && example(params.get('example'))) {
    useExample(example(params.get('example')));
  } else {
    const wanted = params.get('process');
    const first = examples.find((e) => e.kind === 'job' && (!wanted || e.process === wanted));
    if (first) useExample(first);
    else if (wanted) Object.assign(state, {process: wanted, body: {inputs: {}}});
  }

  const templateSelect = h('select', {'aria-label': 'template', onchange: (event) => {
    const e = example(event.target.value);
    if (e) {
      useExample(e);
      render();
    }
  }}, h('option', {value: ''}, '(current)'), examples.map((e) => h('option', {value: e.file},
    `${e.file} (${e.kind === 'sweep' ? `sweep of ${e.body.process}` : e.process})`)));
  const processSelect = h('select', {'aria-label': 'process', onchange: (event) => { state.process = event.target.value; }},
    processes.map((p) => h('option', {value: p.id}, p.id)));
  const target = h('span', {class: 'mono'});
  const form = h('form', {class: 'editor', 'data-editor': '', novalidate: true,
    oninput: () => { syncText(); }, onsubmit: (event) => { event.preventDefault(); send(); }});
  const text = h('textarea', {class: 'json', spellcheck: 'false', rows: 18, 'aria-label': 'request body as JSON',
    onchange: () => {
      try {
        state.body = JSON.parse(text.value);
        renderForm();
        replace(outcome);
      } catch (error) {
        replace(outcome, errorBox({problem: {title: 'Not JSON', detail: error.message}}));
      }
    }});
  const outcome = h('div', {class: 'outcome', 'aria-live': 'polite'});
  const sendButton = h('button', {type: 'button', class: 'primary', onclick: () => send()}, 'Submit');

  const syncText = () => {
    state.body = readForm(form, state.body);
    text.value = JSON.stringify(state.body, null, 2);
  };
  let schema = null;
  const renderForm = () => {
    replace(form, fields(state.body, '', null, {root: schema, body: state.body, onVariant}));
    text.value = JSON.stringify(state.body, null, 2);
  };
  // Another `type` of a tagged object (a section, a pulse, a gap law): the members both
  // variants have are kept, the new one's required members are offered empty.
  const onVariant = (pointer, tag) => {
    syncText();
    const found = taggedVariants(schemaAt(schema, state.body, pointer)).find((v) => v.tag === tag);
    if (!found) return;
    const old = getAt(state.body, pointer) || {};
    const next = {type: tag};
    for (const name of Object.keys(found.variant.properties)) {
      if (name === 'type') continue;
      if (old[name] !== undefined) next[name] = old[name];
      else if ((found.variant.required || []).includes(name)) next[name] = '';
    }
    setAt(state.body, pointer, next);
    renderForm();
  };
  const render = async () => {
    schema = await bodySchema(state.process);
    templateSelect.value = state.file || '';
    processSelect.value = state.process;
    processSelect.disabled = state.kind === 'sweep';
    target.textContent = state.kind === 'sweep' ? 'POST /sweeps' : `POST /processes/${state.process}/execution`;
    renderForm();
    replace(outcome);
  };
  processSelect.addEventListener('change', () => { render(); });
  const send = async () => {
    syncText();
    sendButton.disabled = true;
    const path = state.kind === 'sweep' ? '/sweeps' : `/processes/${state.process}/execution`;
    try {
      const answer = await post(path, text.value);
      if (answer.status === 201 && answer.location) {
        replace(outcome, h('p', {class: 'ok'}, 'Queued: ', h('a', {href: answer.location}, answer.location)));
        location.href = answer.location;
        return;
      }
      showErrors(form, outcome, answer.body || {title: `HTTP ${answer.status}`});
    } catch (error) {
      replace(outcome, errorBox(error));
    } finally {
      sendButton.disabled = false;
    }
  };

  replace(main, h('h1', {}, 'Submit'),
    h('section', {class: 'card'},
      h('div', {class: 'filters'},
        h('label', {}, 'Template ', templateSelect),
        h('label', {}, 'Process ', processSelect),
        h('a', {href: '/processes', onclick: (event) => {
          event.preventDefault();
          location.href = `/processes/${state.process}`;
        }}, 'input schema')),
      h('p', {class: 'muted'}, 'Edit the fields (an empty field is left out, so its default applies), or the JSON below. ',
        'Then ', target, '.'),
      outcome, form,
      h('details', {}, h('summary', {}, 'Edit as JSON'), text),
      h('p', {}, sendButton)));
  await render();
  if (pending) {
    showErrors(form, outcome, pending, `Job ${params.get('from')} was refused; fix the fields marked and submit again.`);
  }
}

/** The type recorded for a scalar field. */
function typeOf(value) {
  if (value === null) return 'null';
  return typeof value;
}

/** The unit label of a field: the unit, `–` for a dimensionless number, `#` for an integer. */
function unitLabel(unit) {
  if (!unit) return null;
  const text = {dimensionless: '–', integer: '#'}[unit] || unit;
  const title = {dimensionless: 'dimensionless', integer: 'a whole number'}[unit] || `in ${unit}`;
  return h('span', {class: 'unit', 'data-unit': unit, title}, text);
}

/** What the form shows of the field at `pointer`: its schema's unit and choices. A sweep's
 *  axis values take the unit of the input their axis points at. */
function infoAt(pointer, key, ctx) {
  if (!ctx.root) return fieldInfo(null);
  const axis = /^\/axes\/(\d+)\/(values|linspace|logspace|uniform|normal|lognormal)/.exec(pointer);
  if (axis && ctx.body.axes && ctx.body.axes[Number(axis[1])]) {
    const target = ctx.body.axes[Number(axis[1])].pointer;
    return fieldInfo(typeof target === 'string' ? schemaAt(ctx.root, ctx.body, `/inputs${target}`) : null);
  }
  if (key === 'type') {
    const parent = pointer.slice(0, pointer.lastIndexOf('/'));
    const tags = taggedVariants(schemaAt(ctx.root, ctx.body, parent)).map((v) => v.tag);
    if (tags.length > 1) return {unit: null, choices: tags, keywords: [], tagOf: parent};
  }
  return fieldInfo(schemaAt(ctx.root, ctx.body, pointer));
}

/** Form controls for a JSON value at `pointer`: fieldsets for objects and arrays of
 *  objects, a select for a choice among names, inputs for the rest, each with its unit. */
function fields(value, pointer, key, ctx) {
  if (value && typeof value === 'object' && !Array.isArray(value)) {
    const children = Object.entries(value).map(([k, v]) => fields(v, `${pointer}/${pointerToken(k)}`, k, ctx));
    if (key === null) return children;
    return h('fieldset', {'data-pointer': pointer}, h('legend', {}, key), children);
  }
  if (Array.isArray(value) && value.length && value.every((v) => v && typeof v === 'object')) {
    const items = value.map((v, k) => fields(v, `${pointer}/${k}`, `${key} ${k}`, ctx));
    const body = value.length > 12
      ? h('details', {}, h('summary', {}, `${value.length} items`), items)
      : items;
    return h('fieldset', {'data-pointer': pointer, class: 'list'}, h('legend', {}, `${key} (${value.length})`), body);
  }
  const info = infoAt(pointer, key, ctx);
  if (info.choices && (typeof value === 'string' || value === undefined)) {
    const choices = info.choices.includes(value) || value === '' || value === undefined ? info.choices : [value, ...info.choices];
    const select = h('select', {'data-pointer': pointer, 'data-type': 'string', 'data-choices': info.choices.length,
      onchange: info.tagOf ? (event) => ctx.onVariant(info.tagOf, event.target.value) : null},
    choices.map((choice) => h('option', {value: choice, selected: choice === value}, choice)));
    return h('label', {class: 'field'}, h('span', {class: 'name'}, key), select);
  }
  const isJson = Array.isArray(value) || (value !== null && typeof value === 'object');
  const list = info.keywords.length ? `keywords${pointer.replaceAll('/', '-')}` : null;
  const input = h('input', {
    type: 'text',
    'data-pointer': pointer,
    'data-type': isJson ? 'json' : typeOf(value),
    value: isJson ? JSON.stringify(value) : value === null ? 'null' : String(value),
    spellcheck: 'false',
    list,
    title: info.description || null,
  });
  return h('label', {class: 'field'}, h('span', {class: 'name'}, key),
    h('span', {class: 'control'}, input, unitLabel(info.unit)),
    list ? h('datalist', {id: list}, info.keywords.map((word) => h('option', {value: word}))) : null);
}

/** The value at a JSON pointer of `root` (undefined when absent). */
function getAt(root, pointer) {
  let node = root;
  for (const token of pointer.split('/').slice(1).map((t) => t.replaceAll('~1', '/').replaceAll('~0', '~'))) {
    if (node === null || typeof node !== 'object') return undefined;
    node = node[Array.isArray(node) ? Number(token) : token];
  }
  return node;
}

/** Sets `value` at a JSON pointer of `root` (existing containers only); `undefined` removes the member. */
function setAt(root, pointer, value) {
  const tokens = pointer.split('/').slice(1).map((t) => t.replaceAll('~1', '/').replaceAll('~0', '~'));
  let node = root;
  for (const token of tokens.slice(0, -1)) node = node[Array.isArray(node) ? Number(token) : token];
  const last = tokens[tokens.length - 1];
  if (value === undefined && !Array.isArray(node)) delete node[last];
  else node[Array.isArray(node) ? Number(last) : last] = value;
}

/** A copy of `body` with every input's value: numbers, booleans and null as such, other text as strings. */
function readForm(form, body) {
  const copy = structuredClone(body);
  for (const input of form.querySelectorAll('input[data-pointer], select[data-pointer]')) {
    const text = input.value.trim();
    let value;
    if (text === '') {
      value = undefined;
    } else if (input.dataset.type === 'json') {
      try {
        value = JSON.parse(text);
      } catch {
        value = text;
      }
    } else {
      try {
        const parsed = JSON.parse(text);
        value = parsed === null || ['number', 'boolean'].includes(typeof parsed) ? parsed : input.value;
      } catch {
        value = input.value;
      }
    }
    setAt(copy, input.dataset.pointer, value);
  }
  return copy;
}

/** The element an error pointer belongs to: the field itself, else its nearest enclosing group. */
function targetOf(form, pointer) {
  // A generated run of a sweep (`/runs/7/inputs/...`) points at the base input it came from.
  const candidates = [pointer, pointer.replace(/^\/runs\/\d+/, '')];
  for (const candidate of candidates) {
    let p = candidate;
    while (p) {
      const found = form.querySelector(`[data-pointer="${CSS.escape(p)}"]`);
      if (found) return found;
      p = p.slice(0, p.lastIndexOf('/'));
    }
  }
  return null;
}

/** Shows a problem document: a summary, and each `errors` item next to its field. */
function showErrors(form, outcome, problem, intro) {
  for (const old of form.querySelectorAll('.field-error')) old.remove();
  for (const old of form.querySelectorAll('.invalid')) old.classList.remove('invalid');
  const errors = Array.isArray(problem.errors) ? problem.errors : [];
  const unplaced = [];
  for (const error of errors) {
    const element = targetOf(form, error.pointer || '');
    const note = h('span', {class: 'field-error', role: 'alert', 'data-error-for': error.pointer},
      element && element.dataset.pointer !== error.pointer ? `${error.pointer}: ${error.detail}` : error.detail);
    if (!element) {
      unplaced.push(error);
    } else if (element.tagName === 'FIELDSET') {
      element.classList.add('invalid');
      const details = element.querySelector(':scope > details');
      if (details) details.open = true;
      element.querySelector('legend').after(note);
    } else {
      element.classList.add('invalid');
      element.after(note);
      let parent = element.closest('details');
      while (parent) {
        parent.open = true;
        parent = parent.parentElement.closest('details');
      }
    }
  }
  replace(outcome, h('div', {class: 'error', role: 'alert', 'data-problem': problem.type || ''},
    intro ? h('p', {}, intro) : null,
    h('strong', {}, problem.title || 'Refused'), ' ', problem.detail || '',
    errors.length ? h('ul', {}, errors.map((e) => h('li', {}, h('code', {}, e.pointer), ' ', e.detail,
      unplaced.includes(e) ? '' : ' (marked below)'))) : null));
  const first = form.querySelector('.invalid');
  if (first && first.tagName === 'INPUT') first.focus();
}
