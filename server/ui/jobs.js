// Job list (#/jobs): name, jobID, status, progress and age of the newest
// jobs, filtered by status and name, refreshed every 2 s. The name filter
// goes to the server (`GET /jobs?name=`); a server that refuses the
// parameter (400) or ignores it is covered by filtering here as well.

import { get_json } from '/ui/api.js';
import { STATUSES, age, h, job_id, notice, progress_bar, status_badge } from '/ui/dom.js';

const POLL_MS = 2000;

export function render(main) {
  document.title = 'Jobs · hmpm';
  const query = new URLSearchParams(location.hash.split('?')[1] || '');
  const status_select = h(
    'select',
    { id: 'filter-status', 'aria-label': 'status' },
    h('option', { value: '' }, 'all statuses'),
    h('option', { value: 'accepted,running' }, 'active'),
    STATUSES.map((s) => h('option', { value: s }, s)),
  );
  const name_input = h('input', { id: 'filter-name', type: 'search', placeholder: 'Filter by name', 'aria-label': 'name' });
  const count = h('span', { class: 'muted', id: 'job-count' });
  const message = h('div');
  const body = h('tbody', { id: 'job-rows' });
  const table = h(
    'table',
    { class: 'jobs', id: 'job-table' },
    h('thead', {}, h('tr', {}, ['Name', 'Job ID', 'Status', 'Progress', 'Age'].map((t) => h('th', {}, t)))),
    body,
  );
  main.append(
    h(
      'section',
      { class: 'card' },
      h(
        'div',
        { class: 'card-head' },
        h('h2', {}, 'Jobs'),
        h('div', { class: 'toolbar' }, status_select, name_input, count, h('a', { class: 'btn btn-primary', href: '#/submit' }, 'New job')),
      ),
      message,
      h('div', { class: 'table-wrap' }, table),
    ),
  );
  status_select.value = query.get('status') || '';
  name_input.value = query.get('name') || '';

  let server_name_filter = true;
  let timer = null;
  let stopped = false;
  let generation = 0;

  async function refresh() {
    clearTimeout(timer);
    const mine = ++generation;
    const name = name_input.value.trim();
    const params = new URLSearchParams({ limit: '200' });
    if (status_select.value) params.set('status', status_select.value);
    if (name && server_name_filter) params.set('name', name);
    try {
      let jobs;
      try {
        jobs = (await get_json(`/jobs?${params}`)).jobs;
      } catch (err) {
        if (err.status !== 400 || !params.has('name')) throw err;
        server_name_filter = false;  // an older server: filter here only
        params.delete('name');
        jobs = (await get_json(`/jobs?${params}`)).jobs;
      }
      if (mine !== generation || stopped) return;
      if (name) jobs = jobs.filter((j) => (j.name || '').toLowerCase().includes(name.toLowerCase()));
      draw(jobs);
      message.replaceChildren();
    } catch (err) {
      if (mine !== generation || stopped) return;
      message.replaceChildren(notice('error', `Cannot load the jobs: ${err.message}`));
    }
    if (!stopped) timer = setTimeout(refresh, POLL_MS);
  }

  function draw(jobs) {
    count.textContent = `${jobs.length} job${jobs.length === 1 ? '' : 's'}`;
    if (jobs.length === 0) {
      body.replaceChildren(h('tr', {}, h('td', { colspan: 5, class: 'empty' }, 'No jobs yet. ', h('a', { href: '#/submit' }, 'Submit one'), '.')));
      return;
    }
    body.replaceChildren(
      ...jobs.map((job) => {
        const href = `#/jobs/${encodeURIComponent(job.jobID)}`;
        return h(
          'tr',
          { class: 'job-row', 'data-job-id': job.jobID, 'data-status': job.status, onclick: (e) => { if (!e.target.closest('a')) location.hash = href; } },
          h('td', { class: 'job-name' }, h('a', { href }, job.name || '(unnamed)')),
          h('td', {}, job_id(job.jobID)),
          h('td', {}, status_badge(job.status)),
          h('td', { class: 'job-progress' }, progress_bar(job.progress, job.status)),
          h('td', { class: 'job-age', title: job.created }, age(job.created)),
        );
      }),
    );
  }

  function filters_changed() {
    const q = new URLSearchParams();
    if (status_select.value) q.set('status', status_select.value);
    if (name_input.value.trim()) q.set('name', name_input.value.trim());
    history.replaceState(null, '', `#/jobs${q.toString() ? `?${q}` : ''}`);
    refresh();
  }

  let debounce = null;
  status_select.addEventListener('change', filters_changed);
  name_input.addEventListener('input', () => {
    clearTimeout(debounce);
    debounce = setTimeout(filters_changed, 300);
  });
  refresh();
  return () => {
    stopped = true;
    clearTimeout(timer);
    clearTimeout(debounce);
  };
}
