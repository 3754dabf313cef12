// Small DOM and formatting helpers shared by the pages.

// h('div', {class: 'x', onclick: f}, child, 'text', ...) builds an element.
// Attributes starting with "on" become listeners; null/false ones are skipped.
export function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [key, value] of Object.entries(attrs || {})) {
    if (value === null || value === undefined || value === false) continue;
    if (key.startsWith('on')) el.addEventListener(key.slice(2), value);
    else if (key === 'class') el.className = value;
    else if (key in el && typeof value !== 'string') el[key] = value;
    else el.setAttribute(key, value === true ? '' : value);
  }
  for (const child of children.flat()) {
    if (child === null || child === undefined || child === false) continue;
    el.append(child instanceof Node ? child : String(child));
  }
  return el;
}

// Units for axis and colour-bar labels. The output fields' units come from
// the server (GET /fields, the solver's table; app.js loads them before the
// first page); the snapshots' extra arrays, which are not output fields, are
// named here. A dimensionless unit ('-') is not shown.
const units = { volume: 'm³', material: '' };

// Takes GET /fields: {fields: [{name, kind, unit}, ...]}.
export function set_field_units(doc) {
  for (const f of doc?.fields || []) if (typeof f.name === 'string' && typeof f.unit === 'string') units[f.name] = f.unit === '-' ? '' : f.unit;
}

// "pore pressure (Pa)", "velocity x (m/s)".
export function field_label(name, component = '') {
  const unit = units[name];
  return `${name.replace(/_/g, ' ')}${component ? ` ${component}` : ''}${unit ? ` (${unit})` : ''}`;
}

// The unit that reads best for times up to `span` seconds (as the Python
// client's units.time_unit): s below 2 min, min below 2 h, h below 2 days,
// days below a year, then years. Returns [seconds per unit, name].
export function time_unit(span) {
  const s = Math.abs(Number(span)) || 0;
  const rows = [[1, 's', 0], [60, 'min', 120], [3600, 'h', 7200], [86400, 'days', 172800], [31557600, 'years', 31557600]];
  let best = rows[0];
  for (const row of rows) if (s >= row[2]) best = row;
  return [best[0], best[1]];
}

// "10 days", "1.5 years", "30 s": `t` in the unit that reads best for it.
export function format_time(t) {
  const [scale, name] = time_unit(t);
  return `${num(t / scale)} ${name}`;
}

export const STATUSES = ['accepted', 'running', 'successful', 'failed', 'dismissed'];

export function is_active(status) {
  return status === 'accepted' || status === 'running';
}

export function status_badge(status) {
  return h('span', { class: `badge status-${status}`, 'data-status': status }, status);
}

export function progress_bar(progress, status) {
  const value = Math.max(0, Math.min(100, Math.round(progress || 0)));
  return h(
    'div',
    { class: `progress status-${status}`, role: 'progressbar', 'aria-valuenow': value, 'aria-valuemin': 0, 'aria-valuemax': 100 },
    h('div', { class: 'progress-fill', style: `width: ${value}%` }),
    h('span', { class: 'progress-label' }, `${value}%`),
  );
}

// "f44c0cb9" bold, then the rest of the id muted: the full id stays in the
// page (and is copied whole), the prefix is what the eye reads.
export function job_id(id) {
  return h('code', { class: 'job-id', title: id }, h('span', { class: 'id-prefix' }, id.slice(0, 8)), h('span', { class: 'id-rest' }, id.slice(8)));
}

export function age(iso) {
  if (!iso) return '';
  const seconds = (Date.now() - Date.parse(iso)) / 1000;
  if (!Number.isFinite(seconds)) return '';
  if (seconds < 5) return 'just now';
  if (seconds < 60) return `${Math.floor(seconds)} s ago`;
  if (seconds < 3600) return `${Math.floor(seconds / 60)} min ago`;
  if (seconds < 86400) return `${Math.floor(seconds / 3600)} h ago`;
  return `${Math.floor(seconds / 86400)} d ago`;
}

// "2026-12-02 01:01:41" in the browser's time zone.
export function local_time(iso) {
  if (!iso) return '—';
  const d = new Date(iso);
  if (Number.isNaN(d.getTime())) return iso;
  const p = (n) => String(n).padStart(2, '0');
  return `${d.getFullYear()}-${p(d.getMonth() + 1)}-${p(d.getDate())} ${p(d.getHours())}:${p(d.getMinutes())}:${p(d.getSeconds())}`;
}

// JSON with two-space indentation, arrays of numbers and strings on one line.
export function pretty_json(value, indent = '') {
  const inner = `${indent}  `;
  if (Array.isArray(value)) {
    if (value.every((v) => v === null || typeof v !== 'object')) return `[${value.map((v) => JSON.stringify(v)).join(', ')}]`;
    return `[\n${value.map((v) => inner + pretty_json(v, inner)).join(',\n')}\n${indent}]`;
  }
  if (value && typeof value === 'object') {
    const keys = Object.keys(value);
    if (!keys.length) return '{}';
    return `{\n${keys.map((k) => `${inner}${JSON.stringify(k)}: ${pretty_json(value[k], inner)}`).join(',\n')}\n${indent}}`;
  }
  return JSON.stringify(value);
}

export function bytes(n) {
  if (n === undefined || n === null) return '';
  if (n < 1024) return `${n} B`;
  if (n < 1024 * 1024) return `${(n / 1024).toFixed(1)} KiB`;
  if (n < 1024 ** 3) return `${(n / 1024 / 1024).toFixed(1)} MiB`;
  return `${(n / 1024 ** 3).toFixed(2)} GiB`;
}

export function duration(seconds) {
  if (seconds === undefined || seconds === null) return '—';
  if (seconds < 1) return `${(seconds * 1000).toFixed(0)} ms`;
  if (seconds < 120) return `${seconds.toFixed(1)} s`;
  return `${Math.floor(seconds / 60)} min ${Math.round(seconds % 60)} s`;
}

// Short number for axis labels and colour bars.
export function num(v) {
  if (!Number.isFinite(v)) return String(v);
  const a = Math.abs(v);
  if (a !== 0 && (a < 1e-3 || a >= 1e5)) return v.toExponential(2);
  return Number(v.toPrecision(4)).toString();
}

export function notice(kind, text) {
  return h('div', { class: `notice notice-${kind}`, role: kind === 'error' ? 'alert' : 'status' }, text);
}

// A modal confirmation; resolves true when the user confirms.
export function confirm_dialog(title, text, action) {
  return new Promise((resolve) => {
    const dialog = h(
      'dialog',
      { class: 'confirm' },
      h('h3', {}, title),
      h('p', {}, text),
      h(
        'form',
        { method: 'dialog', class: 'dialog-actions' },
        h('button', { value: 'cancel', class: 'btn', id: 'confirm-no' }, 'Keep'),
        h('button', { value: 'ok', class: 'btn btn-danger', id: 'confirm-yes' }, action),
      ),
    );
    dialog.addEventListener('close', () => {
      resolve(dialog.returnValue === 'ok');
      dialog.remove();
    });
    document.body.append(dialog);
    dialog.showModal();
  });
}
