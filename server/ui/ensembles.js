// Ensemble list (#/ensembles): id, status, progress, samples and age of the
// newest ensembles, refreshed every 2 s (GET /ensembles).

import { get_json } from '/ui/api.js';
import { age, h, job_id, notice, progress_bar, status_badge } from '/ui/dom.js';

const POLL_MS = 2000;

export function render(main) {
  document.title = 'Ensembles · hmpm';
  const message = h('div');
  const body = h('tbody', { id: 'ensemble-rows' });
  main.append(
    h('section', { class: 'card' },
      h('div', { class: 'card-head' }, h('h2', {}, 'Ensembles')),
      message,
      h('div', { class: 'table-wrap' },
        h('table', { class: 'jobs', id: 'ensemble-table' },
          h('thead', {}, h('tr', {}, ['Ensemble ID', 'Status', 'Progress', 'Samples', 'Age'].map((t) => h('th', {}, t)))),
          body))),
  );
  let timer = null;
  let stopped = false;
  async function refresh() {
    try {
      const list = (await get_json('/ensembles?limit=200')).ensembles;
      if (stopped) return;
      message.replaceChildren();
      body.replaceChildren(...(list.length === 0
        ? [h('tr', {}, h('td', { colspan: 5, class: 'empty' }, 'No ensembles yet (POST /ensembles, or the Python client\'s ensemble submit).'))]
        : list.map((e) => {
          const href = `#/ensembles/${encodeURIComponent(e.ensembleID)}`;
          return h('tr', { class: 'job-row', 'data-ensemble-id': e.ensembleID, 'data-status': e.status, onclick: () => { location.hash = href; } },
            h('td', {}, h('a', { href }, job_id(e.ensembleID))),
            h('td', {}, status_badge(e.status)),
            h('td', { class: 'job-progress' }, progress_bar(e.progress, e.status)),
            h('td', {}, `${e.counts.successful}/${e.samples} successful`),
            h('td', { class: 'job-age', title: e.created }, age(e.created)));
        })));
    } catch (err) {
      if (!stopped) message.replaceChildren(notice('error', `Cannot load the ensembles: ${err.message}`));
    }
    if (!stopped) timer = setTimeout(refresh, POLL_MS);
  }
  refresh();
  return () => {
    stopped = true;
    clearTimeout(timer);
  };
}
