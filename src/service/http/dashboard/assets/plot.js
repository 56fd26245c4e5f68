// SVG figures on categories and bins: heat maps with a contour line, histograms and bar
// charts (line plots, interactive, are lines.js's). Each figure carries data-* attributes
// (the cells, the bars and their values) so that tests can check what is on the page.

import {h, fmt} from './util.js';

const SVG = 'http://www.w3.org/2000/svg';
const WIDTH = 960;

/** An SVG element. */
function s(tag, attrs = {}, ...children) {
  const element = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attrs)) {
    if (value !== null && value !== undefined && value !== false) element.setAttribute(key, String(value));
  }
  for (const child of children.flat(Infinity)) {
    if (child === null || child === undefined || child === false) continue;
    element.append(child instanceof Node ? child : document.createTextNode(String(child)));
  }
  return element;
}

const round = (v) => Math.round(v * 10) / 10;

/** Ticks at 1, 2, 5 × 10^k covering [lo, hi], about `count` of them. */
export function niceTicks(lo, hi, count = 6) {
  if (!(hi > lo)) return [lo];
  const raw = (hi - lo) / count;
  const power = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map((m) => m * power).find((candidate) => candidate >= raw);
  const ticks = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) {
    ticks.push(Math.abs(v) < step * 1e-9 ? 0 : Number(v.toPrecision(12)));
  }
  return ticks;
}

/** Decades (as exponents) inside [lo, hi] (exponents), thinned to at most 8. */
function decadeTicks(lo, hi) {
  const first = Math.ceil(lo - 1e-9);
  const last = Math.floor(hi + 1e-9);
  const every = Math.max(1, Math.ceil((last - first + 1) / 8));
  const ticks = [];
  for (let e = first; e <= last; e += every) ticks.push(e);
  return ticks;
}

function extent(values) {
  let lo = Infinity;
  let hi = -Infinity;
  for (const v of values) {
    if (Number.isFinite(v)) {
      if (v < lo) lo = v;
      if (v > hi) hi = v;
    }
  }
  return [lo, hi];
}

/** Viridis, from 0 (dark purple) to 1 (yellow). */
const VIRIDIS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];

export function viridis(t) {
  const x = Math.max(0, Math.min(1, Number.isFinite(t) ? t : 0)) * (VIRIDIS.length - 1);
  const i = Math.min(VIRIDIS.length - 2, Math.floor(x));
  const f = x - i;
  const c = VIRIDIS[i].map((a, k) => Math.round(a + (VIRIDIS[i + 1][k] - a) * f));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}

function figure(id, title, caption, svg, extra = {}) {
  return h('figure', {class: 'plot', 'data-plot': id, ...extra},
    h('figcaption', {}, h('span', {class: 'title'}, title), caption), svg);
}

function axisLabels(width, height, margin, xLabel, yLabel) {
  return [
    s('text', {class: 'axis-label', x: margin.left + (width - margin.left - margin.right) / 2, y: height - 6,
      'text-anchor': 'middle'}, xLabel || ''),
    s('text', {class: 'axis-label', x: 14, y: margin.top + (height - margin.top - margin.bottom) / 2,
      'text-anchor': 'middle',
      transform: `rotate(-90 14 ${margin.top + (height - margin.top - margin.bottom) / 2})`}, yLabel || ''),
  ];
}

/**
 * Marching squares on a grid of values (rows bottom to top): the segments of the line
 * where the field, linear between cell centres, crosses `level`. `F[j][i]` is the value
 * of column i, row j; returns segments [[x, y], [x, y]] in (column, row) index units.
 */
export function contourSegments(F, level) {
  const segments = [];
  for (let j = 0; j + 1 < F.length; j++) {
    for (let i = 0; i + 1 < F[j].length; i++) {
      // Corners counter-clockwise from the lower left: (i, j), (i+1, j), (i+1, j+1), (i, j+1).
      const corners = [[i, j], [i + 1, j], [i + 1, j + 1], [i, j + 1]];
      const values = corners.map(([a, b]) => F[b][a]);
      if (values.some((v) => !Number.isFinite(v))) continue;
      const above = values.map((v) => v >= level);
      const crossing = [];
      for (let e = 0; e < 4; e++) {
        const n = (e + 1) % 4;
        if (above[e] !== above[n]) {
          const t = (level - values[e]) / (values[n] - values[e]);
          crossing.push({edge: e, point: [corners[e][0] + t * (corners[n][0] - corners[e][0]),
            corners[e][1] + t * (corners[n][1] - corners[e][1])]});
        }
      }
      if (crossing.length === 2) {
        segments.push([crossing[0].point, crossing[1].point]);
      } else if (crossing.length === 4) {
        // A saddle: the centre value decides which corners the line cuts off.
        const centre = values.reduce((a, b) => a + b, 0) / 4;
        const [e0, e1, e2, e3] = crossing.map((c) => c.point);
        if ((centre >= level) === above[0]) {
          segments.push([e0, e1], [e2, e3]);
        } else {
          segments.push([e3, e0], [e1, e2]);
        }
      }
    }
  }
  return segments;
}

