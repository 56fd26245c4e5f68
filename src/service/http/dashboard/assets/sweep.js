// One sweep: status and progress (live), definition, the calibration map of f_err over
// two axes with its 0.2 contour, histograms of Monte Carlo metrics with the q95 and the
// 95 %/95 % Wilks bound against the number of runs, the quality verdicts of the runs
// (how many poor, per axis value), and the results table.

import {FINISHED, api, badge, card, download, errorBox, fmt, fmtColumn, fmtTime, h, keyValueTable, poll, progressBar,
  replace, shortId, sweepBadge} from './util.js';
import {heatMap, histogram} from './plot.js';
import {linePlot} from './lines.js';

/** Rows of the results table shown on the page (the CSV has them all). */
const TABLE_ROWS = 500;

export async function sweep(main, id) {
  const statusBox = h('div', {}, h('p', {class: 'muted'}, 'Loading…'));
  const definitionBox = h('div');
  const resultsBox = h('div', {id: 'results'});
  replace(main, h('h1', {}, 'Sweep ', h('span', {class: 'mono'}, id)), card('Status', statusBox), resultsBox,
    definitionBox);
  let ended = -1;
  let defined = false;
  poll(async () => {
    let status;
    try {
      status = await api(`/sweeps/${id}`);
    } catch (error) {
      replace(statusBox, errorBox(error));
      return error.status !== 404;
    }
    replace(statusBox, statusTable(id, status));
    if (!defined) {
      defined = true;
      replace(definitionBox, definitionCard(status.definition));
    }
    const counts = status.counts;
    const now = counts.successful + counts.failed + counts.dismissed;
    if (now !== ended) {
      ended = now;
      try {
        showResults(resultsBox, status, await api(`/sweeps/${id}/results`));
      } catch (error) {
        replace(resultsBox, card('Results', errorBox(error)));
      }
    }
    return !FINISHED.has(status.status);
  }, 1000);
}

function statusTable(id, status) {
  const c = status.counts;
  const running = !FINISHED.has(status.status);
  return [
    keyValueTable([
      ['Process', status.processID],
      ['Status', sweepBadge(status)],
      ['Progress', running ? progressBar(status.progress, status.status) : `${status.progress} %`],
      ['Runs', h('span', {'data-runs': status.runs}, `${status.runs}: ${c.successful} successful, ${c.failed} failed, ` +
        `${c.running} running, ${c.accepted} queued, ${c.dismissed} dismissed`)],
      ['Design', `${status.design}, policy ${status.policy}`],
      ['Created', fmtTime(status.created)],
      ['Finished', fmtTime(status.finished)],
    ], {'data-sweep-status': status.status}),
    h('p', {class: 'actions'},
      h('a', {href: `/sweeps/${id}?f=json`}, 'status as JSON'),
      download(`/sweeps/${id}/results?format=csv`, 'results.csv'),
      download(`/sweeps/${id}/results`, 'results.json'),
      h('a', {href: `/jobs?sweepID=${id}&limit=100`}, 'its runs'),
      h('a', {href: `/ui/submit?sweep=${id}`}, 'edit and resubmit'),
      running ? h('button', {type: 'button', onclick: async (event) => {
        event.target.disabled = true;
        await api(`/sweeps/${id}`, {method: 'DELETE'}).catch(() => {});
      }}, 'Dismiss') : null),
  ];
}

function axisText(axis) {
  for (const kind of ['values', 'linspace', 'logspace', 'uniform']) {
    if (axis[kind] !== undefined) return `${kind} ${JSON.stringify(axis[kind])}`;
  }
  for (const kind of ['normal', 'lognormal']) {
    if (axis[kind] !== undefined) return `${kind} mean ${fmt(axis[kind].mean)}, std ${fmt(axis[kind].std)}`;
  }
  return JSON.stringify(axis);
}

function definitionCard(definition) {
  if (!definition) return null;
  return card('Definition',
    keyValueTable([
      ...(definition.axes || []).map((axis) => [h('code', {}, axis.pointer), axisText(axis)]),
      ['samples, seed', `${definition.samples ?? '–'}, ${definition.seed ?? '–'}`],
      ['invalid runs', definition.invalid_runs || '–'],
    ]),
    h('details', {}, h('summary', {}, 'base inputs as JSON'), h('pre', {}, JSON.stringify(definition.inputs, null, 2))));
}

