// The stored signals (accelerograms): the list, and one signal's page with its metadata,
// its record (when short enough to draw whole) and its pseudo-acceleration response
// spectrum on log–log axes at any damping ratios, with a line at its PGA.

import {api, card, download, errorBox, fmt, fmtTime, h, keyValueTable, replace, shortId, withUnit} from './util.js';
import {linePlot} from './lines.js';
import {psaPlot, spectrumControls} from './spectra.js';

/** Records up to this many samples are drawn on the signal's page (the CSV has any). */
const DRAWN_SAMPLES = 50000;

function signalTable(signals) {
  if (!signals.length) {
    return h('p', {class: 'muted'}, 'No signals yet: upload a record with ',
      h('code', {}, 'curl -X POST -H \'Content-Type: text/csv\' --data-binary @record.csv <service>/signals'), '.');
  }
  return h('table', {class: 'list', 'data-list': 'signals'},
    h('thead', {}, h('tr', {}, ['Signal', 'Samples', 'Duration', 'Sampling rate', 'PGA', 'Arias intensity', 'Uploaded']
      .map((c) => h('th', {}, c)))),
    h('tbody', {}, signals.map((signal) => h('tr', {'data-signal': signal.id},
      h('td', {}, h('a', {href: `/signals/${signal.id}`, title: signal.id, class: 'mono'}, shortId(signal.id))),
      h('td', {}, fmt(signal.samples)),
      h('td', {}, withUnit(signal.duration, 's')),
      h('td', {}, withUnit(signal.sampling_rate, 'Hz')),
      h('td', {}, withUnit(signal.pga, 'm/s²')),
      h('td', {}, withUnit(signal.arias_intensity, 'm/s')),
      h('td', {}, fmtTime(signal.created))))));
}

/** The list of the tenant's signals, newest first, page by page. */
export async function signals(main) {
  const params = new URLSearchParams(location.search);
  params.delete('f');
  const box = h('div', {}, h('p', {class: 'muted'}, 'Loading…'));
  const pager = h('p', {class: 'pager'});
  replace(main, h('h1', {}, 'Signals'),
    h('p', {class: 'muted'}, 'Accelerograms stored once, referenced by jobs and sweeps as ',
      h('code', {}, '{"type": "signal", "id": "…", "scale": 1.0}'), '.'),
    card(null, box, pager));
  try {
    const doc = await api(`/signals${params.toString() ? `?${params}` : ''}`);
    replace(box, signalTable(doc.signals));
    const next = doc.links.find((l) => l.rel === 'next');
    replace(pager, next ? h('a', {href: next.href}, 'older signals →') : null);
  } catch (error) {
    replace(box, errorBox(error));
  }
}

async function recordCard(id, metadata) {
  if (metadata.samples > DRAWN_SAMPLES) {
    return card('Record', h('p', {class: 'muted'}, `${fmt(metadata.samples)} samples: too many to draw here; `,
      download(`/signals/${id}/samples?format=csv`, 'samples.csv'), ' has them all.'));
  }
  const record = await api(`/signals/${id}/samples?format=json`);
  return card('Record', linePlot({id: 'signal-record', title: 'Acceleration a(t)',
    series: [{name: 'acceleration', x: record.time, y: record.acceleration, color: 0}],
    hLines: [{y: metadata.pga, label: 'PGA'}, {y: -metadata.pga, label: '−PGA'}],
    xName: 'time', xLabel: 'time (s)', yLabel: 'a (m/s²)',
    caption: h('span', {class: 'muted'}, ` ${fmt(metadata.samples)} samples`)}));
}

/** One signal: metadata, record, response spectrum. */
export async function signal(main, id) {
  const metadata = await api(`/signals/${id}`);
  const drawn = h('div');
  const controls = spectrumControls({damping: '0.02, 0.05, 0.1', fMin: 0.1,
    fMax: Math.min(100, Number((metadata.sampling_rate / 4).toPrecision(2))), onsubmit: () => draw()});
  const draw = async () => {
    try {
      const doc = await api(`/signals/${id}/spectrum?${controls.query()}`);
      replace(drawn, psaPlot(doc, {id: 'signal-spectrum', title: 'Pseudo-acceleration response spectrum',
        peak: doc.pga, peakLabel: 'PGA'}));
    } catch (error) {
      replace(drawn, errorBox(error));
    }
  };
  const record = h('div');
  replace(main, h('h1', {}, 'Signal ', h('span', {class: 'mono'}, id)),
    card('Metadata', keyValueTable([
      ['samples', fmt(metadata.samples)],
      ['start, duration', `${withUnit(metadata.start, 's')}, ${withUnit(metadata.duration, 's')}`],
      ['sampling', `${withUnit(metadata.sampling_rate, 'Hz')} (interval ${withUnit(metadata.sampling_interval, 's')}` +
        `${metadata.uniform ? ', uniform' : `, from ${fmt(metadata.shortest_interval)} to ${fmt(metadata.longest_interval)} s`})`],
      ['PGA', h('span', {'data-pga': metadata.pga}, `${withUnit(metadata.pga, 'm/s²')} at ${withUnit(metadata.pga_time, 's')}`)],
      ['Arias intensity', withUnit(metadata.arias_intensity, 'm/s')],
      ['uploaded', fmtTime(metadata.created)],
      ['use it as', h('code', {}, `{"type": "signal", "id": "${id}", "scale": 1.0}`)],
    ], {'data-signal-metadata': id}),
    h('p', {class: 'actions'}, download(`/signals/${id}/samples?format=csv`, 'samples.csv'),
      download(`/signals/${id}/spectrum?format=csv`, 'spectrum.csv'), h('a', {href: `/signals/${id}?f=json`}, 'as JSON'))),
    record, card('Response spectrum', controls.form, drawn));
  await Promise.all([draw(),
    recordCard(id, metadata).catch((error) => card('Record', errorBox(error))).then((box) => replace(record, box))]);
}