/**
 * A heat map of cells on a categorical grid: `xValues`, `yValues` label the columns and
 * rows (row 0 at the bottom); `cells`: [{i, j, value, text, href, title, attrs}], `value`
 * null for a cell without one (drawn hatched). Colours: viridis over `domain`, on a log
 * scale when `log`. `contour`: {level, missing} draws the line value = level, cells
 * without value counting as `missing`.
 */
export function heatMap({id, title, caption, xValues, yValues, cells, xLabel, yLabel, domain, log = false,
  colorLabel = '', contour = null, cellHeight = 44}) {
  const margin = {left: 96, right: 110, top: 12, bottom: 58};
  const width = WIDTH;
  const plotW = width - margin.left - margin.right;
  const nx = Math.max(1, xValues.length);
  const ny = Math.max(1, yValues.length);
  const cw = plotW / nx;
  const ch = Math.max(14, Math.min(cellHeight, 520 / ny));
  const height = margin.top + ny * ch + margin.bottom;
  const [lo, hi] = domain;
  const scale = (v) => {
    if (log) return (Math.log10(Math.max(v, lo)) - Math.log10(lo)) / (Math.log10(hi) - Math.log10(lo) || 1);
    return (v - lo) / (hi - lo || 1);
  };
  const cx = (i) => margin.left + i * cw;
  const cy = (j) => margin.top + (ny - 1 - j) * ch;
  const rects = cells.map((cell) => {
    const has = cell.value !== null && cell.value !== undefined && Number.isFinite(cell.value);
    const t = has ? scale(cell.value) : 0;
    const rect = s('rect', {x: round(cx(cell.i)) + 0.5, y: round(cy(cell.j)) + 0.5, width: round(cw) - 1,
      height: round(ch) - 1, fill: has ? viridis(t) : `url(#hatch-${id})`, class: has ? 'cell' : 'cell missing'});
    const label = cw >= 36 && ch >= 16 && cell.text !== undefined
      ? s('text', {x: round(cx(cell.i) + cw / 2), y: round(cy(cell.j) + ch / 2) + 4, 'text-anchor': 'middle',
        class: !has || t > 0.6 ? 'cell-text dark' : 'cell-text'}, cell.text)
      : null;
    const group = s('g', {'data-cell': '', 'data-i': cell.i, 'data-j': cell.j,
      'data-value': has ? cell.value : '', ...(cell.attrs || {})},
    s('title', {}, cell.title || ''), rect, label);
    if (cell.onclick) {
      group.addEventListener('click', cell.onclick);
      group.classList.add('clickable');
    }
    return cell.href ? s('a', {href: cell.href}, group) : group;
  });
  let contourPath = null;
  if (contour) {
    // The field on the cell centres, inside a ring of ghost cells that copy the border
    // ones, so that the line runs on to the edges of the map instead of stopping at the
    // outermost centres. Padded index t: 0 and n + 1 are the edges, t the centre of cell t − 1.
    const F = Array.from({length: ny + 2}, () => Array(nx + 2).fill(NaN));
    for (const cell of cells) {
      const has = cell.value !== null && cell.value !== undefined && Number.isFinite(cell.value);
      const v = has ? cell.value : contour.missing;
      F[cell.j + 1][cell.i + 1] = log ? Math.log10(Math.max(v, 1e-300)) : v;
    }
    for (let j = 0; j < ny + 2; j++) {
      for (let i = 0; i < nx + 2; i++) F[j][i] = F[Math.min(ny, Math.max(1, j))][Math.min(nx, Math.max(1, i))];
    }
    const level = log ? Math.log10(contour.level) : contour.level;
    const along = (t, n, size) => {
      if (t <= 1) return t * 0.5 * size;
      if (t >= n) return (n - 0.5 + (t - n) * 0.5) * size;
      return (t - 0.5) * size;
    };
    const px = (t) => round(margin.left + along(t, nx, cw));
    const py = (t) => round(margin.top + ny * ch - along(t, ny, ch));
    const d = contourSegments(F, level)
      .map(([a, b]) => `M${px(a[0])} ${py(a[1])}L${px(b[0])} ${py(b[1])}`).join('');
    contourPath = s('g', {class: 'contour'},
      s('path', {class: 'halo', d}),
      s('path', {class: 'line', d, 'data-contour': contour.level}));
  }
  const rotate = cw < 60;
  const xTicks = xValues.map((label, i) => s('text', {class: 'tick', x: round(cx(i) + cw / 2),
    y: margin.top + ny * ch + 16, 'text-anchor': rotate ? 'end' : 'middle',
    transform: rotate ? `rotate(-35 ${round(cx(i) + cw / 2)} ${margin.top + ny * ch + 16})` : null}, label));
  const yTicks = yValues.map((label, j) => s('text', {class: 'tick', x: margin.left - 6,
    y: round(cy(j) + ch / 2) + 4, 'text-anchor': 'end'}, label));
  // Colour bar.
  const barX = width - margin.right + 24;
  const barH = ny * ch;
  const stops = Array.from({length: 11}, (_, k) => s('stop', {offset: `${k * 10}%`, 'stop-color': viridis(1 - k / 10)}));
  const barTicks = (log ? decadeTicks(Math.log10(lo), Math.log10(hi)).map((e) => 10 ** e) : niceTicks(lo, hi, 4))
    .filter((v) => v >= lo && v <= hi)
    .map((v) => s('text', {class: 'tick', x: barX + 18, y: round(margin.top + (1 - scale(v)) * barH) + 4}, fmt(v, 2)));
  const svg = s('svg', {viewBox: `0 0 ${width} ${height}`, role: 'img', 'aria-label': title, class: 'chart'},
    s('defs', {},
      s('linearGradient', {id: `bar-${id}`, x1: 0, x2: 0, y1: 0, y2: 1}, stops),
      s('pattern', {id: `hatch-${id}`, width: 8, height: 8, patternUnits: 'userSpaceOnUse', patternTransform: 'rotate(45)'},
        s('rect', {width: 8, height: 8, fill: '#eceff3'}), s('line', {x1: 0, y1: 0, x2: 0, y2: 8, class: 'hatch'}))),
    rects, contourPath, xTicks, yTicks,
    s('rect', {x: barX, y: margin.top, width: 12, height: barH, fill: `url(#bar-${id})`, class: 'colorbar'}),
    barTicks,
    s('text', {class: 'axis-label', x: barX - 4, y: margin.top + barH + 18}, colorLabel),
    axisLabels(width, height, margin, xLabel, yLabel));
  return figure(id, title, caption || null, svg);
}

