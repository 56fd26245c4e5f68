// Pseudo-acceleration response spectra on log–log axes: of a job's displacement history
// (a point of the model: the history and its column picked, any damping ratios), of the
// excitation it was given (a synthetic earthquake against its target) and of a stored
// signal (signals.js). The API computes them (`/jobs/{id}/results/{output}/
// response_spectrum`, `/signals/{id}/spectrum`); this draws one curve per damping ratio
// and a line at the record's peak acceleration, which the spectrum reaches at high
// frequency.

import {api, card, errorBox, fmt, h, replace} from './util.js';
import {linePlot} from './lines.js';

/** Frequencies of a drawn spectrum (log-spaced). */
const POINTS = 200;

/** Damping ratios from a text such as `0.02, 0.05` (percent signs allowed: `2 %, 5 %`). */
export function dampings(text) {
  return String(text).replace(/\s+%/g, '%').split(/[,;\s]+/).filter(Boolean).map((item) => {
    const percent = item.endsWith('%');
    const value = Number(percent ? item.slice(0, -1) : item);
    return percent ? value / 100 : value;
  });
}

/**
 * A PSA plot of a spectrum document (`frequencies`, `pseudo_acceleration`:
 * [{damping, values}]), with a horizontal line at `peak` (m/s²) labelled `peakLabel`.
 */
export function psaPlot(doc, {id, title, peak, peakLabel, caption = null, markers = [], extra = []}) {
  return linePlot({id, title, caption, logX: true, logY: true, logRange: 8, xName: 'frequency',
    xLabel: 'frequency (Hz)', yLabel: 'PSA (m/s²)', markers,
    hLines: Number.isFinite(peak) && peak > 0 ? [{y: peak, label: `${peakLabel} ${fmt(peak, 4)} m/s²`}] : [],
    series: doc.pseudo_acceleration.map((spectrum, k) => ({name: `psa_${spectrum.damping}`,
      label: `ξ = ${fmt(100 * spectrum.damping, 3)} %`, x: doc.frequencies, y: spectrum.values, color: k}))
      .concat(extra)});
}

/** The inputs of a spectrum request: damping ratios and the frequency band. */
export function spectrumControls({damping = '0.02, 0.05', fMin = 1, fMax = 1000, onsubmit}) {
  const dampingInput = h('input', {type: 'text', value: damping, size: 18, 'data-control': 'damping',
    'aria-label': 'damping ratios'});
  const fMinInput = h('input', {type: 'number', min: 0, step: 'any', value: fMin, 'data-control': 'f_min',
    'aria-label': 'lowest frequency (Hz)'});
  const fMaxInput = h('input', {type: 'number', min: 0, step: 'any', value: fMax, 'data-control': 'f_max',
    'aria-label': 'highest frequency (Hz)'});
  const form = h('form', {class: 'inline', onsubmit: (event) => { event.preventDefault(); onsubmit(); }},
    h('label', {}, 'damping ξ ', dampingInput, h('span', {class: 'unit'}, '(ratios, e.g. 0.05 or 5 %)')),
    h('label', {}, 'from ', fMinInput, ' to ', fMaxInput, h('span', {class: 'unit'}, 'Hz')),
    h('button', {type: 'submit', 'data-action': 'draw-spectrum'}, 'Draw'));
  const query = () => {
    const params = new URLSearchParams({f_min: fMinInput.value, f_max: fMaxInput.value, points: POINTS});
    for (const xi of dampings(dampingInput.value)) params.append('damping', xi);
    return params;
  };
  const set = (values) => {
    if (values.damping !== undefined) dampingInput.value = values.damping;
    if (values.fMin !== undefined) fMinInput.value = values.fMin;
    if (values.fMax !== undefined) fMaxInput.value = values.fMax;
  };
  return {form, query, set};
}

/** The process's displacement and acceleration histories (`kind` in its description), by name. */
async function spectrumOutputs(processID) {
  const description = await api(`/processes/${processID}`);
  return Object.entries(description.outputs || {})
    .filter(([, output]) => output.kind === 'displacement' || output.kind === 'acceleration')
    .map(([name, output]) => ({name, kind: output.kind}));
}

