// Interactive line plots, drawn by uPlot (vendored: vendor/README.md): drag across a plot
// to zoom in on that x range (double-click or "reset zoom" to zoom out), hover to read
// every series' value at that x in the legend, and save the plotted points of the shown
// range as CSV or the drawing as PNG. Axes are linear or logarithmic (x and y apart).
//
// Each figure carries data-* attributes for tests and scripts: `data-plot` (its id),
// `data-log-x`/`data-log-y`, `data-x-min`/`data-x-max` (the shown x range), and per
// series (`data-series` on its legend key) `data-points`, `data-min`, `data-max` of the
// values uPlot holds, and `data-value`, the value under the cursor; `data-cursor-x` on
// the legend's x key. Reference lines: `data-hline` (horizontal), `data-marker` (vertical).

import uPlot from './uPlot.esm.js';
import {fmt, h, saveBlob} from './util.js';

const HEIGHT = 300;
/** Width before the figure is laid out (the width of a card on a 1280 px window). */
const FIRST_WIDTH = 1180;
/** Draw the points themselves on series this short. */
const FEW_POINTS = 60;
const MARKER_COLOUR = '#8a6d00';

/** The colour of series class `k` (CSS variables --c0 … --c5), `alpha` < 1 for a lighter one. */
function colour(k, alpha = 1) {
  const value = getComputedStyle(document.documentElement).getPropertyValue(`--c${k % 6}`).trim() || '#1f5fa8';
  if (alpha >= 1 || !/^#[0-9a-f]{6}$/i.test(value)) return value;
  const [r, g, b] = [1, 3, 5].map((i) => parseInt(value.slice(i, i + 2), 16));
  return `rgba(${r},${g},${b},${alpha})`;
}

/** Finite values, and on a log axis positive ones; anything else is a gap (null). */
const usable = (v, log) => (Number.isFinite(v) && (!log || v > 0) ? v : null);

/**
 * The series on one x grid, as uPlot wants them: [x, y1, y2, ...], x increasing. Series
 * sharing an x array are kept together; different grids are merged (a series is a gap
 * where it has no sample, drawn across).
 */
function aligned(series, logX, logY) {
  const groups = [];
  for (const item of series) {
    let group = groups.find((g) => g.x === item.x);
    if (!group) groups.push(group = {x: item.x, members: []});
    group.members.push(item);
  }
  const tables = groups.map((group) => {
    const order = group.x.map((_, i) => i).filter((i) => usable(group.x[i], logX) !== null)
      .sort((a, b) => group.x[a] - group.x[b]);
    return [order.map((i) => group.x[i]),
      ...group.members.map((item) => order.map((i) => usable(item.y[i], logY)))];
  });
  const data = tables.length === 1 ? tables[0] : uPlot.join(tables);
  // uPlot.join puts the columns in the order of the groups: back to the order given.
  const columns = groups.flatMap((group) => group.members);
  return [data[0], ...series.map((item) => data[1 + columns.indexOf(item)])];
}

function extentOf(values) {
  let lo = Infinity;
  let hi = -Infinity;
  let count = 0;
  for (const v of values) {
    if (v === null || v === undefined) continue;
    count++;
    if (v < lo) lo = v;
    if (v > hi) hi = v;
  }
  return {count, lo, hi};
}

/** Ticks of a log axis: every decade (every other one, … past ten), or 1, 2, 5 × 10^k
 *  within two decades; uPlot's own put nine per decade, a grey band on many decades. */
function logSplits(u, axis, min, max) {
  const low = Math.log10(min);
  const high = Math.log10(max);
  const first = Math.ceil(low - 1e-9);
  const last = Math.floor(high + 1e-9);
  const splits = [];
  if (high - low < 2) {
    for (let e = Math.floor(low); e <= last; e++) {
      for (const m of [1, 2, 5]) {
        const v = m * 10 ** e;
        if (v >= min * (1 - 1e-9) && v <= max * (1 + 1e-9)) splits.push(v);
      }
    }
    return splits;
  }
  const every = Math.max(1, Math.ceil((last - first + 1) / 10));
  for (let e = first; e <= last; e += every) splits.push(10 ** e);
  return splits;
}

/** Tick labels in our number format. */
const tickValues = (u, splits) => splits.map((v) => (v === null || v === undefined ? '' : fmt(v, 3)));

/** An axis: its label, our ticks (log ones for a log scale), light grid. */
function axis(label, log, extra = {}) {
  return {label: label || '', values: tickValues, ...(log ? {splits: logSplits} : {}), stroke: '#66707c',
    grid: {stroke: '#e9edf1'}, ticks: {stroke: '#d8dde3'}, ...extra};
}

/** The rows of `data` whose x lies in [lo, hi], as CSV with `names` for a header. */
export function csvOf(names, data, lo = -Infinity, hi = Infinity) {
  const lines = [names.join(',')];
  for (let i = 0; i < data[0].length; i++) {
    const x = data[0][i];
    if (x < lo || x > hi) continue;
    lines.push(data.map((column) => (column[i] === null || column[i] === undefined ? '' : String(column[i]))).join(','));
  }
  return `${lines.join('\n')}\n`;
}

/**
 * A line plot. `series`: [{name, label, x: [...], y: [...], dashed, color, envelope}]
 * (`envelope`: drawn light, behind, for the peak-per-interval companion of a history);
 * `xName`: the x column's name in the CSV export (`time`, `frequency`); `logX`, `logY`:
 * logarithmic axes (values ≤ 0 are gaps; on y at most `logRange` decades below the top
 * are shown); `markers`: vertical lines [{x, label}]; `hLines`: horizontal lines
 * [{y, label}].
 */
export function linePlot({id, title, caption, series, xLabel, yLabel, xName = 'x', logX = false, logY = false,
  logRange = 10, height = HEIGHT, markers = [], hLines = []}) {
  const data = aligned(series, logX, logY);
  const extents = series.map((_, k) => extentOf(data[k + 1]));
  const shown = hLines.filter((line) => Number.isFinite(line.y) && (!logY || line.y > 0));
  const figure = h('figure', {class: 'plot', 'data-plot': id, 'data-log-x': String(logX), 'data-log-y': String(logY)});
  if (!data[0].length || extents.every((e) => e.count === 0)) {
    figure.append(h('figcaption', {}, h('span', {class: 'title'}, title), h('span', {class: 'muted'}, ' no data')));
    return figure;
  }
  const values = series.map(() => h('span', {class: 'value', 'data-value': ''}, ''));
  const xValue = h('span', {class: 'value'}, '');
  const xKey = h('span', {class: 'key x', 'data-cursor-x': ''}, `${xLabel || xName} `, xValue);
  const keys = series.map((item, k) => h('span', {class: 'key', 'data-series': item.name,
    'data-points': extents[k].count, 'data-min': extents[k].count ? extents[k].lo : '',
    'data-max': extents[k].count ? extents[k].hi : ''},
  h('span', {class: `swatch c${item.color ?? k}${item.dashed ? ' dashed' : ''}${item.envelope ? ' envelope' : ''}`}),
  item.label || item.name, ' ', values[k]));
  const lines = [
    ...shown.map((line) => h('span', {class: 'key reference', 'data-hline': line.y},
      h('span', {class: 'swatch reference'}), line.label || fmt(line.y))),
    ...markers.filter((m) => Number.isFinite(m.x)).map((m) => h('span', {class: 'key reference', 'data-marker': m.x},
      h('span', {class: 'swatch reference vertical'}), m.label || fmt(m.x))),
  ];
  const area = h('div', {class: 'plot-area'});
  const reset = h('button', {type: 'button', class: 'small', disabled: true, 'data-action': 'reset-zoom'}, 'reset zoom');
  const csvLink = h('a', {href: '#', class: 'export', 'data-export': 'csv', download: `${id}.csv`,
    title: 'the plotted points of the shown x range'}, 'CSV');
  const pngLink = h('a', {href: '#', class: 'export', 'data-export': 'png', download: `${id}.png`,
    title: 'the drawing as an image'}, 'PNG');
  figure.append(
    h('figcaption', {}, h('span', {class: 'title'}, title), caption || null,
      h('span', {class: 'tools'}, h('span', {class: 'muted'}, 'drag to zoom'), reset, csvLink, pngLink)),
    h('div', {class: 'legend'}, xKey, keys, lines),
    area);

  const full = [data[0][0], data[0][data[0].length - 1]];
  const yRange = (u, min, max) => {
    let lo = min;
    let hi = max;
    for (const line of shown) {
      lo = Math.min(lo, line.y);
      hi = Math.max(hi, line.y);
    }
    if (logY) {
      lo = Math.max(lo, hi / 10 ** logRange);
      return uPlot.rangeLog(lo, hi, 10, true);
    }
    return uPlot.rangeNum(lo, hi, 0.1, true);
  };
  const drawReferences = (u) => {
    if (!shown.length && !markers.length) return;
    const ctx = u.ctx;
    const ratio = uPlot.pxRatio;
    const {left, top, width, height: plotHeight} = u.bbox;
    ctx.save();
    ctx.beginPath();
    ctx.rect(left, top, width, plotHeight);
    ctx.clip();
    ctx.strokeStyle = MARKER_COLOUR;
    ctx.fillStyle = MARKER_COLOUR;
    ctx.lineWidth = ratio;
    ctx.setLineDash([3 * ratio, 3 * ratio]);
    ctx.font = `${11.5 * ratio}px system-ui, sans-serif`;
    for (const line of shown) {
      const y = Math.round(u.valToPos(line.y, 'y', true));
      ctx.beginPath();
      ctx.moveTo(left, y);
      ctx.lineTo(left + width, y);
      ctx.stroke();
      ctx.textAlign = 'right';
      // Above the line, or below it when the line runs along the top.
      const below = y - top < 16 * ratio;
      ctx.fillText(line.label || '', left + width - 4 * ratio, below ? y + 14 * ratio : y - 4 * ratio);
    }
    for (const marker of markers) {
      if (!Number.isFinite(marker.x)) continue;
      const x = Math.round(u.valToPos(marker.x, 'x', true));
      ctx.beginPath();
      ctx.moveTo(x, top);
      ctx.lineTo(x, top + plotHeight);
      ctx.stroke();
      ctx.textAlign = 'left';
      ctx.fillText(marker.label || '', x + 4 * ratio, top + 14 * ratio);
    }
    ctx.restore();
  };
  const showCursor = (u) => {
    const i = u.cursor.idx;
    const at = i === null || i === undefined ? null : u.data[0][i];
    xValue.textContent = at === null ? '' : `= ${fmt(at, 6)}`;
    xKey.setAttribute('data-cursor-x', at === null ? '' : String(at));
    series.forEach((_, k) => {
      const v = at === null ? null : u.data[k + 1][i];
      const has = v !== null && v !== undefined;
      values[k].textContent = has ? fmt(v, 5) : (at === null ? '' : '–');
      values[k].setAttribute('data-value', has ? String(v) : '');
    });
  };
  const showScale = (u, key) => {
    if (key !== 'x') return;
    const {min, max} = u.scales.x;
    figure.setAttribute('data-x-min', String(min));
    figure.setAttribute('data-x-max', String(max));
    reset.disabled = !(min > full[0] || max < full[1]);
  };
  const few = data[0].length <= FEW_POINTS;
  const plot = new uPlot({
    width: FIRST_WIDTH,
    height,
    legend: {show: false},
    cursor: {drag: {x: true, y: false, setScale: true}},
    scales: {
      x: {time: false, distr: logX ? 3 : 1, log: 10},
      y: {distr: logY ? 3 : 1, log: 10, range: yRange},
    },
    axes: [axis(xLabel || xName, logX), axis(yLabel, logY, {size: 70})],
    series: [
      {label: xName},
      ...series.map((item, k) => ({
        label: item.label || item.name,
        stroke: colour(item.color ?? k, item.envelope ? 0.45 : 1),
        width: item.envelope ? 1 : item.dashed ? 1.8 : 1.4,
        dash: item.dashed && !item.envelope ? [6, 4] : undefined,
        spanGaps: true,
        points: {show: few},
      })),
    ],
    hooks: {draw: [drawReferences], setCursor: [showCursor], setScale: [showScale], ready: [(u) => showScale(u, 'x')]},
  }, data, area);
  reset.addEventListener('click', () => plot.setScale('x', {min: full[0], max: full[1]}));
  csvLink.addEventListener('click', (event) => {
    event.preventDefault();
    const {min, max} = plot.scales.x;
    const text = csvOf([xName, ...series.map((item) => item.name)], plot.data, min, max);
    saveBlob(new Blob([text], {type: 'text/csv'}), `${id}.csv`);
  });
  pngLink.addEventListener('click', (event) => {
    event.preventDefault();
    plot.ctx.canvas.toBlob((blob) => { if (blob) saveBlob(blob, `${id}.png`); }, 'image/png');
  });
  // The plot takes the width of its figure, once laid out and whenever it changes.
  new ResizeObserver(() => {
    const width = Math.floor(area.clientWidth);
    if (width > 0 && width !== plot.width) plot.setSize({width, height});
  }).observe(area);
  return figure;
}