/** A histogram of `values` with `bins` bars (default: √n, 5 to 30); `markers`: [{x, label}]. */
export function histogram({id, title, caption, values, xLabel, bins, markers = []}) {
  const finite = values.filter(Number.isFinite);
  const count = bins || Math.max(5, Math.min(30, Math.round(Math.sqrt(finite.length)) || 5));
  const [lo, hi] = extent(finite);
  const margin = {left: 60, right: 18, top: 44, bottom: 46};
  const width = WIDTH;
  const height = 290;
  if (!finite.length) return figure(id, title, h('span', {class: 'muted'}, ' no values'), h('div'));
  const span = hi > lo ? hi - lo : Math.abs(lo) * 0.1 || 1;
  const start = hi > lo ? lo : lo - span / 2;
  const binWidth = span / count;
  const counts = Array(count).fill(0);
  for (const v of finite) counts[Math.min(count - 1, Math.floor((v - start) / binWidth))]++;
  const top = Math.max(...counts);
  const plotW = width - margin.left - margin.right;
  const plotH = height - margin.top - margin.bottom;
  const X = (x) => margin.left + ((x - start) / (binWidth * count)) * plotW;
  const Y = (c) => margin.top + plotH - (c / top) * plotH;
  const bars = counts.map((c, k) => s('rect', {class: 'bar', x: round(X(start + k * binWidth)) + 0.5,
    y: round(Y(c)), width: Math.max(1, round(plotW / count) - 1), height: round(margin.top + plotH - Y(c)),
    'data-bin': k, 'data-count': c, 'data-from': start + k * binWidth, 'data-to': start + (k + 1) * binWidth},
  s('title', {}, `${fmt(start + k * binWidth)} to ${fmt(start + (k + 1) * binWidth)}: ${c}`)));
  const ticks = [];
  for (const t of niceTicks(start, start + span, 8)) {
    ticks.push(s('text', {class: 'tick', x: round(X(t)), y: margin.top + plotH + 16, 'text-anchor': 'middle'}, fmt(t, 3)));
  }
  for (const t of niceTicks(0, top, Math.min(top, 5))) {
    ticks.push(s('line', {class: 'grid', x1: margin.left, x2: margin.left + plotW, y1: round(Y(t)), y2: round(Y(t))}));
    ticks.push(s('text', {class: 'tick', x: margin.left - 6, y: round(Y(t)) + 4, 'text-anchor': 'end'}, fmt(t)));
  }
  const lines = markers.filter((m) => Number.isFinite(m.x)).map((m, k) => s('g', {class: 'marker', 'data-marker': m.label},
    s('line', {x1: round(X(m.x)), x2: round(X(m.x)), y1: margin.top, y2: margin.top + plotH}),
    s('line', {x1: round(X(m.x)), x2: round(X(m.x)), y1: 12 + 12 * (k % 3), y2: margin.top, class: 'leader'}),
    s('text', {x: round(X(m.x)) + 3, y: 16 + 12 * (k % 3)}, m.label)));
  const svg = s('svg', {viewBox: `0 0 ${width} ${height}`, role: 'img', 'aria-label': title, class: 'chart'},
    ticks, bars, s('rect', {class: 'frame', x: margin.left, y: margin.top, width: plotW, height: plotH}), lines,
    axisLabels(width, height, margin, xLabel, 'runs'));
  return figure(id, title, caption || h('span', {class: 'muted'}, ` ${finite.length} values`), svg,
    {'data-values': finite.length});
}

