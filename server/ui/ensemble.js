// Ensemble page (#/ensembles/{id}): status, progress and counts (polled),
// each sample's status (its job, from GET /jobs) and, once every sample has
// ended, the drawn values (samples.json), a fan plot of a series field of a
// series particle (median, 5–95 % band and mean over the successful
// samples, from statistics.json) and a histogram of its value at the last
// time (each successful sample's own series.json). Cancel and delete
// behind a confirmation.

import { get_json, request } from '/ui/api.js';
import { confirm_dialog, field_label, h, is_active, job_id, local_time, notice, num, progress_bar, status_badge } from '/ui/dom.js';
import { histogram, line_chart, legend } from '/ui/chart.js';

const POLL_MS = 1000;
const FAN = '#2563eb';

export function render(main, id) {
  document.title = `Ensemble ${id.slice(0, 8)} · hmpm`;
  const base = `/ensembles/${encodeURIComponent(id)}`;
  const head = h('section', { class: 'card job-head', id: 'ensemble-head' }, notice('info', 'Loading…'));
  const message = h('div', { id: 'action-message' });
  const samples_body = h('div', { id: 'ensemble-samples' });
  const fan_body = h('div', { id: 'ensemble-fan' }, h('p', { class: 'muted' }, 'The fan plot appears when every sample has ended.'));
  const hist_body = h('div', { id: 'ensemble-histogram' });
  main.append(
    h('div', { class: 'crumbs' }, h('a', { href: '#/ensembles' }, '← All ensembles')),
    head, message,
    h('section', { class: 'card' }, h('div', { class: 'card-head' }, h('h3', {}, 'Series over the samples')), fan_body, hist_body),
    h('section', { class: 'card' }, h('div', { class: 'card-head' }, h('h3', {}, 'Samples')), samples_body),
  );
  let stopped = false;
  let timer = null;
  let plotted = false;

  async function act(path, method, title, text, label) {
    if (!(await confirm_dialog(title, text, label))) return;
    try {
      await request(method, path);
      refresh();
    } catch (err) {
      message.replaceChildren(notice('error', err.message));
    }
  }

  function draw_head(e) {
    const counts = Object.entries(e.counts).filter(([, n]) => n > 0).map(([s, n]) => h('span', { class: 'count' }, status_badge(s), ` ${n}`));
    head.replaceChildren(
      h('div', { class: 'card-head' },
        h('h2', {}, 'Ensemble ', job_id(e.ensembleID)),
        h('div', { class: 'toolbar' },
          is_active(e.status) ? h('button', { class: 'btn', id: 'cancel-ensemble', onclick: () => act(`${base}/cancel`, 'POST', 'Cancel the ensemble?', 'Every sample that has not ended is cancelled; those that ended keep their results.', 'Cancel ensemble') }, 'Cancel') : '',
          h('button', { class: 'btn btn-danger', id: 'delete-ensemble', onclick: () => act(base, 'DELETE', 'Delete the ensemble?', 'Every sample is dismissed and its result files are deleted. This cannot be undone.', 'Delete ensemble') }, 'Delete'))),
      h('div', { class: 'job-status-line' }, status_badge(e.status), progress_bar(e.progress, e.status)),
      h('p', { class: 'muted', id: 'ensemble-counts' }, `${e.samples} samples, seed ${e.seed}, created ${local_time(e.created)}: `, ...counts),
    );
  }

  async function draw_samples(e) {
    const jobs = (await get_json('/jobs?limit=1000')).jobs.filter((j) => j.ensemble && j.ensemble.ensembleID === e.ensembleID);
    const by_index = new Map(jobs.map((j) => [j.ensemble.index, j]));
    let values = null;
    if (!is_active(e.status) && e.state !== 'deleted') {
      try { values = await get_json(`${base}/results/samples.json`); } catch { values = null; }
    }
    const paths = values ? values.vary : [];
    samples_body.replaceChildren(h('div', { class: 'table-wrap' }, h('table', { class: 'jobs', id: 'sample-table' },
      h('thead', {}, h('tr', {}, ['#', 'Job', 'Status', 'Progress', ...paths].map((t) => h('th', {}, t)))),
      h('tbody', {}, ...e.jobs.map((jid, k) => {
        const j = by_index.get(k);
        const status = j ? j.status : '?';
        const v = values && values.samples[k] ? values.samples[k].values : {};
        return h('tr', { class: 'job-row', 'data-status': status },
          h('td', {}, String(k)),
          h('td', {}, h('a', { href: `#/jobs/${encodeURIComponent(jid)}` }, job_id(jid))),
          h('td', {}, status_badge(status)),
          h('td', { class: 'job-progress' }, progress_bar(j ? j.progress : 0, status)),
          ...paths.map((p) => h('td', {}, num(v[p]))));
      })))));
  }

  async function draw_plots(e) {
    const stats = await get_json(`${base}/results/statistics.json`);
    if (!stats.particles.length) {
      fan_body.replaceChildren(h('p', { class: 'muted' }, 'No successful sample with a series.'));
      return;
    }
    const particle = h('select', { id: 'fan-particle', 'aria-label': 'particle' }, stats.particles.map((p, i) => h('option', { value: i }, `particle ${p.index}`)));
    const fields = Object.keys(stats.particles[0]).filter((k) => stats.particles[0][k] && stats.particles[0][k].mean);
    const field = h('select', { id: 'fan-field', 'aria-label': 'field' }, fields.map((f) => h('option', { value: f }, f)));
    const chart = h('div');
    const hist = h('div');
    const series_cache = new Map();
    async function final_values(p, f) {
      const out = [];
      for (const jid of e.jobs) {
        if (!series_cache.has(jid)) {
          try { series_cache.set(jid, await get_json(`/jobs/${encodeURIComponent(jid)}/results/series.json`)); } catch { series_cache.set(jid, null); }
        }
        const s = series_cache.get(jid);
        const history = s && s.particles[p] && s.particles[p][f];
        if (!history || !history.length) continue;
        const v = history[history.length - 1];
        out.push(Array.isArray(v) ? v[0] : v);
      }
      return out.filter(Number.isFinite);
    }
    async function draw() {
      const p = Number(particle.value);
      const f = field.value;
      const fig = stats.particles[p][f];
      const pick = (column) => column.map((v) => (Array.isArray(v) ? v[0] : v) ?? NaN);
      const lines = [
        { label: '5–95 %', x: stats.time, y: pick(fig.p95), y_low: pick(fig.p05), colour: FAN },
        { label: 'median', x: stats.time, y: pick(fig.p50), colour: FAN },
        { label: 'mean', x: stats.time, y: pick(fig.mean), colour: '#dc2626' },
      ];
      const label = field_label(f, Array.isArray(fig.mean[0]) ? 'x' : '');
      chart.replaceChildren(line_chart(lines, { x_label: 'time (s)', y_label: label }), legend(lines),
        h('p', { class: 'muted small' }, `${stats.samples} successful samples`));
      const values = await final_values(p, f);
      hist.replaceChildren(h('h4', {}, `${label} at t = ${num(stats.time[stats.time.length - 1])} s`), histogram(values, { x_label: label }));
    }
    particle.addEventListener('change', draw);
    field.addEventListener('change', draw);
    fan_body.replaceChildren(h('div', { class: 'toolbar' }, particle, field), chart);
    hist_body.replaceChildren(hist);
    await draw();
  }

  async function refresh() {
    clearTimeout(timer);
    try {
      const e = await get_json(base);
      if (stopped) return;
      draw_head(e);
      await draw_samples(e);
      if (!is_active(e.status) && e.state !== 'deleted' && !plotted) {
        plotted = true;
        await draw_plots(e);
      }
      if (is_active(e.status)) timer = setTimeout(refresh, POLL_MS);
    } catch (err) {
      if (!stopped) message.replaceChildren(notice('error', `Cannot load the ensemble: ${err.message}`));
    }
  }
  refresh();
  return () => {
    stopped = true;
    clearTimeout(timer);
  };
}
