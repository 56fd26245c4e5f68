// Margins (docs/margins.md): the utilisation ratios `output.allowables` gives (peak over
// allowable, per contact, per pin and the run's worst), coloured by band: green below
// 0.8, amber from 0.8 to 1, red from 1 (an allowable reached). Without allowables every
// ratio is null and nothing here is drawn.
//
// For tests: the margins card carries `data-worst` (the run's worst utilisation); its bar
// charts `margin-pins` and `margin-contacts` bars with `data-bar`, `data-value` and
// `data-band`; a band is also set as `data-band` on the bars of the pins' deflection
// chart and on the pins of the hexagonal cross-section.

import {card, fmt, h, keyValueTable, withUnit} from './util.js';
import {barChart} from './plot.js';

/** Below it green; from it to 1 amber; from 1 red (`margins::AMBER`). */
export const AMBER = 0.8;

/** The band of a utilisation: `ok`, `near` or `over`; null without one. */
export function band(utilisation) {
  if (utilisation === null || utilisation === undefined || !Number.isFinite(utilisation)) return null;
  return utilisation >= 1 ? 'over' : utilisation >= AMBER ? 'near' : 'ok';
}

/** A utilisation as text with its coloured badge. */
export function utilisationBadge(utilisation) {
  const b = band(utilisation);
  return b ? h('span', {class: `badge margin-${b}`, 'data-band': b}, fmt(utilisation, 3)) : '–';
}

/**
 * The margins card, or null when the run has no utilisation: the run's worst, its worst
 * contact and stress, and bars per pin and per contact coloured by band. `margins` holds
 * `worst_utilisation`, `max_utilisation` (contact) and `max_stress_utilisation`;
 * `contacts`, `pins` the results' lists (`utilisation` each); `describe(k)` names contact k.
 */
export function marginsCard({margins, contacts = [], pins = [], describe = (k) => `c${k}`}) {
  const worst = margins.worst_utilisation;
  if (worst === null || worst === undefined) return null;
  const contact = margins.max_utilisation;
  const stress = margins.max_stress_utilisation;
  const rows = [
    ['worst utilisation', utilisationBadge(worst)],
    ['worst contact', contact ? [utilisationBadge(contact.utilisation),
      ` ${describe(contact.contact)}: ${withUnit(contact.force, 'N')} of ${withUnit(contact.allowable_force, 'N')}`] : '–'],
    ['worst clad stress', stress ? [utilisationBadge(stress.utilisation),
      ` pin ${stress.pin} at ${withUnit(stress.height, 'm')}, t = ${withUnit(stress.time, 's')}: ` +
      `${withUnit(stress.stress, 'Pa')} of ${withUnit(stress.allowable_stress, 'Pa')}`] : '–'],
  ];
  const bars = (id, title, items, label, xLabel) => {
    const kept = items.map((item, k) => [k, item.utilisation]).filter(([, u]) => u !== null && u !== undefined);
    if (!kept.length) return null;
    return barChart({id, title, labels: kept.map(([k]) => label(k)), values: kept.map(([, u]) => u),
      bands: kept.map(([, u]) => band(u)), yLabel: 'utilisation', xLabel, reference: 1,
      caption: h('span', {class: 'muted'}, ` green < ${AMBER} ≤ amber < 1 ≤ red`)});
  };
  const section = card('Margins', keyValueTable(rows),
    bars('margin-pins', 'Utilisation per pin (the larger of its stress and its contacts)', pins, (p) => `${pins[p].pin ?? p}`, 'pin'),
    bars('margin-contacts', 'Utilisation per contact (peak force / allowable)', contacts, (k) => `c${k}`, 'contact'));
  section.dataset.margins = '';
  section.dataset.worst = String(worst);
  return section;
}
