// One job: status (live while it runs), inputs, results and plots. `cantilever-impact`
// gets its tip deflection and contact force, numerical against reference, and the power
// spectra of both with f_err; `bundle-dynamics` its peak contact forces by level and
// position and any contact's or pin's history; `hex-bundle-dynamics` a cross-section
// per level (hex.js); any other process its histories.
// Every job with a quality section shows its verdict as a badge (with the reasons) next
// to its numbers, and each force or displacement plot draws the history's peak-keeping
// companion (`<name>_peaks`) with the samples, so the plotted peak is the reported one.
// Plausibility warnings about the inputs (the status's, or a sweep run's results') are
// listed under the status, each with the input it points at. Every process with a
// displacement history gets its response spectra (spectra.js).

import {FINISHED, ApiProblem, api, badge, card, download, errorBox, fmt, fmtElapsed, fmtTime, h, keyValueTable,
  leaves, poll, progressCell, replace, withUnit} from './util.js';
import {barChart, heatMap} from './plot.js';
import {linePlot} from './lines.js';
import {hexBundle} from './hex.js';
import {responseSpectrumCard} from './spectra.js';
import {STATISTICS, contactImpacts, impactsCard, statisticPicker} from './impacts.js';
import {band, marginsCard} from './margins.js';

/** Points asked of a history for a plot (min/max thinning keeps every peak). */
const PLOT_POINTS = 2400;

export async function job(main, id) {
  const statusBox = h('div', {}, h('p', {class: 'muted'}, 'Loading…'));
  const inputsBox = h('div');
  const resultsBox = h('div', {id: 'results'});
  replace(main, h('h1', {}, 'Job ', h('span', {class: 'mono'}, id)), card('Status', statusBox),
    resultsBox, inputsBox);
  api(`/jobs/${id}/inputs`).then((body) => replace(inputsBox, inputsCard(id, body)))
    .catch((error) => replace(inputsBox, card('Inputs', errorBox(error))));
  let shown = false;
  poll(async () => {
    let status;
    try {
      status = await api(`/jobs/${id}`);
    } catch (error) {
      replace(statusBox, errorBox(error));
      return !(error instanceof ApiProblem && error.status === 404);
    }
    replace(statusBox, statusTable(id, status));
    if (FINISHED.has(status.status) && !shown) {
      shown = true;
      await showResults(resultsBox, id, status);
    }
    return !FINISHED.has(status.status);
  }, 1000);
}

function statusTable(id, status) {
  const running = !FINISHED.has(status.status);
  const dismiss = h('button', {type: 'button', onclick: async (event) => {
    event.target.disabled = true;
    await api(`/jobs/${id}`, {method: 'DELETE'}).catch(() => {});
  }}, 'Dismiss');
  return [
    keyValueTable([
      ['Process', status.processID],
      ['Status', [badge(status.status), status.message && !['queued', 'running', 'finished', 'dismissed'].includes(status.message)
        ? h('span', {class: 'message'}, ` ${status.message}`) : null]],
      ['Progress', progressCell(status)],
      ['Created', fmtTime(status.created)],
      ['Started', fmtTime(status.started)],
      ['Finished', fmtTime(status.finished)],
      ['Run time', fmtElapsed(status.started, status.finished) || '–'],
      ...(status.sweepID ? [['Sweep', h('a', {href: `/sweeps/${status.sweepID}`, class: 'mono'}, status.sweepID)]] : []),
    ], {'data-job-status': status.status}),
    warningsList(status.warnings),
    h('p', {class: 'actions'},
      h('a', {href: `/jobs/${id}?f=json`}, 'status as JSON'),
      h('a', {href: `/ui/submit?from=${id}`}, 'edit and resubmit'),
      status.status === 'successful'
        ? h('a', {href: `/jobs/${id}/report`, 'data-report-link': ''}, 'calculation note (printable)') : null,
      running ? dismiss : null),
  ];
}

/** Plausibility warnings (valid inputs that look like a mistake), each at its input; null without any. */
function warningsList(warnings) {
  if (!warnings || !warnings.length) return null;
  return h('ul', {class: 'warnings', 'data-warnings': warnings.length},
    warnings.map((w) => h('li', {'data-warning': w.code},
      h('span', {class: 'badge doubtful'}, 'warning'), ' ', h('code', {}, w.pointer), ' ', w.message)));
}