function showResults(box, status, doc) {
  const aggregates = doc.aggregates || {};
  const axes = ((status.definition && status.definition.axes) || []).map((a) => a.pointer);
  const jobOf = new Map(doc.rows.map((row) => [row.run, row.job]));
  replace(box,
    aggregates.quality ? qualityCard(aggregates.quality) : null,
    aggregates.calibration ? calibrationCard(aggregates.calibration, axes, jobOf) : null,
    aggregates.statistics ? monteCarloCard(aggregates.statistics, doc, status.definition) : null,
    tableCard(doc));
}

/** Verdict counts of the successful runs: in total, then per value of each list axis. */
function qualityCard(quality) {
  const counts = (c) => [
    h('td', {}, fmt(c.runs)),
    h('td', {}, c.good ? h('span', {class: 'badge good'}, `${c.good} good`) : '0'),
    h('td', {}, c.unchecked ? h('span', {class: 'badge unchecked'}, `${c.unchecked} unchecked`) : '0'),
    h('td', {}, c.doubtful ? h('span', {class: 'badge doubtful'}, `${c.doubtful} doubtful`) : '0'),
    h('td', {'data-poor': c.poor}, c.poor ? h('span', {class: 'badge poor'}, `${c.poor} poor`) : '0'),
  ];
  const head = h('thead', {}, h('tr', {}, ['axis', 'value', 'runs', 'good', 'unchecked', 'doubtful', 'poor'].map((t) => h('th', {}, t))));
  const rows = [h('tr', {'data-quality-total': ''}, h('th', {}, 'all runs'), h('td'), counts(quality))];
  for (const axis of quality.by_axis || []) {
    for (const entry of axis.values) {
      rows.push(h('tr', {}, h('th', {}, h('code', {}, axis.axis)),
        h('td', {}, typeof entry.value === 'number' ? fmtColumn(entry.value, axis.axis, 6) : JSON.stringify(entry.value)), counts(entry)));
    }
  }
  return card('Quality of the runs',
    h('p', {class: 'muted'}, 'verdicts of the successful runs (quality.verdict); the reasons are on each run\'s page'),
    h('table', {class: 'list', 'data-quality-counts': quality.poor}, head, h('tbody', {}, rows)));
}

function sortedValues(values) {
  const unique = [];
  for (const v of values) if (!unique.some((u) => JSON.stringify(u) === JSON.stringify(v))) unique.push(v);
  return unique.every((v) => typeof v === 'number') ? unique.sort((a, b) => a - b) : unique;
}

const same = (a, b) => JSON.stringify(a) === JSON.stringify(b);

function calibrationCard(calibration, axes, jobOf) {
  const cells = calibration.cells || [];
  const threshold = calibration.threshold ?? 0.2;
  const values = Object.fromEntries(axes.map((p) => [p, sortedValues(cells.map((c) => c.parameters[p]))]));
  const mapBox = h('div');
  const controls = h('div', {class: 'filters'});
  const state = {
    x: axes.includes('/solver/time_step') ? '/solver/time_step' : axes[axes.length - 1],
    fixed: Object.fromEntries(axes.map((p) => [p, values[p][0]])),
  };
  state.y = axes.find((p) => p !== state.x) || null;
  const positive = cells.map((c) => c.f_err).filter((v) => v > 0);
  const lo = Math.min(threshold / 10, positive.length ? Math.min(...positive) : 1e-4);
  const draw = () => {
    const others = axes.filter((p) => p !== state.x && p !== state.y);
    replace(controls,
      axes.length > 1 ? [
        h('label', {}, 'x ', axisSelect(axes, state.x, (p) => { if (p === state.y) state.y = state.x; state.x = p; draw(); })),
        h('label', {}, 'y ', axisSelect(axes, state.y, (p) => { if (p === state.x) state.x = state.y; state.y = p; draw(); })),
      ] : null,
      others.map((p) => h('label', {}, `${p} = `, h('select', {onchange: (event) => {
        state.fixed[p] = values[p][Number(event.target.value)];
        draw();
      }}, values[p].map((v, k) => h('option', {value: k, selected: same(v, state.fixed[p])}, fmt(v)))))));
    const shown = cells.filter((c) => others.every((p) => same(c.parameters[p], state.fixed[p])));
    const label = (c) => axes.map((p) => `${p} = ${fmtColumn(c.parameters[p], p)}`).join(', ');
    const title = 'f_err over the grid';
    if (!state.y) {
      replace(mapBox, linePlot({id: 'calibration', title, xName: state.x, xLabel: state.x, yLabel: 'f_err', logY: true,
        series: [{name: 'f_err', x: shown.map((c) => c.parameters[state.x]), y: shown.map((c) => c.f_err)}],
        hLines: [{y: threshold, label: `f_err = ${fmt(threshold)}`}]}));
      return;
    }
    const xs = values[state.x];
    const ys = values[state.y];
    replace(mapBox, heatMap({id: 'calibration', title,
      caption: h('span', {class: 'muted'}, ` valid below the line f_err = ${fmt(threshold)}; hatched: run failed`),
      xValues: xs.map((v) => fmt(v, 3)), yValues: ys.map((v) => fmt(v, 3)), xLabel: state.x, yLabel: state.y,
      domain: [lo, 1], log: true, colorLabel: 'f_err', contour: {level: threshold, missing: 1},
      cells: shown.map((c) => {
        const failed = c.f_err === null || c.f_err === undefined;
        return {
          i: xs.findIndex((v) => same(v, c.parameters[state.x])), j: ys.findIndex((v) => same(v, c.parameters[state.y])),
          value: failed ? null : c.f_err, text: failed ? '×' : fmt(c.f_err, 2),
          title: `${label(c)}: ${failed ? 'run failed' : `f_err = ${fmt(c.f_err, 3)} (${c.valid ? 'valid' : 'not valid'})`}`,
          href: jobOf.has(c.run) ? `/jobs/${jobOf.get(c.run)}` : null,
          attrs: {'data-run': c.run, 'data-valid': c.valid},
        };
      })}));
  };
  draw();
  const cheapest = (calibration.cheapest || []).map((entry) => h('div', {},
    h('h3', {}, `${entry.rule} of ${entry.axis}`),
    h('table', {class: 'list', 'data-cheapest': entry.axis},
      h('thead', {}, h('tr', {}, h('th', {}, 'given'), h('th', {}, entry.axis), h('th', {}, 'run'))),
      h('tbody', {}, entry.choices.map((choice) => h('tr', {},
        h('td', {}, Object.entries(choice.given).map(([p, v]) => `${p} = ${fmt(v)}`).join(', ')),
        h('td', {}, choice.value === null ? 'none valid' : fmt(choice.value)),
        h('td', {}, jobOf.has(choice.run) ? h('a', {href: `/jobs/${jobOf.get(choice.run)}`}, `run ${choice.run}`) : '')))))));
  return card('Calibration map', controls, mapBox, cheapest);
}

