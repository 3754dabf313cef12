// Drawing without libraries: an SVG line chart (time histories and
// profiles of series.json) and a canvas view of snapshot particles coloured
// by a scalar, with a colour bar.

import { num } from '/ui/dom.js';

const SVG = 'http://www.w3.org/2000/svg';
export const PALETTE = ['#2563eb', '#dc2626', '#16a34a', '#9333ea', '#ea580c', '#0891b2', '#ca8a04', '#db2777', '#4b5563', '#65a30d'];

function svg(tag, attrs = {}, text) {
  const el = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) el.setAttribute(k, v);
  if (text !== undefined) el.textContent = text;
  return el;
}

// About `count` round tick values covering [lo, hi].
export function ticks(lo, hi, count = 6) {
  if (!(hi > lo)) return [lo];
  const raw = (hi - lo) / count;
  const mag = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((s) => s >= raw) || raw;
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(Math.abs(v) < step * 1e-9 ? 0 : v);
  return out;
}

function extent(values) {
  let lo = Infinity;
  let hi = -Infinity;
  for (const v of values) {
    if (Number.isFinite(v)) {
      lo = Math.min(lo, v);
      hi = Math.max(hi, v);
    }
  }
  if (lo === Infinity) return [0, 1];
  if (lo === hi) {
    const pad = Math.abs(lo) * 0.1 || 1;
    return [lo - pad, hi + pad];
  }
  const pad = (hi - lo) * 0.04;
  return [lo - pad, hi + pad];
}

// Line chart of `lines` = [{label, x: number[], y: number[]}] into an SVG
// element; `markers` draws a dot at every point (profiles); `y_down` makes
// y grow downward (depth); `x_log` puts x on a log scale (positive values
// only, decades as ticks).
export function line_chart(lines, { x_label = '', y_label = '', markers = false, y_down = false, x_log = false, width = 760, height = 360 } = {}) {
  const m = { left: 72, right: 16, top: 14, bottom: 46 };
  const w = width - m.left - m.right;
  const hgt = height - m.top - m.bottom;
  const fx = x_log ? (v) => (v > 0 ? Math.log10(v) : NaN) : (v) => v;
  lines = lines.map((l) => ({ ...l, x: l.x.map(fx) }));
  const [x0, x1] = extent(lines.flatMap((l) => l.x));
  const [y0, y1] = extent(lines.flatMap((l) => (l.y_low ? [...l.y, ...l.y_low] : l.y)));
  const sx = (v) => m.left + ((v - x0) / (x1 - x0)) * w;
  const sy = y_down ? (v) => m.top + ((v - y0) / (y1 - y0)) * hgt : (v) => m.top + hgt - ((v - y0) / (y1 - y0)) * hgt;
  const x_ticks = x_log ? ticks(Math.ceil(x0), Math.floor(x1), Math.max(1, Math.floor(x1) - Math.ceil(x0))).filter(Number.isInteger) : ticks(x0, x1);
  const root = svg('svg', { viewBox: `0 0 ${width} ${height}`, class: 'chart', role: 'img', 'aria-label': `${y_label} against ${x_label}`, 'data-y-down': y_down ? 'true' : 'false' });
  const grid = svg('g', { class: 'grid' });
  const axes = svg('g', { class: 'axis' });
  for (const t of x_ticks) {
    grid.append(svg('line', { x1: sx(t), x2: sx(t), y1: m.top, y2: m.top + hgt }));
    axes.append(svg('text', { x: sx(t), y: m.top + hgt + 16, 'text-anchor': 'middle' }, num(x_log ? 10 ** t : t)));
  }
  for (const t of ticks(y0, y1, 5)) {
    grid.append(svg('line', { x1: m.left, x2: m.left + w, y1: sy(t), y2: sy(t) }));
    axes.append(svg('text', { x: m.left - 6, y: sy(t) + 4, 'text-anchor': 'end' }, num(t)));
  }
  axes.append(svg('rect', { x: m.left, y: m.top, width: w, height: hgt, class: 'frame' }));
  axes.append(svg('text', { x: m.left + w / 2, y: height - 8, 'text-anchor': 'middle', class: 'axis-label' }, x_label));
  axes.append(svg('text', { x: 14, y: m.top + hgt / 2, 'text-anchor': 'middle', class: 'axis-label', transform: `rotate(-90 14 ${m.top + hgt / 2})` }, y_label));
  root.append(grid, axes);
  const plot = svg('g', { class: 'lines' });
  lines.forEach((line, i) => {
    const colour = line.colour || PALETTE[i % PALETTE.length];
    let d = '';
    let pen = false;
    for (let k = 0; k < line.x.length; ++k) {
      const ok = Number.isFinite(line.x[k]) && Number.isFinite(line.y[k]);
      if (ok) d += `${pen ? 'L' : 'M'}${sx(line.x[k]).toFixed(2)},${sy(line.y[k]).toFixed(2)}`;
      pen = ok;
    }
    if (line.y_low) {
      // A band between y_low and y (a fan plot's 5–95 %): filled, no outline.
      let band = '';
      const ok = (k) => Number.isFinite(line.x[k]) && Number.isFinite(line.y[k]) && Number.isFinite(line.y_low[k]);
      for (let k = 0; k < line.x.length; ++k) if (ok(k)) band += `${band ? 'L' : 'M'}${sx(line.x[k]).toFixed(2)},${sy(line.y[k]).toFixed(2)}`;
      for (let k = line.x.length - 1; k >= 0; --k) if (ok(k)) band += `L${sx(line.x[k]).toFixed(2)},${sy(line.y_low[k]).toFixed(2)}`;
      const area = svg('path', { d: `${band}Z`, fill: colour, 'fill-opacity': 0.18, stroke: 'none', class: 'band', 'data-label': line.label });
      area.append(svg('title', {}, line.label));
      plot.append(area);
      return;
    }
    const path = svg('path', { d, fill: 'none', stroke: colour, 'stroke-width': 1.8, 'data-points': line.x.length, 'data-label': line.label });
    path.append(svg('title', {}, line.label));
    plot.append(path);
    if (markers) for (let k = 0; k < line.x.length; ++k) if (Number.isFinite(line.x[k]) && Number.isFinite(line.y[k])) plot.append(svg('circle', { cx: sx(line.x[k]), cy: sy(line.y[k]), r: 2.5, fill: colour }));
  });
  root.append(plot);
  return root;
}

