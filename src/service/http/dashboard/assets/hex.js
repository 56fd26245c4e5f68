// `hex-bundle-dynamics`: a cross-section of the bundle at one level (the wrapper's
// hexagon, pins as circles, the level's contacts as segments from the wire's pin toward
// what it touches, coloured by any impact statistic or the wear work rate), a level
// slider, and the force history and impacts of a clicked contact (histories exist for
// the recorded contacts only: `output.contacts`; statistics and impacts for every one).
// Then the run's impacts, and each pin's largest deflections and histories.
//
// For tests: the cross-section figure carries `data-level`, `data-measure` (the colouring
// statistic), `data-contacts-shown` and `data-selected`; its pins `data-pin`, its segments
// `data-contact` and `data-value`, and the colour scale's top `data-scale-max`.

import {api, card, errorBox, fmt, h, keyValueTable, replace, withUnit} from './util.js';
import {barChart, figure, svgElement as s, viridis} from './plot.js';
import {linePlot} from './lines.js';
import {envelope, envelopeSeries, history, qualityBadge, reportedPeak, seriesOf, thinned} from './job.js';
import {STATISTICS, contactImpacts, impactsCard, statisticPicker} from './impacts.js';
import {band, marginsCard} from './margins.js';

/**
 * What the segments may be coloured by: every impact statistic, the wear work rate, and
 * where the contact laws or `output.allowables` give them (docs/margins.md) the utilisation, friction's
 * wear power and slip, and the Archard wear depth.
 */
const WEAR = {wear_work_rate: {label: 'wear work rate', unit: 'W', of: (c) => c.wear_work_rate}};
const LAWS = {
  utilisation: {label: 'utilisation (peak / allowable)', unit: '', of: (c) => c.utilisation},
  wear_depth: {label: 'wear depth', unit: 'm', of: (c) => c.wear?.depth},
  friction_wear_power: {label: 'friction wear power', unit: 'W', of: (c) => c.friction?.wear_power},
  slip_distance: {label: 'slip distance', unit: 'm', of: (c) => c.friction?.slip_distance},
};
const MEASURES = {...STATISTICS, ...WEAR, ...LAWS};

/** The measures of the laws some contact of the run reports. */
function lawMeasures(contacts) {
  return Object.fromEntries(Object.entries(LAWS).filter(([, m]) => contacts.some((c) => m.of(c) != null)));
}
const SIZE = 560;

export async function hexBundle(box, id, results) {
  const geometry = results.geometry || {};
  const contacts = results.contacts || [];
  const pins = results.pins || [];
  const levels = geometry.levels || [];
  const peak = results.max_contact_force || {};
  const energy = results.energy || {};
  box.append(card('Summary', keyValueTable([
    ['pins, rings', `${geometry.pins}, ${geometry.rings}`],
    ['contacts, levels', `${contacts.length}, ${levels.length} (one every H/12)`],
    ['nominal clearances', `pin–pin ${withUnit(geometry.pin_clearance, 'm')}, pin–wall ${withUnit(geometry.wall_clearance, 'm')}`],
    ['peak contact force', [peak.force === undefined ? '–'
      : `${withUnit(peak.force, 'N')} at contact c${peak.contact} (level ${contacts[peak.contact].level}), ` +
        `t = ${withUnit(peak.time, 's')} `, qualityBadge(results)]],
    ['impacts', fmt(results.impacts)],
    ['time step', `${withUnit(results.time_step, 's')} (critical ${withUnit(results.critical_time_step, 's')})`],
    ['steps', fmt(results.steps)],
    ['energy balance residual', `${fmt(energy.relative_residual, 3)} (relative)`],
  ])));
  const describe = (k) => {
    const c = contacts[k];
    return `c${k}: pin ${c.wire_pin} on ${c.touched_pin === null ? `flat ${c.touched_flat}` : `pin ${c.touched_pin}`}` +
      ` at level ${c.level}`;
  };
  const margins = marginsCard({margins: results, contacts, pins, describe});
  if (margins) box.append(margins);
  if (contacts.length && pins.length) box.append(crossSectionCard(id, results, levels, contacts, pins, peak));
  const impacts = impactsCard(results, results.impact_summary, describe);
  if (impacts) box.append(impacts);
  if (pins.length) box.append(await pinsCard(id, results, pins));
}