function axisSelect(axes, current, onchange) {
  return h('select', {onchange: (event) => onchange(event.target.value)},
    axes.map((p) => h('option', {value: p, selected: p === current}, p)));
}

function monteCarloCard(groups, doc, definition) {
  if (!groups.length) return card('Statistics', h('p', {class: 'muted'}, 'No successful run yet.'));
  const metrics = Object.keys(groups[0].metrics);
  const preferred = ['max_contact_force.force', 'comparison.f_err', 'impacts'];
  const state = {metric: preferred.find((m) => metrics.includes(m)) || metrics[0], cell: 0};
  const listAxes = Object.keys(groups[0].cell || {});
  const plotBox = h('div');
  const convergenceBox = h('div');
  const tableBox = h('div');
  const cellLabel = (g) => Object.entries(g.cell).map(([p, v]) => `${p} = ${fmtColumn(v, p)}`).join(', ') || 'all runs';
  const draw = () => {
    const group = groups[state.cell];
    const stats = group.metrics[state.metric] || {};
    const rows = doc.rows.filter((row) => row.status === 'successful' && listAxes.every((p) => same(row[p], group.cell[p])));
    replace(plotBox, histogram({id: 'histogram', title: `${state.metric} over ${group.runs} runs (${cellLabel(group)})`,
      values: rows.map((row) => row[state.metric]).filter((v) => typeof v === 'number'), xLabel: state.metric,
      caption: h('span', {class: 'muted'}, ` mean ${fmt(stats.mean)}, std ${fmt(stats.std)}, min ${fmt(stats.min)}, ` +
        `q05 ${fmt(stats.q05)}, median ${fmt(stats.q50)}, q95 ${fmt(stats.q95)}, max ${fmt(stats.max)}` +
        (stats.bound_95_95 == null ? ' (a 95 %/95 % bound needs 59 runs)' : `, 95 %/95 % bound ${fmt(stats.bound_95_95)}`)),
      markers: [{x: stats.q05, label: 'q05'}, {x: stats.q50, label: 'median'}, {x: stats.q95, label: 'q95'},
        {x: stats.mean, label: 'mean'}]}));
    showConvergence(convergenceBox, doc.sweepID, state.metric, group.cell, listAxes);
    replace(tableBox, h('details', {}, h('summary', {}, `statistics of every column (${cellLabel(group)})`),
      h('div', {class: 'scroll'}, h('table', {class: 'list', 'data-statistics': ''},
        h('thead', {}, h('tr', {}, ['column', 'count', 'mean', 'std', 'min', 'q05', 'q50', 'q95', 'max', 'bound 95/95'].map((c) => h('th', {}, c)))),
        h('tbody', {}, Object.entries(group.metrics).map(([name, s]) => h('tr', {class: name === state.metric ? 'selected' : null},
          h('td', {}, h('a', {href: '#', onclick: (event) => { event.preventDefault(); state.metric = name; draw(); }}, name)),
          [s.count, s.mean, s.std, s.min, s.q05, s.q50, s.q95, s.max].map((v) => h('td', {}, fmt(v)))
            .concat([h('td', {title: s.bound_95_95 == null ? 'Wilks: needs 59 runs' : `Wilks: value ${s.bound_95_95_rank} from the top`},
              s.bound_95_95 == null ? '—' : fmt(s.bound_95_95))]))))))));
  };
  const controls = h('div', {class: 'filters'},
    h('label', {}, 'metric ', h('select', {onchange: (event) => { state.metric = event.target.value; draw(); }},
      metrics.map((m) => h('option', {value: m, selected: m === state.metric}, m)))),
    groups.length > 1 ? h('label', {}, 'cell ', h('select', {onchange: (event) => { state.cell = Number(event.target.value); draw(); }},
      groups.map((g, k) => h('option', {value: k}, cellLabel(g))))) : null);
  draw();
  const random = ((definition && definition.axes) || []).filter((a) => a.values === undefined && a.linspace === undefined &&
    a.logspace === undefined).map((a) => a.pointer);
  return card('Monte Carlo statistics', random.length ? h('p', {class: 'muted'}, `random: ${random.join(', ')}`) : null,
    controls, plotBox, convergenceBox, tableBox);
}