// Histogram of `values` as an SVG: about sqrt(n) equal bins (5 to 30)
// between the smallest and largest value, bar heights the counts.
export function histogram(values, { x_label = '', width = 760, height = 260 } = {}) {
  const m = { left: 56, right: 16, top: 14, bottom: 46 };
  const w = width - m.left - m.right;
  const hgt = height - m.top - m.bottom;
  const root = svg('svg', { viewBox: `0 0 ${width} ${height}`, class: 'chart histogram', role: 'img', 'aria-label': `histogram of ${x_label}`, 'data-samples': values.length });
  if (!values.length) return root;
  const bins = Math.max(5, Math.min(30, Math.round(Math.sqrt(values.length))));
  let lo = Math.min(...values);
  let hi = Math.max(...values);
  if (!(hi > lo)) {
    const pad = Math.abs(lo) * 0.05 || 1;
    lo -= pad;
    hi += pad;
  }
  const counts = new Array(bins).fill(0);
  for (const v of values) counts[Math.min(bins - 1, Math.floor(((v - lo) / (hi - lo)) * bins))] += 1;
  const top = Math.max(...counts);
  const sx = (v) => m.left + ((v - lo) / (hi - lo)) * w;
  const sy = (c) => m.top + hgt - (c / top) * hgt;
  const grid = svg('g', { class: 'grid' });
  const axes = svg('g', { class: 'axis' });
  for (const t of ticks(lo, hi)) axes.append(svg('text', { x: sx(t), y: m.top + hgt + 16, 'text-anchor': 'middle' }, num(t)));
  for (const t of ticks(0, top, Math.min(5, top)).filter(Number.isInteger)) {
    grid.append(svg('line', { x1: m.left, x2: m.left + w, y1: sy(t), y2: sy(t) }));
    axes.append(svg('text', { x: m.left - 6, y: sy(t) + 4, 'text-anchor': 'end' }, String(t)));
  }
  axes.append(svg('rect', { x: m.left, y: m.top, width: w, height: hgt, class: 'frame' }));
  axes.append(svg('text', { x: m.left + w / 2, y: height - 8, 'text-anchor': 'middle', class: 'axis-label' }, x_label));
  axes.append(svg('text', { x: 14, y: m.top + hgt / 2, 'text-anchor': 'middle', class: 'axis-label', transform: `rotate(-90 14 ${m.top + hgt / 2})` }, 'samples'));
  const bars = svg('g', { class: 'bars' });
  counts.forEach((c, i) => {
    const x = sx(lo + ((hi - lo) * i) / bins);
    const bar = svg('rect', { x: x + 1, y: sy(c), width: Math.max(1, w / bins - 2), height: m.top + hgt - sy(c), fill: PALETTE[0], 'data-count': c });
    bar.append(svg('title', {}, `${c} samples`));
    bars.append(bar);
  });
  root.append(grid, bars, axes);
  return root;
}

// A legend of `lines` (HTML: a swatch and the label per line).
export function legend(lines) {
  const box = document.createElement('div');
  box.className = 'legend';
  lines.forEach((line, i) => {
    const item = document.createElement('span');
    item.className = 'legend-item';
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = line.colour || PALETTE[i % PALETTE.length];
    item.append(swatch, line.label);
    box.append(item);
  });
  return box;
}