function inputsCard(id, body) {
  const rows = leaves(body.inputs).map(([pointer, value]) =>
    [h('code', {}, pointer.slice(1)), typeof value === 'string' ? value : fmt(value, 6)]);
  return card('Inputs',
    h('details', {open: rows.length <= 40},
      h('summary', {}, `${rows.length} values`), keyValueTable(rows, {'data-inputs': ''})),
    h('details', {}, h('summary', {}, 'as JSON'), h('pre', {}, JSON.stringify(body, null, 2))),
    h('p', {}, download(`/jobs/${id}/inputs`, 'inputs.json')));
}

async function showResults(box, id, status) {
  if (status.status === 'dismissed') {
    replace(box, card('Results', h('p', {class: 'muted'}, 'Dismissed: no results.')));
    return;
  }
  let results;
  try {
    results = await api(`/jobs/${id}/results`);
  } catch (error) {
    const errors = (error.problem && error.problem.errors) || [];
    replace(box, card('Results', errorBox(error),
      errors.length ? h('ul', {class: 'field-errors'}, errors.map((e) => h('li', {}, h('code', {}, e.pointer), ' ',
        e.detail))) : null,
      errors.length ? h('p', {}, h('a', {href: `/ui/submit?from=${id}`}, 'Fix the inputs and resubmit →')) : null));
    return;
  }
  const sections = h('div');
  const spectrumBox = h('div');
  const runWarnings = (status.warnings || []).length ? null : warningsList(results.warnings);
  replace(box, runWarnings ? card('Warnings', runWarnings) : null, qualityCard(results), sections, spectrumBox,
    downloadsCard(id, results));
  if (status.processID === 'cantilever-impact') {
    await cantilever(sections, id, results);
  } else if (status.processID === 'bundle-dynamics') {
    await bundle(sections, id, results);
  } else if (status.processID === 'hex-bundle-dynamics') {
    await hexBundle(sections, id, results);
  } else {
    await generic(sections, id, results);
  }
  replace(spectrumBox, await responseSpectrumCard(id, status.processID, results));
}

function downloadsCard(id, results) {
  const outputs = Object.entries(results.outputs || {});
  return card('Downloads', h('table', {class: 'list downloads'},
    h('tbody', {},
      h('tr', {}, h('th', {}, 'results'), h('td', {}, download(`/jobs/${id}/results`, 'results.json'))),
      outputs.map(([name, link]) => h('tr', {},
        h('th', {}, name),
        h('td', {}, download(`${link.href}?format=csv`, `${name}.csv`), ' ',
          download(`${link.href}?format=json`, `${name}.json`), ' ',
          // The per-impact table is no time series: it has no spectrum.
          name === 'impacts' ? null : download(`${link.href}/spectrum?format=csv`, `${name}-spectrum.csv`)))))),
  h('p', {class: 'muted'}, 'CSV histories at full resolution; spectra are one-sided power spectral densities; ' +
    '`impacts` is one row per impact.'));
}

/** What each verdict tells the user. */
const VERDICT_MEANING = {
  good: 'every discretisation error (step, modes, mesh) measured and within the tolerance',
  unchecked: 'within the tolerance by every measure taken, but the time step\'s error was not measured: not proven',
  doubtful: 'outside the tolerance by some measure: check before relying on these numbers',
  poor: 'do not use these numbers: some measure is far outside the tolerance',
};

/** The quality verdict as a badge, its reasons as a tooltip; null without a quality section. */
export function qualityBadge(results) {
  const quality = results.quality;
  if (!quality || !quality.verdict) return null;
  return h('span', {class: `badge ${quality.verdict}`, 'data-quality': quality.verdict,
    title: (quality.reasons || []).join('\n') || VERDICT_MEANING[quality.verdict] || ''}, `quality ${quality.verdict}`);
}

