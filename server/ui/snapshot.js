// Snapshot panel of the job page: one .vtu file's particles drawn at their
// positions (x, y; 3D is seen along z) and coloured by a chosen field.

import { get_text } from '/ui/api.js';
import { bytes, field_label, h, notice, num } from '/ui/dom.js';

const MAX_AUTO_BYTES = 64 * 1024 * 1024;  // larger snapshots load on request
import { draw_particles } from '/ui/chart.js';
import { component_names, field_values, parse_vtu } from '/ui/vtu.js';

// snapshots.pvd: file name -> time.
async function pvd_times(href) {
  const times = new Map();
  if (!href) return times;
  try {
    const doc = new DOMParser().parseFromString(await get_text(href), 'application/xml');
    for (const ds of doc.querySelectorAll('DataSet')) times.set(ds.getAttribute('file'), Number(ds.getAttribute('timestep')));
  } catch { /* names without times */ }
  return times;
}

export async function snapshot_panel(root, files, pvd_href, get_spec) {
  const times = await pvd_times(pvd_href);
  const pick = h('select', { id: 'snapshot-file', 'aria-label': 'snapshot' },
    files.map((f) => h('option', { value: f.href }, times.has(f.name) ? `t = ${num(times.get(f.name))} s · ${f.name}` : f.name)));
  pick.value = files[files.length - 1].href;
  const field = h('select', { id: 'snapshot-field', 'aria-label': 'field' });
  const component = h('select', { id: 'snapshot-component', 'aria-label': 'component' });
  const info = h('span', { class: 'muted small', id: 'snapshot-info' });
  const step = (by) => {
    const i = Math.max(0, Math.min(pick.options.length - 1, pick.selectedIndex + by));
    if (i !== pick.selectedIndex) {
      pick.selectedIndex = i;
      load();
    }
  };
  const previous = h('button', { class: 'btn', type: 'button', title: 'previous snapshot', onclick: () => step(-1) }, '◀');
  const next = h('button', { class: 'btn', type: 'button', title: 'next snapshot', onclick: () => step(1) }, '▶');
  const keep = h('input', { type: 'checkbox', id: 'snapshot-keep-range' });
  const keep_label = h('label', { class: 'small', title: 'keep the colour range when changing snapshot' }, keep, ' keep range');
  let kept = null;
  const canvas = h('canvas', { id: 'snapshot-canvas', class: 'particles' });
  const message = h('div');
  root.replaceChildren(h('div', { class: 'controls' }, previous, pick, next, field, component, keep_label, info), message, canvas);

  const cache = new Map();
  const sizes_by_href = new Map(files.map((f) => [f.href, f.size]));
  const allowed = new Set();
  let current = null;

  async function load() {
    const href = pick.value;
    message.replaceChildren();
    if (sizes_by_href.get(href) > MAX_AUTO_BYTES && !allowed.has(href)) {
      message.replaceChildren(notice('warn', `This snapshot is ${bytes(sizes_by_href.get(href))}: reading it may take a while. `),
        h('button', { class: 'btn', type: 'button', onclick: () => { allowed.add(href); load(); } }, 'Load it'));
      return;
    }
    try {
      if (!cache.has(href)) cache.set(href, parse_vtu(await get_text(href)));
    } catch (err) {
      message.replaceChildren(notice('error', `Cannot read ${href.split('/').pop()}: ${err.message}`));
      return;
    }
    current = cache.get(href);
    const previous = field.value;
    field.replaceChildren(...current.fields.map((f) => h('option', { value: f.name }, f.name.replace(/_/g, ' '))));
    const preferred = ['pore_pressure', 'displacement', 'velocity'].find((n) => current.fields.some((f) => f.name === n));
    field.value = current.fields.some((f) => f.name === previous) ? previous : preferred || current.fields[0]?.name || '';
    fill_components();
    draw();
  }

  function fill_components() {
    const f = current.fields.find((x) => x.name === field.value);
    const n = f ? f.components : 1;
    const previous = component.value;
    component.replaceChildren(
      ...(n === 3 ? [h('option', { value: -1 }, 'magnitude')] : []),
      ...component_names(n).map((c, i) => h('option', { value: i }, n === 1 ? 'value' : c)),
    );
    component.hidden = n === 1;
    component.value = [...component.options].some((o) => o.value === previous) ? previous : component.options[0].value;
  }

  function draw() {
    const f = current && current.fields.find((x) => x.name === field.value);
    if (!f) return;
    const spec = get_spec() || {};
    const dim = spec.dimension || 2;
    const volume = current.fields.find((x) => x.name === 'volume');
    const sizes = volume ? Array.from(volume.values, (v) => Math.abs(v) ** (1 / dim)) : null;
    const values = field_values(f, Number(component.value));
    const label = field_label(f.name, component.hidden ? '' : component.selectedOptions[0].textContent);
    const grid = spec.grid && spec.grid.min && spec.grid.max ? spec.grid : null;
    const range = keep.checked && kept && kept.label === label ? kept : null;
    const result = draw_particles(canvas, current.points, values, sizes, { bounds: grid, label, range });
    if (!range) kept = { label, vmin: result.vmin, vmax: result.vmax };
    canvas.dataset.drawn = result.drawn;
    info.textContent = `${current.count} particles · ${Number.isFinite(current.time) ? `t = ${num(current.time)} s · ` : ''}range ${num(result.vmin)} … ${num(result.vmax)}`;
  }

  pick.addEventListener('change', load);
  field.addEventListener('change', () => {
    fill_components();
    draw();
  });
  component.addEventListener('change', draw);
  keep.addEventListener('change', draw);
  let resize = null;
  window.addEventListener('resize', () => {
    clearTimeout(resize);
    resize = setTimeout(() => root.isConnected && draw(), 150);
  });
  await load();
}