/** The latest convergence plot asked for: an older answer arriving late is dropped. */
let convergenceAsked = 0;

/**
 * The empirical 95 % quantile and the 95 %/95 % Wilks bound of `figure` over the first n
 * runs of the cell, against n in the order the runs were drawn: has the campaign
 * converged? (`/sweeps/{id}/statistics/convergence`, also as CSV.)
 */
async function showConvergence(box, id, figure, cell, listAxes) {
  const asked = ++convergenceAsked;
  const path = `/sweeps/${id}/statistics/convergence?figure=${encodeURIComponent(figure)}`;
  let track;
  try {
    track = await api(path);
  } catch (error) {
    if (asked === convergenceAsked) replace(box, errorBox(error));
    return;
  }
  if (asked !== convergenceAsked) return;
  const rows = track.rows.filter((row) => listAxes.every((p) => same(row[p], cell[p])));
  const runs = rows.map((row) => row.runs);
  const first = rows.find((row) => row.bound !== null);
  replace(box, linePlot({id: 'convergence', title: `${figure} against the number of runs`, xName: 'runs', xLabel: 'runs',
    yLabel: figure,
    caption: h('span', {class: 'muted'}, first ? ` the bound from run ${first.runs} (${track.runs_needed} needed)`
      : ` a 95 %/95 % bound needs ${track.runs_needed} runs`),
    series: [
      {name: 'value', label: 'each run', x: runs, y: rows.map((row) => row.value), envelope: true},
      {name: 'quantile', label: 'q95 of the runs so far', x: runs, y: rows.map((row) => row.quantile)},
      {name: 'bound', label: 'Wilks 95 %/95 % bound', x: runs, y: rows.map((row) => row.bound), dashed: true},
    ]}),
  h('p', {class: 'actions'}, download(`${path}&format=csv`, 'convergence.csv')));
}

function tableCard(doc) {
  const columns = doc.columns;
  const rows = doc.rows.slice(0, TABLE_ROWS);
  const cell = (row, column) => {
    const value = row[column];
    if (column === 'job') return h('a', {href: `/jobs/${value}`, class: 'mono'}, shortId(value));
    if (column === 'status') return badge(value);
    return value === undefined ? '' : fmtColumn(value, column);
  };
  return card(`Results (${doc.rows.length} of ${doc.runs} runs ended)`,
    h('div', {class: 'scroll'}, h('table', {class: 'list results', 'data-results': doc.rows.length},
      h('thead', {}, h('tr', {}, columns.map((c) => h('th', {}, c)))),
      h('tbody', {}, rows.map((row) => h('tr', {'data-run': row.run}, columns.map((c) => h('td', {}, cell(row, c)))))))),
    doc.rows.length > TABLE_ROWS ? h('p', {class: 'muted'}, `first ${TABLE_ROWS} rows; the CSV has them all`) : null);
}