function crossSectionCard(id, results, levels, contacts, pins, peak) {
  const recorded = new Set(results.recorded_contacts || []);
  const byLevel = levels.map(() => []);
  contacts.forEach((c, k) => byLevel[c.level].push(k));
  let level = peak.contact === undefined ? 0 : contacts[peak.contact].level;
  let selected = peak.contact === undefined ? -1 : peak.contact;
  let measure = 'max_force';
  const drawing = h('div');
  const detail = h('div');
  const plotBox = h('div');
  const label = h('span', {class: 'mono'});
  const slider = h('input', {type: 'range', min: 0, max: levels.length - 1, step: 1, value: level,
    'aria-label': 'level', 'data-level-slider': '', oninput: (event) => { level = Number(event.target.value); draw(); }});
  const colour = statisticPicker((key) => { measure = key; draw(); }, {...WEAR, ...lawMeasures(contacts)});
  const impactsBox = h('div');
  const draw = () => {
    const z = levels[level];
    replace(label, `level ${level}: z = ${fmt(z.height, 4)} m, wires at ${fmt(z.wire_angle)}°` +
      (z.flat === null ? ` (toward neighbours in direction ${z.neighbour_direction})` : ` (toward flat ${z.flat})`));
    replace(drawing, crossSection(results, pins, contacts, level, byLevel[level], measure, selected, select));
  };
  const select = async (k) => {
    selected = k;
    draw();
    const c = contacts[k];
    const touched = c.touched_pin === null ? `flat ${c.touched_flat}` : `pin ${c.touched_pin}`;
    replace(detail, keyValueTable([
      ['contact', `c${k}: the wire of pin ${c.wire_pin} on ${touched}, level ${c.level} (z = ${withUnit(c.height, 'm')})`],
      ['normal, gap', `(${fmt(c.normal[0], 3)}, ${fmt(c.normal[1], 3)}), ${withUnit(c.gap, 'm')}`],
      ['max force', `${withUnit(c.max_force, 'N')} at ${withUnit(c.max_force_time, 's')}`],
      ['impacts', fmt(c.impacts)], ['time in contact', withUnit(c.contact_time, 's')],
      ['impulse', withUnit(c.impulse, 'N·s')], ['wear work rate', withUnit(c.wear_work_rate, 'W')],
      ...(c.utilisation == null ? [] : [['utilisation', fmt(c.utilisation, 3)]]),
      ...(c.friction ? [
        ['tangential force', `mean ${withUnit(c.friction.mean_tangential_force, 'N')}, RMS ` +
          `${withUnit(c.friction.rms_tangential_force, 'N')}, max ${withUnit(c.friction.max_tangential_force, 'N')}`],
        ['slip, stick', `${withUnit(c.friction.slip_distance, 'm')} slid, sticking ` +
          `${fmt(100 * c.friction.stick_fraction, 3)} % of the time closed`],
        ['friction wear power', withUnit(c.friction.wear_power, 'W')]] : []),
      ...(c.wear ? [['Archard wear', `${withUnit(c.wear.depth, 'm')} deep, ${withUnit(c.wear.volume, 'm³')}`]] : []),
    ], {class: 'kv wide'}));
    replace(impactsBox, contactImpacts(id, k, c));
    if (!recorded.has(k)) {
      replace(plotBox, h('p', {class: 'muted', 'data-unrecorded': k}, `No history for c${k}: only the contacts of ` +
        `output.contacts are recorded (e.g. {"type": "list", "contacts": [${k}]}); its statistics above are complete.`));
      return;
    }
    try {
      const [doc, peaks] = await Promise.all([history(id, 'contact_forces', `c${k}`),
        envelope(id, results, 'contact_forces', `c${k}`)]);
      // A contact clicked since asks for its own history: this answer is stale.
      if (selected !== k) return;
      replace(plotBox, linePlot({id: 'contact_forces', title: `Contact force c${k}`,
        series: [...envelopeSeries(peaks), ...seriesOf(doc)], hLines: reportedPeak(c.max_force, 'N'),
        xName: 'time', xLabel: 'time (s)', yLabel: 'F (N)', caption: thinned(doc, peaks)}));
    } catch (error) {
      if (selected === k) replace(plotBox, errorBox(error));
    }
  };
  draw();
  if (selected >= 0) select(selected);
  return card('Cross-section', h('p', {class: 'inline'}, h('label', {}, 'Level ', slider), ' ', label),
    h('p', {class: 'inline'}, h('label', {}, 'Colour by ', colour)), drawing, detail, plotBox, impactsBox);
}

/**
 * The bundle seen from above at one level: y up, the wrapper's inner hexagon (flat k's
 * outward normal at k·60° + 30°), the pins, and the level's contacts as segments.
 */
