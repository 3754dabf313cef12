// Profiles and consolidation panels of the job page.
//
// profiles.json ({time, profiles: [{index, from, to, points, distance,
// particles, initial_positions, <field>: [one row per time]}]}): a field
// along any line of output.profiles, a curve per profile time (isochrones).
// A mostly vertical line (the last coordinate is vertical: x in 1D, y in 2D)
// is drawn against depth below its top, growing downward, the field across;
// any other line against the distance from its start.
//
// consolidation.json ({time, degree, average_excess_pore_pressure, t50,
// t90, ...}): the average degree of consolidation U against time (log
// scale), U growing downward as in a settlement curve, and the average
// excess pore pressure.

import { get_json } from '/ui/api.js';
import { field_label, format_time, h, notice, num, time_unit } from '/ui/dom.js';
import { colour, legend, line_chart } from '/ui/chart.js';
import { component_names } from '/ui/vtu.js';

const META = new Set(['index', 'from', 'to', 'points', 'distance', 'particles', 'initial_positions']);

// How a line is drawn: {vertical, where: value per point, label}.
export function profile_axis(line) {
  const from = line.from || [];
  const to = line.to || [];
  const points = line.points || [];
  const dim = from.length;
  if (dim && to.length === dim && points.length) {
    const rise = Math.abs(to[dim - 1] - from[dim - 1]);
    let run = 0;
    for (let a = 0; a + 1 < dim; ++a) run += (to[a] - from[a]) ** 2;
    if (rise > Math.sqrt(run)) {
      const top = Math.max(from[dim - 1], to[dim - 1]);
      const axis = dim > 1 ? 'xyz'[dim - 1] : 'x';
      return { vertical: true, where: points.map((p) => top - p[dim - 1]), label: `depth below ${axis} = ${num(top)} m (m)` };
    }
  }
  return { vertical: false, where: line.distance || [], label: `distance from (${from.map(num).join(', ')}) towards (${to.map(num).join(', ')}) (m)` };
}

function value_at(v, c) {
  if (v === null || v === undefined) return NaN;
  if (!Array.isArray(v)) return Number(v);
  if (c >= 0) return Number(v[c]);
  return Math.sqrt(v.reduce((s, x) => s + x * x, 0));
}

export async function profiles_panel(root, href) {
  root.replaceChildren(h('p', { class: 'muted' }, 'Loading profiles.json…'));
  let doc;
  try {
    doc = await get_json(href);
  } catch (err) {
    root.replaceChildren(notice('error', `Cannot load profiles.json: ${err.message}`));
    return;
  }
  const lines = doc.profiles || [];
  const time = doc.time || [];
  if (!lines.length || !time.length) {
    root.replaceChildren(h('p', { class: 'muted' }, 'The profiles are empty.'));
    return;
  }
  const line_pick = h('select', { id: 'profile-line', 'aria-label': 'profile line' },
    lines.map((l, i) => h('option', { value: i }, `line ${l.index ?? i}: (${(l.from || []).map(num).join(', ')}) → (${(l.to || []).map(num).join(', ')})`)));
  const field = h('select', { id: 'profile-field', 'aria-label': 'field' });
  const component = h('select', { id: 'profile-component', 'aria-label': 'component' });
  const chart_box = h('div', { class: 'chart-box', id: 'profile-chart' });
  const legend_box = h('div', { id: 'profile-legend' });
  root.replaceChildren(h('div', { class: 'controls' }, line_pick, field, component), chart_box, legend_box);

  const line = () => lines[Number(line_pick.value)];
  function fill_fields() {
    const names = Object.keys(line()).filter((k) => !META.has(k) && Array.isArray(line()[k]));
    const previous = field.value;
    field.replaceChildren(...names.map((f) => h('option', { value: f }, f.replace(/_/g, ' '))));
    if (names.includes(previous)) field.value = previous;
    fill_components();
  }
  function fill_components() {
    const rows = line()[field.value] || [];
    const first = (rows[0] || []).find((v) => v !== null && v !== undefined);
    const n = Array.isArray(first) ? first.length : 1;
    component.replaceChildren(
      ...(n === 2 || n === 3 ? [h('option', { value: -1 }, 'magnitude')] : []),
      ...component_names(n).map((c, i) => h('option', { value: i }, n === 1 ? 'value' : c)),
    );
    component.hidden = n === 1;
    component.value = '0';
  }
  function draw() {
    const l = line();
    const rows = l[field.value] || [];
    const c = Number(component.value);
    const axis = profile_axis(l);
    const curves = rows.map((row, r) => {
      const values = row.map((v) => value_at(v, c));
      const label = `t = ${format_time(time[r])}`;
      const tint = colour(rows.length > 1 ? r / (rows.length - 1) : 0);
      return axis.vertical ? { label, x: values, y: axis.where, colour: tint } : { label, x: axis.where, y: values, colour: tint };
    });
    const value_label = field_label(field.value, component.hidden ? '' : component.selectedOptions[0]?.textContent || '');
    chart_box.replaceChildren(line_chart(curves, {
      x_label: axis.vertical ? value_label : axis.label,
      y_label: axis.vertical ? axis.label : value_label,
      markers: true,
      y_down: axis.vertical,
    }));
    legend_box.replaceChildren(legend(curves));
  }
  line_pick.addEventListener('change', () => {
    fill_fields();
    draw();
  });
  field.addEventListener('change', () => {
    fill_components();
    draw();
  });
  component.addEventListener('input', draw);
  fill_fields();
  draw();
}

export async function consolidation_panel(root, href) {
  root.replaceChildren(h('p', { class: 'muted' }, 'Loading consolidation.json…'));
  let doc;
  try {
    doc = await get_json(href);
  } catch (err) {
    root.replaceChildren(notice('error', `Cannot load consolidation.json: ${err.message}`));
    return;
  }
  const time = doc.time || [];
  const degree = doc.degree || [];
  const excess = doc.average_excess_pore_pressure || [];
  const keep = time.map((t, i) => i).filter((i) => time[i] > 0);
  if (!keep.some((i) => degree[i] !== null && degree[i] !== undefined)) {
    root.replaceChildren(notice('warning', 'consolidation.json has no degree of consolidation (null in every sample: the excess at "from" was zero; see the run\'s warnings).'));
    return;
  }
  const [scale, unit] = time_unit(Math.max(...keep.map((i) => time[i])));
  const x = keep.map((i) => time[i] / scale);
  const marks = ['t50', 't90'].filter((k) => Number.isFinite(doc[k])).map((k) => `${k} = ${format_time(doc[k])}`);
  root.replaceChildren(
    h('p', { class: 'muted small', id: 'consolidation-marks' }, marks.length ? marks.join(', ') : 't50 and t90 not reached'),
    h('div', { class: 'chart-pair' },
      h('div', { class: 'chart-box', id: 'consolidation-degree' }, line_chart(
        [{ label: 'U', x, y: keep.map((i) => (degree[i] === null ? NaN : 100 * degree[i])) }],
        { x_label: `time (${unit}, log)`, y_label: 'average degree of consolidation U (%)', markers: true, y_down: true, x_log: true, width: 520 })),
      h('div', { class: 'chart-box', id: 'consolidation-excess' }, line_chart(
        [{ label: 'excess', x, y: keep.map((i) => (excess[i] === null ? NaN : excess[i] / 1000)) }],
        { x_label: `time (${unit}, log)`, y_label: 'average excess pore pressure (kPa)', markers: true, x_log: true, width: 520 }))),
  );
}