/** The quality section: verdict, reasons, and the measures behind them. */
function qualityCard(results) {
  const q = results.quality;
  if (!q) return null;
  const percent = (x) => (Number.isFinite(x) ? `${fmt(100 * x, 3)} %` : '–');
  const check = q.step_halving;
  const reasons = q.reasons || [];
  return card('Quality',
    h('p', {class: 'big'}, qualityBadge(results), h('span', {class: 'muted'}, VERDICT_MEANING[q.verdict] || '')),
    reasons.length ? h('ul', {class: `quality-reasons ${q.verdict}`, 'data-quality-reasons': reasons.length},
      reasons.map((reason) => h('li', {}, reason))) : null,
    keyValueTable([
      ['energy balance residual', `${percent(q.energy_residual)} (tolerance ${percent(q.tolerance)})`],
      ['time step / critical', fmt(q.time_step_over_critical, 3)],
      ['steps per contact period', `${fmt(q.steps_per_contact_period, 3)} (time step set by ${q.time_step_limited_by || '–'})`],
      [check && check.compared_with === 'double_step' ? 'step check (at 2Δt)' : 'step check (at Δt/2)', check
        ? `peak force ${percent(check.peak_force_change)}, peak displacement ${percent(check.peak_displacement_change)}, ` +
          `impacts ${percent(check.impact_count_change)} (cost ×${fmt(check.relative_cost, 3)})` +
          (check.why_half_step ? `; at Δt/2 because ${check.why_half_step}` : '')
        : 'not run (solver.check "none")'],
      ['modal basis', probeText(q.modal_truncation)],
      ['element mesh', probeText(q.mesh)],
    ], {'data-quality-measures': ''}));
}

/** An impact probe's estimate: the peak force error and the contact where it is largest. */
function probeText(probe) {
  if (!probe) return '–';
  const at = Number.isFinite(probe.height) ? ` (worst at the contact at ${fmt(probe.height, 4)} m)` : '';
  return `estimated peak force error ${fmt(100 * probe.estimated_peak_force_error, 3)} %${at}`;
}

/**
 * The peak-keeping companion of `output` (`<output>_peaks`: the extreme of every output
 * interval over all steps), or null when the results have none.
 */
export async function envelope(id, results, output, series) {
  const name = `${output}_peaks`;
  if (!(results.outputs || {})[name]) return null;
  return history(id, name, series);
}

/** The series of an envelope document, drawn light under the samples of the same colour. */
export function envelopeSeries(doc, styles = {}) {
  if (!doc) return [];
  return doc.series.map((item, k) => ({...(styles[item.name] || {color: k}), name: `${item.name}_peaks`,
    label: `${item.name}: peak per output interval`, x: doc.time, y: item.values, envelope: true, dashed: false}));
}

/** A horizontal line at a reported peak. */
export const reportedPeak = (value, unit) => (Number.isFinite(value) && value !== 0
  ? [{y: value, label: `reported ${fmt(value, 4)} ${unit}`}] : []);

/** A history (or some of its series) thinned for plotting: {time, series: [{name, values}]}. */
export function history(id, output, series) {
  const params = new URLSearchParams({max_points: PLOT_POINTS});
  if (series) params.set('series', series);
  return api(`/jobs/${id}/results/${output}?${params}`);
}

export function seriesOf(doc, styles = {}) {
  return doc.series.map((item, k) => ({name: item.name, x: doc.time, y: item.values, ...(styles[item.name] || {color: k})}));
}

const COMPARED = {numerical: {color: 0, label: 'numerical'}, reference: {color: 1, dashed: true, label: 'reference'}};