function crossSection(results, pins, contacts, level, shown, measure, selected, onselect) {
  const g = results.geometry;
  const apothem = g.wrapper_flat_to_flat / 2;
  const corner = apothem / Math.cos(Math.PI / 6);
  const scale = (SIZE / 2 - 16) / corner;
  const X = (x) => SIZE / 2 + x * scale;
  const Y = (y) => SIZE / 2 - y * scale;
  const hexagon = [0, 1, 2, 3, 4, 5].map((k) => {
    const a = (k * Math.PI) / 3;
    return `${X(corner * Math.cos(a)).toFixed(1)},${Y(corner * Math.sin(a)).toFixed(1)}`;
  }).join(' ');
  const m = MEASURES[measure];
  const valueOf = (c) => m.of(c) ?? 0;
  const top = Math.max(...contacts.map(valueOf), 0) || 1;
  const radius = (g.pin_diameter / 2) * scale;
  // Pins filled by their utilisation's band when the run has allowables (margins.js).
  const circles = pins.map((p) => s('circle', {class: band(p.utilisation) ? `pin margin-${band(p.utilisation)}` : 'pin',
    cx: X(p.position[0]).toFixed(1), cy: Y(p.position[1]).toFixed(1),
    r: radius.toFixed(1), fill: '#eef1f4', stroke: '#9aa5b1', 'data-pin': p.pin, 'data-band': band(p.utilisation)},
  s('title', {}, `pin ${p.pin} (ring ${p.ring})` + (p.utilisation == null ? '' : `, utilisation ${fmt(p.utilisation, 3)}`))));
  const numbers = pins.length <= 61 ? pins.map((p) => s('text', {class: 'tick', x: X(p.position[0]).toFixed(1),
    y: (Y(p.position[1]) + 4).toFixed(1), 'text-anchor': 'middle'}, p.pin)) : [];
  const segments = shown.map((k) => {
    const c = contacts[k];
    const from = pins[c.wire_pin].position;
    let to;
    if (c.touched_pin !== null) {
      to = pins[c.touched_pin].position;
    } else {
      // The point of the flat the wire faces: along the normal, at the flat's distance.
      const reach = apothem - (from[0] * c.normal[0] + from[1] * c.normal[1]);
      to = [from[0] + reach * c.normal[0], from[1] + reach * c.normal[1]];
    }
    const value = valueOf(c);
    const line = s('line', {class: k === selected ? 'contact selected' : 'contact',
      x1: X(from[0]).toFixed(1), y1: Y(from[1]).toFixed(1), x2: X(to[0]).toFixed(1), y2: Y(to[1]).toFixed(1),
      stroke: value > 0 ? viridis(value / top) : '#c5ccd4', 'stroke-width': k === selected ? 6 : 3.5,
      'stroke-linecap': 'round', 'data-contact': k, 'data-value': value, style: 'cursor: pointer'},
    s('title', {}, `c${k}: ${m.label} ${fmt(value)} ${m.unit}`));
    line.addEventListener('click', () => onselect(k));
    return line;
  });
  const svg = s('svg', {viewBox: `0 0 ${SIZE} ${SIZE}`, role: 'img', class: 'chart cross-section',
    'aria-label': 'bundle cross-section', style: `max-width: ${SIZE}px`},
  s('polygon', {points: hexagon, fill: 'none', stroke: '#17212e', 'stroke-width': 2}), circles, numbers, segments);
  return figure('cross-section', `Contacts of the level, coloured by ${m.label}`,
    h('span', {class: 'muted', 'data-scale-max': top},
      ` dark: 0, yellow: ${fmt(top, 3)} ${m.unit} (the largest over all levels); ` +
      'grey: never loaded; click a contact for its history'), svg,
    {'data-level': level, 'data-measure': measure, 'data-contacts-shown': shown.length, 'data-selected': selected});
}

async function pinsCard(id, results, pins) {
  const pinBox = h('div');
  const barBox = h('div');
  const largest = (p) => Math.max(p.x.max_abs_deflection, p.y.max_abs_deflection);
  let shown = -1;
  const drawPin = async (p) => {
    shown = p;
    replace(barBox, barChart({id: 'pin-deflection', title: 'Largest |deflection| per pin (x or y)',
      labels: pins.map((x) => `${x.pin}`), values: pins.map(largest), yLabel: 'max |w| (m)', xLabel: 'pin',
      selected: p, onselect: drawPin}));
    try {
      // The tips (`p<pin>x`) or the first output height (`p<pin>x@<z>`).
      const names = (await api(`/jobs/${id}/results/displacements?t_end=0`)).series.map((item) => item.name);
      const pick = (axis) => names.find((n) => n === `p${p}${axis}` || n.startsWith(`p${p}${axis}@`));
      const wanted = [pick('x'), pick('y')].filter(Boolean).join(',');
      const [doc, peaks] = await Promise.all([history(id, 'displacements', wanted),
        envelope(id, results, 'displacements', wanted)]);
      if (shown !== p) return; // another pin was clicked since
      replace(pinBox, linePlot({id: 'displacements', title: `Deflection of pin ${p} along x and y (${wanted})`,
        series: [...envelopeSeries(peaks), ...seriesOf(doc)], xName: 'time', xLabel: 'time (s)', yLabel: 'w (m)',
        caption: thinned(doc, peaks)}));
    } catch (error) {
      if (shown === p) replace(pinBox, errorBox(error));
    }
  };
  const container = card('Pins', barBox, pinBox);
  await drawPin(pins.reduce((best, x, p) => (largest(x) > largest(pins[best]) ? p : best), 0));
  return container;
}