// Viridis-like colour map, t in [0, 1] -> "rgb(...)".
const STOPS = [
  [68, 1, 84], [72, 40, 120], [62, 74, 137], [49, 104, 142], [38, 130, 142],
  [31, 158, 137], [53, 183, 121], [109, 205, 89], [180, 222, 44], [253, 231, 37],
];
export function colour(t) {
  const x = Math.max(0, Math.min(1, Number.isFinite(t) ? t : 0)) * (STOPS.length - 1);
  const i = Math.min(Math.floor(x), STOPS.length - 2);
  const f = x - i;
  const c = STOPS[i].map((a, k) => Math.round(a + (STOPS[i + 1][k] - a) * f));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}

// Draws particles (points: x y z per point, sizes: a length per point or
// null) coloured by `values` on the canvas, with a colour bar on the right.
// `bounds` ({min: [x, y], max: [x, y]}) fixes the view, e.g. to the grid.
// `range` ({vmin, vmax}) fixes the colour scale, e.g. across snapshots.
export function draw_particles(canvas, points, values, sizes, { bounds = null, label = '', range = null } = {}) {
  const n = values.length;
  const bar_w = 86;
  const pad = 28;
  let [xmin, xmax] = [Infinity, -Infinity];
  let [ymin, ymax] = [Infinity, -Infinity];
  for (let i = 0; i < n; ++i) {
    xmin = Math.min(xmin, points[3 * i]);
    xmax = Math.max(xmax, points[3 * i]);
    ymin = Math.min(ymin, points[3 * i + 1]);
    ymax = Math.max(ymax, points[3 * i + 1]);
  }
  if (bounds) {
    xmin = Math.min(xmin, bounds.min[0]);
    xmax = Math.max(xmax, bounds.max[0]);
    if (bounds.min.length > 1) {
      ymin = Math.min(ymin, bounds.min[1]);
      ymax = Math.max(ymax, bounds.max[1]);
    }
  }
  const span_x = xmax - xmin || 1;
  const span_y = ymax - ymin;
  // the canvas takes the domain's aspect ratio (within limits)
  const ratio = window.devicePixelRatio || 1;
  const css_w = canvas.clientWidth || 760;
  const fit = span_y > 0 ? ((css_w - bar_w - 2 * pad) * span_y) / span_x + 2 * pad : 170;
  const css_h = Math.round(Math.max(170, Math.min(560, fit)));
  canvas.style.height = `${css_h}px`;
  canvas.width = Math.round(css_w * ratio);
  canvas.height = Math.round(css_h * ratio);
  const ctx = canvas.getContext('2d');
  ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
  ctx.clearRect(0, 0, css_w, css_h);
  const area_w = css_w - bar_w - 2 * pad;
  const area_h = css_h - 2 * pad;
  const scale = span_y > 0 ? Math.min(area_w / span_x, area_h / span_y) : area_w / span_x;
  const ox = pad + (area_w - span_x * scale) / 2;
  const oy = span_y > 0 ? pad + (area_h + span_y * scale) / 2 : css_h / 2;
  const px = (x) => ox + (x - xmin) * scale;
  const py = (y) => oy - (y - ymin) * scale;
  // domain frame
  ctx.strokeStyle = '#cbd5e1';
  ctx.lineWidth = 1;
  if (span_y > 0) ctx.strokeRect(px(xmin), py(ymax), span_x * scale, span_y * scale);
  else {
    ctx.beginPath();
    ctx.moveTo(px(xmin), oy);
    ctx.lineTo(px(xmax), oy);
    ctx.stroke();
  }
  let [vmin, vmax] = [Infinity, -Infinity];
  for (const v of values) if (Number.isFinite(v)) [vmin, vmax] = [Math.min(vmin, v), Math.max(vmax, v)];
  if (vmin === Infinity) [vmin, vmax] = [0, 1];
  if (range) [vmin, vmax] = [range.vmin, range.vmax];
  const vspan = vmax - vmin || 1;
  for (let i = 0; i < n; ++i) {
    const r = Math.max(1.5, Math.min(20, sizes ? 0.5 * sizes[i] * scale : 3));
    ctx.fillStyle = colour((values[i] - vmin) / vspan);
    ctx.beginPath();
    ctx.arc(px(points[3 * i]), py(points[3 * i + 1]), r, 0, 2 * Math.PI);
    ctx.fill();
  }
  // colour bar
  const bx = css_w - bar_w + 8;
  const by = pad;
  const bh = css_h - 2 * pad;
  for (let k = 0; k < bh; ++k) {
    ctx.fillStyle = colour(1 - k / bh);
    ctx.fillRect(bx, by + k, 14, 1);
  }
  ctx.strokeStyle = '#64748b';
  ctx.strokeRect(bx, by, 14, bh);
  ctx.fillStyle = '#334155';
  ctx.font = '11px system-ui, sans-serif';
  ctx.textAlign = 'left';
  for (const t of [0, 0.25, 0.5, 0.75, 1]) ctx.fillText(num(vmin + t * (vmax - vmin)), bx + 18, by + bh - t * bh + 4);
  ctx.save();
  ctx.translate(css_w - 4, by + bh / 2);
  ctx.rotate(-Math.PI / 2);
  ctx.textAlign = 'center';
  ctx.fillText(label, 0, 0);
  ctx.restore();
  return { vmin, vmax, drawn: n };
}