async function cantilever(box, id, results) {
  const n = results.numerical || {};
  const r = results.reference || {};
  const c = results.comparison || {};
  const row = (label, a, b, unit = '') => h('tr', {}, h('th', {}, label), h('td', {}, a), h('td', {}, b), h('td', {}, unit));
  const list = (values) => (values || []).slice(0, 4).map((v) => fmt(v, 4)).join(', ');
  const verdict = c.agrees ? 'agree' : 'differ';
  append(box, card('Numerical against reference',
    h('p', {class: 'big'}, 'f_err = ', h('strong', {'data-f-err': c.f_err}, fmt(c.f_err, 3)),
      h('span', {class: `badge ${c.agrees ? 'successful' : 'failed'}`}, `${verdict} (threshold ${fmt(c.threshold)})`),
      qualityBadge(results)),
    h('table', {class: 'list compare'},
      h('thead', {}, h('tr', {}, h('th'), h('th', {}, 'numerical'), h('th', {}, 'reference'), h('th'))),
      h('tbody', {},
        row('first impact', fmt(n.first_impact_time), fmt(r.first_impact_time), 's'),
        row('impacts', fmt(n.impacts), fmt(r.impacts)),
        row('max contact force', fmt(n.max_contact_force), fmt(r.max_contact_force), 'N'),
        row('min tip displacement', fmt(n.min_tip_displacement), fmt(r.min_tip_displacement), 'm'),
        row('free frequencies', list(n.frequencies_hz), list(r.free_frequencies_hz), 'Hz'),
        row('contact frequencies', '', list(r.contact_frequencies_hz), 'Hz'),
        row('time step', `${fmt(n.time_step)} (critical ${fmt(n.critical_time_step)})`, '', 's'),
        row('modes', fmt((n.frequencies_hz || []).length), fmt(r.modes)))),
    (r.notes || []).map((note) => h('p', {class: 'muted'}, note))));
  append(box, marginsCard({
    margins: {worst_utilisation: n.worst_utilisation, max_stress_utilisation: n.max_stress_utilisation,
      max_utilisation: n.utilisation === null || n.utilisation === undefined ? null
        : {contact: 0, utilisation: n.utilisation, force: n.max_contact_force, allowable_force: n.allowable_force}},
    contacts: [{utilisation: n.utilisation}], describe: () => 'the tip contact'}));
  append(box, impactsCard(results, n.impact_summary, () => 'the tip contact'),
    card('Impacts of the tip contact', contactImpacts(id, 0, {impact_statistics: n.impact_statistics})));
  const plots = h('div');
  const spectrumBox = h('div');
  append(box, card('Histories', plots), card('Power spectra', spectrumBox));
  const [tip, force, tipPeaks, forcePeaks] = await Promise.all([history(id, 'tip_displacement'),
    history(id, 'contact_force'), envelope(id, results, 'tip_displacement'), envelope(id, results, 'contact_force')]);
  append(plots,
    linePlot({id: 'tip_displacement', title: 'Tip displacement w(L, t)',
      series: [...envelopeSeries(tipPeaks, COMPARED), ...seriesOf(tip, COMPARED)],
      hLines: reportedPeak(n.min_tip_displacement, 'm'),
      xName: 'time', xLabel: 'time (s)', yLabel: 'w (m)', caption: thinned(tip, tipPeaks)}),
    linePlot({id: 'contact_force', title: 'Contact force',
      series: [...envelopeSeries(forcePeaks, COMPARED), ...seriesOf(force, COMPARED)],
      hLines: reportedPeak(n.max_contact_force, 'N'),
      xName: 'time', xLabel: 'time (s)', yLabel: 'F (N)', caption: thinned(force, forcePeaks)}));
  const highest = Math.max(...(r.free_frequencies_hz || []).slice(0, 2), ...(r.contact_frequencies_hz || []).slice(0, 2));
  const fMax = h('input', {type: 'number', min: 0, step: 'any', value: Number.isFinite(highest) ? fmt(1.25 * highest, 2) : 200,
    'aria-label': 'highest frequency (Hz)'});
  const drawn = h('div');
  const draw = async () => {
    const params = new URLSearchParams({f_max: fMax.value, max_points: PLOT_POINTS});
    try {
      const doc = await api(`/jobs/${id}/results/tip_displacement/spectrum?${params}`);
      const cmp = doc.comparison;
      replace(drawn, linePlot({id: 'tip_displacement-spectrum', title: 'Power spectral density of w(L, t)',
        series: doc.series.map((item) => ({name: item.name, x: doc.frequency, y: item.values, ...COMPARED[item.name]})),
        xName: 'frequency', xLabel: 'frequency (Hz)', yLabel: 'Γ (m²/Hz)', logY: true,
        markers: cmp ? [{x: cmp.frequency, label: `max |Γnum − Γref| at ${fmt(cmp.frequency, 4)} Hz`}] : [],
        caption: cmp ? h('span', {class: 'muted', 'data-spectrum-f-err': cmp.f_err},
          ` f_err = ${fmt(cmp.f_err, 3)} = max |Γnum − Γref| / max Γ, at ${fmt(cmp.frequency, 4)} Hz`) : null}));
    } catch (error) {
      replace(drawn, errorBox(error));
    }
  };
  append(spectrumBox, h('form', {class: 'inline', onsubmit: (event) => { event.preventDefault(); draw(); }},
    h('label', {}, 'up to ', fMax, ' Hz'), h('button', {type: 'submit'}, 'Redraw')), drawn);
  await draw();
}

export function thinned(doc, peaks = null) {
  return h('span', {class: 'muted', 'data-envelope': peaks ? 'true' : null},
    doc.thinned ? ` ${doc.points} of ${doc.total_points} samples (peaks kept)` : ` ${doc.points} samples`,
    peaks ? '; light: the extreme of every output interval over all steps' : '');
}

