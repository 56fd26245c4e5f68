// Impact statistics on a job's page (issue 19): the statistics a level × position grid
// or a cross-section can be coloured by, the run's peak-force histogram and contact
// rankings, and the per-impact table of one contact (served page by page from
// `/jobs/{id}/results/impacts`).

import {api, card, errorBox, fmt, h, keyValueTable, replace, withUnit} from './util.js';
import {barChart} from './plot.js';

/** Per-contact statistics to show: label, unit and how to read it from a contact. */
const stat = (key, label, unit) => ({label, unit, of: (c) => (c.impact_statistics || {})[key]});
export const STATISTICS = {
  max_force: {label: 'peak force', unit: 'N', of: (c) => c.max_force},
  impacts: {label: 'impact count', unit: '', of: (c) => c.impacts},
  impacts_per_second: stat('impacts_per_second', 'impacts per second', '1/s'),
  contact_fraction: stat('contact_fraction', 'fraction of time in contact', ''),
  mean_force: stat('mean_force', 'mean force', 'N'),
  rms_force: stat('rms_force', 'RMS force', 'N'),
  impulse: stat('impulse', 'impulse', 'N·s'),
  mean_duration: stat('mean_duration', 'mean impact duration', 's'),
  rebounds_per_impact: stat('rebounds_per_impact', 'rebounds per impact', ''),
  max_impact_energy: stat('max_impact_energy', 'largest impact energy ½mv²', 'J'),
};

/** A select over `STATISTICS` (plus `extra` entries) calling `onchange(key)`. */
export function statisticPicker(onchange, extra = {}) {
  const all = {...STATISTICS, ...extra};
  return h('select', {'aria-label': 'statistic', 'data-picker': 'statistic',
    onchange: (event) => onchange(event.target.value)},
  Object.entries(all).map(([key, m]) => h('option', {value: key}, m.label)));
}

/** The run's impacts: counting, peak-force histogram and the contacts ranked. */
export function impactsCard(results, summary, describe) {
  if (!summary) return null;
  const edges = (summary.histogram || {}).edges || [];
  const counts = (summary.histogram || {}).counts || [];
  const ranking = (rows, title) => h('table', {class: 'list', 'data-ranking': title},
    h('thead', {}, h('tr', {}, h('th', {}, title), h('th', {}, 'peak force'), h('th', {}, 'impacts'))),
    h('tbody', {}, rows.map((r) => h('tr', {}, h('td', {}, describe(r.contact)), h('td', {}, withUnit(r.max_force, 'N')),
      h('td', {}, fmt(r.impacts))))));
  return card('Impacts',
    keyValueTable([
      ['counting', `force threshold ${withUnit(summary.force_threshold, 'N')}, rest time ` +
        `${withUnit(summary.rest_time, 's')}, ${summary.blocks} block${summary.blocks === 1 ? '' : 's'}`],
      ['impacts', `${fmt(summary.impacts)} (${fmt(summary.tabulated)} in the table` +
        (summary.truncated ? `, truncated at max_rows ${fmt(summary.max_rows)}: the largest by peak force, ` +
          `${fmt(summary.fair_share)} per contact first; ${fmt(summary.untabulated)} left out, none above ` +
          `${withUnit(summary.untabulated_max_peak, 'N')})` : ', complete)')],
      ['largest impact energy, duration', `${withUnit(summary.max_impact_energy, 'J')}, ` +
        `${withUnit(summary.max_duration, 's')}`],
    ]),
    counts.length && summary.impacts ? barChart({id: 'impact-histogram', title: 'Impacts by peak force',
      labels: counts.map((_, k) => `${fmt(edges[k], 3)}–${fmt(edges[k + 1], 3)}`), values: counts,
      xLabel: 'peak force (N)', yLabel: 'impacts'}) : h('p', {class: 'muted'}, 'No impact.'),
    h('div', {class: 'columns'}, ranking(summary.by_peak_force || [], 'by peak force'),
      ranking(summary.by_impacts || [], 'by impact count')));
}

const PAGE = 50;

/** Contact k's statistics and its impacts, one page of the table at a time. */
export function contactImpacts(id, k, contact) {
  const s = contact.impact_statistics || {};
  const box = h('div', {'data-contact-impacts': k});
  const statistics = keyValueTable([
    ['impacts', `${fmt(s.impacts)} (${fmt(s.impacts_per_second)} per second, ` +
      `${fmt(s.rebounds_per_impact, 3)} rebounds each)`],
    ['durations', `mean ${withUnit(s.mean_duration, 's')}, from ${withUnit(s.min_duration, 's')} to ` +
      `${withUnit(s.max_duration, 's')}`],
    ['time in contact', `${fmt(100 * (s.contact_fraction || 0), 3)} %`],
    ['force, whole run', `mean ${withUnit(s.mean_force, 'N')}, RMS ${withUnit(s.rms_force, 'N')}`],
    ['force, in contact', `mean ${withUnit(s.mean_contact_force, 'N')}, RMS ${withUnit(s.rms_contact_force, 'N')}`],
    ['impact energy ½mv²', `mean ${withUnit(s.mean_impact_energy, 'J')}, largest ${withUnit(s.max_impact_energy, 'J')}`],
    s.blocks ? ['across blocks', `${s.blocks.blocks} blocks: impacts ${fmt(s.blocks.impacts.mean)} ± ` +
      `${fmt(s.blocks.impacts.standard_deviation, 3)}, peak force ${withUnit(s.blocks.max_force.mean, 'N')} ± ` +
      `${fmt(s.blocks.max_force.standard_deviation, 3)}`] : null,
  ].filter(Boolean), {class: 'kv wide'});
  const table = h('div');
  const load = async (offset) => {
    try {
      const page = await api(`/jobs/${id}/results/impacts?contact=${k}&offset=${offset}&limit=${PAGE}`);
      const more = page.next ? h('button', {type: 'button', onclick: () => load(offset + PAGE)},
        `next ${PAGE} of ${page.total_rows}`) : null;
      replace(table, page.rows.length ? h('table', {class: 'list', 'data-impacts-table': k},
        h('thead', {}, h('tr', {}, ['start (s)', 'peak (N)', 'at (s)', 'impulse (N·s)', 'duration (s)',
          'approach (m/s)', 'rebounds', 'dissipated (J)', '½mv² (J)'].map((t) => h('th', {}, t)))),
        h('tbody', {}, page.rows.map((r) => h('tr', {'data-impact': ''},
          [r.start, r.peak_force, r.peak_time, r.impulse, r.duration, r.approach_velocity, r.rebounds, r.dissipated,
            r.energy].map((v) => h('td', {}, fmt(v, 4))))))) : h('p', {class: 'muted'}, 'No impact in the table.'),
      h('p', {class: 'muted'}, `rows ${offset + 1}–${offset + page.rows.length} of ${page.total_rows}` +
        (page.truncated ? ` (the table is truncated: these are the contact's ${fmt(s.tabulated)} largest of ` +
          `${fmt(s.impacts)} impacts) ` : ' '),
        h('a', {href: `/jobs/${id}/results/impacts?format=csv&contact=${k}`, download: `impacts-c${k}.csv`},
          'CSV'), ' ', more));
    } catch (error) {
      replace(table, errorBox(error));
    }
  };
  load(0);
  box.append(statistics, table);
  return box;
}
