// Series panel of the job page: series.json ({time, particles: [{index,
// initial_position, <field>: [value per time]}]}) as a time history of the
// chosen particles, or as a profile (value against initial position) at a
// chosen time.

import { get_json } from '/ui/api.js';
import { field_label, format_time, h, notice, num, time_unit } from '/ui/dom.js';
import { line_chart, PALETTE } from '/ui/chart.js';
import { component_names } from '/ui/vtu.js';

const AXES = ['x', 'y', 'z'];
const DEFAULT_PARTICLES = 5;

function components_of(particle, field) {
  const first = particle[field].find((v) => v !== null && v !== undefined);
  return Array.isArray(first) ? first.length : 1;
}

function value_at(row, component) {
  if (row === null || row === undefined) return NaN;
  if (!Array.isArray(row)) return Number(row);
  if (component >= 0) return Number(row[component]);
  return Math.sqrt(row.reduce((s, v) => s + v * v, 0));
}

function position_label(p) {
  return `#${p.index} (${(p.initial_position || []).map(num).join(', ')})`;
}

export async function series_panel(root, href) {
  root.replaceChildren(h('p', { class: 'muted' }, 'Loading series.json…'));
  let series;
  try {
    series = await get_json(href);
  } catch (err) {
    root.replaceChildren(notice('error', `Cannot load series.json: ${err.message}`));
    return;
  }
  const particles = series.particles || [];
  const time = series.time || [];
  if (!particles.length || !time.length) {
    root.replaceChildren(h('p', { class: 'muted' }, 'The series is empty.'));
    return;
  }
  const fields = Object.keys(particles[0]).filter((k) => k !== 'index' && k !== 'initial_position' && Array.isArray(particles[0][k]));
  const dimension = (particles[0].initial_position || [0]).length;

  const mode = h('select', { id: 'series-mode', 'aria-label': 'plot kind' }, h('option', { value: 'history' }, 'Time history'), h('option', { value: 'profile' }, 'Profile'));
  const field = h('select', { id: 'series-field', 'aria-label': 'field' }, fields.map((f) => h('option', { value: f }, f.replace(/_/g, ' '))));
  const component = h('select', { id: 'series-component', 'aria-label': 'component' });
  const axis = h('select', { id: 'series-axis', 'aria-label': 'profile axis' }, AXES.slice(0, dimension).map((a, i) => h('option', { value: i }, `along ${a}`)));
  const step = h('input', { id: 'series-time', type: 'range', min: 0, max: time.length - 1, value: time.length - 1, 'aria-label': 'time' });
  const step_label = h('span', { class: 'muted small' });
  const picks = particles.map((p, i) => h('input', { type: 'checkbox', value: i, checked: i < DEFAULT_PARTICLES, class: 'particle-pick' }));
  const particle_box = h('div', { class: 'particle-picks', id: 'series-particles' },
    particles.map((p, i) => h('label', { class: 'pick' }, picks[i], h('span', { class: 'swatch' }), position_label(p))));
  const chart_box = h('div', { class: 'chart-box', id: 'series-chart' });
  const profile_only = h('span', { class: 'profile-only' }, axis, step, step_label);

  root.replaceChildren(
    h('div', { class: 'controls' }, mode, field, component, profile_only),
    h('div', { class: 'chart-layout' }, chart_box, particle_box),
  );

  function fill_components() {
    const n = components_of(particles[0], field.value);
    const names = component_names(n);
    const previous = component.value;
    component.replaceChildren(
      ...(n === 2 || n === 3 ? [h('option', { value: -1 }, 'magnitude')] : []),
      ...names.map((c, i) => h('option', { value: i }, n === 1 ? 'value' : c)),
    );
    component.hidden = n === 1;
    // 1D vectors: the x component; tensors: the first (xx) by default
    component.value = [...component.options].some((o) => o.value === previous) ? previous : '0';
  }

  function draw() {
    const f = field.value;
    const c = Number(component.value);
    const chosen = picks.filter((p) => p.checked).map((p) => Number(p.value));
    const y_label = field_label(f, component.hidden ? '' : component.selectedOptions[0]?.textContent || '');
    profile_only.hidden = mode.value !== 'profile';
    picks.forEach((p, k) => {
      const rank = chosen.indexOf(k);
      p.parentElement.querySelector('.swatch').style.background = mode.value === 'history' && rank >= 0 ? PALETTE[rank % PALETTE.length] : 'transparent';
    });
    if (!chosen.length) {
      chart_box.replaceChildren(h('p', { class: 'muted' }, 'Choose at least one particle.'));
      return;
    }
    let lines;
    let x_label;
    if (mode.value === 'history') {
      const [scale, unit] = time_unit(time[time.length - 1]);
      lines = chosen.map((k) => ({ label: position_label(particles[k]), x: time.map((t) => t / scale), y: particles[k][f].map((row) => value_at(row, c)) }));
      x_label = `time (${unit})`;
    } else {
      const a = Number(axis.value);
      const t = Number(step.value);
      step_label.textContent = `t = ${format_time(time[t])}`;
      const ordered = [...chosen].sort((i, j) => particles[i].initial_position[a] - particles[j].initial_position[a]);
      lines = [{ label: `t = ${format_time(time[t])}`, x: ordered.map((k) => particles[k].initial_position[a]), y: ordered.map((k) => value_at(particles[k][f][t], c)) }];
      x_label = `initial ${AXES[a]} (m)`;
    }
    chart_box.replaceChildren(line_chart(lines, { x_label, y_label, markers: mode.value === 'profile' }));
  }

  mode.addEventListener('change', () => {
    if (mode.value === 'profile' && picks.filter((p) => p.checked).length < 2) picks.forEach((p) => (p.checked = true));
    draw();
  });
  field.addEventListener('change', () => {
    fill_components();
    draw();
  });
  for (const el of [component, axis, step, ...picks]) el.addEventListener('input', draw);
  fill_components();
  draw();
}