function append(parent, ...children) {
  for (const child of children.flat()) if (child) parent.append(child);
}

/** Body label of a contact side: `wall` or the pin number. */
const side = (body) => (body === 'wall' ? 'wall' : `pin ${body}`);
const sideKey = (body, wall) => (body === 'wall' ? wall : Number(body));

async function bundle(box, id, results) {
  const contacts = results.contacts || [];
  const pins = results.pins || [];
  const peak = results.max_contact_force || {};
  const energy = results.energy || {};
  append(box, card('Summary', keyValueTable([
    ['pins, contacts', `${pins.length}, ${contacts.length}`],
    ['peak contact force', [peak.force === undefined ? '–'
      : `${withUnit(peak.force, 'N')} at contact c${peak.contact}, t = ${withUnit(peak.time, 's')} `, qualityBadge(results)]],
    ['impacts', fmt(results.impacts)],
    ['time step', `${withUnit(results.time_step, 's')} (critical ${withUnit(results.critical_time_step, 's')})`],
    ['steps', fmt(results.steps)],
    ['energy balance residual', `${fmt(energy.relative_residual, 3)} (relative)`],
  ])));
  const describe = (k) => `c${k}: ${side(contacts[k].left)} – ${side(contacts[k].right)} at ${fmt(contacts[k].height)} m`;
  append(box, marginsCard({margins: results, contacts, pins, describe}));
  if (contacts.length) {
    // Columns: the places between two neighbours, left to right; rows: the levels, top up.
    const positions = [];
    for (const c of contacts) {
      const key = `${c.left}|${c.right}`;
      if (!positions.some((p) => p.key === key)) {
        positions.push({key, order: [sideKey(c.left, -1), sideKey(c.right, Infinity)]});
      }
    }
    positions.sort((a, b) => a.order[0] - b.order[0] || a.order[1] - b.order[1]);
    const heights = [...new Set(contacts.map((c) => c.height))].sort((a, b) => a - b);
    let statistic = 'max_force';
    let selected = contacts.reduce((best, c, k) => (c.max_force > contacts[best].max_force ? k : best), 0);
    const gridBox = h('div');
    // With allowables (docs/margins.md) the grid may show each contact's utilisation.
    const extra = contacts.some((c) => c.utilisation != null)
      ? {utilisation: {label: 'utilisation (peak / allowable)', unit: '', of: (c) => c.utilisation}} : {};
    const measures = {...STATISTICS, ...extra};
    const statistics = statisticPicker((key) => { statistic = key; drawGrid(); }, extra);
    const picker = h('select', {'aria-label': 'contact', 'data-picker': 'contact',
      onchange: (event) => select(Number(event.target.value))},
    contacts.map((c, k) => h('option', {value: k},
      `c${k}: ${side(c.left)} – ${side(c.right)} at ${fmt(c.height)} m (max ${fmt(c.max_force, 3)} N)`)));
    const detail = h('div');
    const plotBox = h('div');
    const drawGrid = () => {
      const m = measures[statistic];
      const value = (c) => m.of(c) ?? 0;
      const top = Math.max(...contacts.map(value), 0);
      replace(gridBox, heatMap({id: 'max-force-grid', title: `${m.label[0].toUpperCase()}${m.label.slice(1)} by level and position`,
        caption: h('span', {class: 'muted'}, ' click a cell to see its history and impacts'),
        xValues: positions.map((p) => p.key.replace('|', '–')), yValues: heights.map((z) => `${fmt(z, 3)} m`),
        xLabel: 'between (left – right)', yLabel: 'height', domain: [0, top || 1], colorLabel: m.unit,
        cellHeight: 36,
        cells: contacts.map((c, k) => ({
          i: positions.findIndex((p) => p.key === `${c.left}|${c.right}`), j: heights.indexOf(c.height),
          value: value(c), text: fmt(value(c), 2),
          title: `c${k}: ${side(c.left)} – ${side(c.right)} at ${fmt(c.height)} m: ${m.label} ${fmt(value(c))} ${m.unit}` +
            `; max ${fmt(c.max_force)} N at ${fmt(c.max_force_time)} s, ${c.impacts} impacts`,
          attrs: {'data-contact': k, class: k === selected ? 'selected' : null}, onclick: () => select(k),
        }))}));
    };
    const impactsBox = h('div');
    const select = async (k) => {
      selected = k;
      picker.value = String(k);
      drawGrid();
      const c = contacts[k];
      replace(detail, keyValueTable([
        ['between', `${side(c.left)} and ${side(c.right)}`], ['height', withUnit(c.height, 'm')],
        ['gap', withUnit(c.gap, 'm')], ['max force', `${withUnit(c.max_force, 'N')} at ${withUnit(c.max_force_time, 's')}`],
        ['impacts', fmt(c.impacts)], ['time in contact', withUnit(c.contact_time, 's')], ['impulse', withUnit(c.impulse, 'N·s')],
      ], {class: 'kv wide'}));
      replace(impactsBox, contactImpacts(id, k, c));
      try {
        const [doc, peaks] = await Promise.all([history(id, 'contact_forces', `c${k}`),
          envelope(id, results, 'contact_forces', `c${k}`)]);
        replace(plotBox, linePlot({id: 'contact_forces', title: `Contact force c${k}`,
          series: [...envelopeSeries(peaks), ...seriesOf(doc)], hLines: reportedPeak(c.max_force, 'N'),
          xName: 'time', xLabel: 'time (s)', yLabel: 'F (N)', caption: thinned(doc, peaks)}));
      } catch (error) {
        replace(plotBox, errorBox(error));
      }
    };
    append(box, card('Contact forces', h('p', {class: 'inline'}, h('label', {}, 'Show ', statistics)), gridBox,
      h('p', {class: 'inline'}, h('label', {}, 'Contact ', picker)), detail, plotBox, impactsBox),
    impactsCard(results, results.impact_summary, describe));
    await select(selected);
  }
  if (pins.length) {
    const pinBox = h('div');
    const barBox = h('div');
    const drawPin = async (p) => {
      // Coloured by the pin's utilisation when the run has allowables (margins.js).
      const bands = pins.some((x) => band(x.utilisation)) ? pins.map((x) => band(x.utilisation)) : null;
      replace(barBox, barChart({id: 'pin-deflection', title: 'Largest |deflection| per pin', labels: pins.map((x) => `${x.pin}`),
        values: pins.map((x) => x.max_abs_deflection), yLabel: 'max |w| (m)', xLabel: 'pin', selected: p,
        onselect: drawPin, bands,
        caption: bands ? h('span', {class: 'muted'}, ' coloured by utilisation: green < 0.8 ≤ amber < 1 ≤ red') : null}));
      try {
        const names = await seriesNames(id, 'displacements');
        const name = names.find((n) => n === `p${p}`) || names.find((n) => n.startsWith(`p${p}@`)) || names[0];
        const [doc, peaks] = await Promise.all([history(id, 'displacements', name),
          envelope(id, results, 'displacements', name)]);
        replace(pinBox, linePlot({id: 'displacements', title: `Deflection of pin ${p} (${name})`,
          series: [...envelopeSeries(peaks), ...seriesOf(doc)],
          xName: 'time', xLabel: 'time (s)', yLabel: 'w (m)', caption: thinned(doc, peaks)}));
      } catch (error) {
        replace(pinBox, errorBox(error));
      }
    };
    append(box, card('Pins', barBox, pinBox));
    await drawPin(pins.reduce((best, x, p) => (x.max_abs_deflection > pins[best].max_abs_deflection ? p : best), 0));
  }
}

/** The series names of a history (from a one-row window). */
async function seriesNames(id, output) {
  const doc = await api(`/jobs/${id}/results/${output}?t_end=0`);
  return doc.series.map((s) => s.name);
}

async function generic(box, id, results) {
  const scalars = leaves(Object.fromEntries(Object.entries(results).filter(([k]) => k !== 'outputs')), '', 4)
    .filter(([, v]) => typeof v !== 'object' || v === null);
  append(box, card('Results', keyValueTable(scalars.map(([p, v]) => [h('code', {}, p.slice(1)), fmt(v)]))));
  for (const name of Object.keys(results.outputs || {})) {
    if (name === 'impacts') continue;
    const names = await seriesNames(id, name);
    const doc = await history(id, name, names.slice(0, 6).join(','));
    append(box, card(name, linePlot({id: name, title: name, series: seriesOf(doc), xName: 'time', xLabel: 'time (s)', yLabel: name,
      caption: names.length > 6 ? h('span', {class: 'muted'}, ` first 6 of ${names.length} series`) : thinned(doc)})));
  }
}