/** What the caption says of a drawn spectrum: how its acceleration was read, and its target. */
function spectrumCaption(doc, kind) {
  const read = kind === 'acceleration'
    ? ` the ${doc.samples} stored samples of the excitation, as the run was given it`
    : ` acceleration by second differences of ${doc.samples + 2} samples every ${fmt(doc.sample_interval, 3)} s, ` +
      'relative to the base (the frame of the histories)';
  const target = doc.target && Number.isFinite(doc.target.max_deviation)
    ? `; against its target (ξ = ${fmt(100 * doc.target.damping, 3)} %): largest deviation ` +
      `${fmt(100 * doc.target.max_deviation, 3)} % at ${fmt(doc.target.deviation_frequency, 4)} Hz ` +
      `(tolerance ${fmt(100 * doc.target.tolerance, 3)} %)`
    : '';
  return h('span', {class: 'muted', 'data-peak-acceleration': doc.peak_acceleration,
    'data-target-deviation': doc.target ? doc.target.max_deviation : ''}, read + target);
}

/**
 * A job's response spectra: pick a displacement history (a pin, a height, numerical or
 * reference) or the excitation (a synthetic earthquake drawn against its target), its
 * column and damping ratios; null when the process has neither. `results`: the job's
 * results document, which the page has already read (its `generated_records`).
 */
export async function responseSpectrumCard(id, processID, results) {
  const outputs = await spectrumOutputs(processID).catch(() => []);
  if (!outputs.length) return null;
  const generated = (results && results.generated_records) || [];
  const drawn = h('div');
  const output = h('select', {'aria-label': 'history', 'data-control': 'output', onchange: () => columns()},
    outputs.map(({name}) => h('option', {value: name}, name)));
  const column = h('select', {'aria-label': 'column', 'data-control': 'series', onchange: () => fitTarget()});
  const kind = () => (outputs.find((item) => item.name === output.value) || {}).kind;
  // A synthetic earthquake's column is drawn at its target's damping and over its band.
  const fitTarget = () => {
    const record = kind() === 'acceleration' && generated.find((item) => item.member === column.value);
    if (!record) return;
    const bands = record.target.frequencies;
    controls.set({damping: String(record.target.damping), fMin: bands[0], fMax: bands[bands.length - 1]});
  };
  const columns = async () => {
    const doc = await api(`/jobs/${id}/results/${output.value}?t_end=0`);
    replace(column, doc.series.map((item) => h('option', {value: item.name}, item.name)));
    fitTarget();
  };
  const draw = async () => {
    const params = controls.query();
    params.set('series', column.value);
    try {
      const doc = await api(`/jobs/${id}/results/${output.value}/response_spectrum?${params}`);
      const resolved = 1 / (10 * doc.sample_interval);
      const target = doc.target
        ? [{name: 'target', label: `target (ξ = ${fmt(100 * doc.target.damping, 3)} %)`, x: doc.frequencies,
          y: doc.target.pseudo_acceleration, color: doc.pseudo_acceleration.length, dashed: true}]
        : [];
      replace(drawn, psaPlot(doc, {id: 'response-spectrum',
        title: `Pseudo-acceleration response spectrum of ${doc.output} ${doc.series}`,
        peak: doc.peak_acceleration, peakLabel: 'peak acceleration', extra: target,
        markers: kind() === 'displacement' && resolved < doc.frequencies[doc.frequencies.length - 1]
          ? [{x: resolved, label: `1/(10 Δt) = ${fmt(resolved, 3)} Hz`}] : [],
        caption: spectrumCaption(doc, kind())}));
    } catch (error) {
      replace(drawn, errorBox(error));
    }
  };
  const controls = spectrumControls({onsubmit: draw});
  const box = card('Response spectrum',
    h('p', {class: 'muted'}, 'What an oscillator of each frequency, mounted at that point, would feel: ',
      'PSA = ω² max|u|, on log–log axes.'),
    h('div', {class: 'filters'}, h('label', {}, 'history ', output), h('label', {}, 'column ', column)),
    controls.form, drawn);
  box.setAttribute('data-card', 'response-spectrum');
  await columns();
  await draw();
  return box;
}