/**
 * A bar chart: one bar per label; `selected` index highlighted; `onselect(k)` on click;
 * `bands` (optional) a utilisation band per bar
 * (`ok`, `near`, `over` or null: margins.js) colouring it; `reference` a value drawn as a
 * dashed line (a utilisation of 1).
 */
export function barChart({id, title, caption, labels, values, yLabel, xLabel, selected = -1, onselect, bands = null,
  reference = null}) {
  const margin = {left: 78, right: 18, top: 14, bottom: 46};
  const width = WIDTH;
  const height = 220;
  const plotW = width - margin.left - margin.right;
  const plotH = height - margin.top - margin.bottom;
  const top = Math.max(...values.filter(Number.isFinite), reference ?? 0, 0) || 1;
  const bw = plotW / Math.max(1, values.length);
  const Y = (v) => margin.top + plotH - (v / top) * plotH;
  const bars = values.map((v, k) => {
    const band = bands ? bands[k] : null;
    const bar = s('rect', {class: `bar${k === selected ? ' selected' : ''}${band ? ` margin-${band}` : ''}`,
      x: round(margin.left + k * bw) + 0.5,
      y: round(Y(v)), width: Math.max(1, round(bw) - 1), height: round(margin.top + plotH - Y(v)),
      'data-bar': labels[k], 'data-value': v, 'data-band': band}, s('title', {}, `${labels[k]}: ${fmt(v)}`));
    if (onselect) bar.addEventListener('click', () => onselect(k));
    return bar;
  });
  const ticks = [];
  for (const t of niceTicks(0, top, 4)) {
    ticks.push(s('line', {class: 'grid', x1: margin.left, x2: margin.left + plotW, y1: round(Y(t)), y2: round(Y(t))}));
    ticks.push(s('text', {class: 'tick', x: margin.left - 6, y: round(Y(t)) + 4, 'text-anchor': 'end'}, fmt(t, 3)));
  }
  const every = Math.max(1, Math.ceil(values.length / 24));
  labels.forEach((label, k) => {
    if (k % every === 0) {
      ticks.push(s('text', {class: 'tick', x: round(margin.left + (k + 0.5) * bw), y: margin.top + plotH + 16,
        'text-anchor': 'middle'}, label));
    }
  });
  const line = reference === null ? null : s('line', {class: 'reference', x1: margin.left, x2: margin.left + plotW,
    y1: round(Y(reference)), y2: round(Y(reference)), 'data-reference': reference});
  const svg = s('svg', {viewBox: `0 0 ${width} ${height}`, role: 'img', 'aria-label': title, class: 'chart'},
    ticks, bars, line, s('rect', {class: 'frame', x: margin.left, y: margin.top, width: plotW, height: plotH}),
    axisLabels(width, height, margin, xLabel, yLabel));
  return figure(id, title, caption || null, svg);
}

/** For figures drawn elsewhere (hex.js): the SVG element builder and the figure frame. */
export {s as svgElement, figure};
