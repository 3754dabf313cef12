// Job page (#/jobs/{id}): status and progress (live from the event stream,
// polling when the stream is unavailable), warnings, the log tail, plots
// of series.json, a snapshot view, the result files, the spec, and cancel
// and delete behind a confirmation.

import { download, get_json, get_text, read_events, request, token } from '/ui/api.js';
import { bytes, confirm_dialog, duration, h, is_active, job_id, local_time, notice, format_time, num, pretty_json, progress_bar, status_badge } from '/ui/dom.js';
import { series_panel } from '/ui/series.js';
import { consolidation_panel, profiles_panel } from '/ui/profiles.js';
import { snapshot_panel } from '/ui/snapshot.js';
import { DRAFT_KEY, expected_seconds } from '/ui/submit.js';

const LOG_POLL_MS = 2000;
const STATUS_POLL_MS = 1000;
const LOG_TAIL_LINES = 400;

export function render(main, id) {
  const base = `/jobs/${encodeURIComponent(id)}`;
  const abort = new AbortController();
  let job = null;
  let stopped = false;
  let timers = [];
  let results_loaded = false;
  let spec = null;
  let spec_text = '';

  const head = h('section', { class: 'card job-head', id: 'job-head' }, notice('info', 'Loading…'));
  const warnings = h('div', { id: 'job-warnings' });
  const action_message = h('div', { id: 'action-message' });
  const results_body = h('div', { id: 'results' }, h('p', { class: 'muted' }, 'Result files appear when the job has finished.'));
  const series_body = h('div', { id: 'series' }, h('p', { class: 'muted' }, 'Plots appear when the job has finished.'));
  const snapshot_body = h('div', { id: 'snapshot' }, h('p', { class: 'muted' }, 'Snapshots appear when the job has finished.'));
  const log_pre = h('pre', { class: 'log', id: 'job-log' }, '');
  const log_note = h('div', { class: 'muted small', id: 'log-note' });
  const spec_pre = h('pre', { class: 'json', id: 'job-spec' }, '…');

  // shown once the job has results
  const series_card = h('section', { class: 'card', hidden: true }, h('div', { class: 'card-head' }, h('h3', {}, 'Series')), series_body);
  const snapshot_card = h('section', { class: 'card', hidden: true }, h('div', { class: 'card-head' }, h('h3', {}, 'Snapshot')), snapshot_body);
  // shown when the job wrote profiles.json / consolidation.json
  const profiles_body = h('div', { id: 'profiles' });
  const profiles_card = h('section', { class: 'card', hidden: true, id: 'profiles-card' }, h('div', { class: 'card-head' }, h('h3', {}, 'Profiles')), profiles_body);
  const consolidation_body = h('div', { id: 'consolidation' });
  const consolidation_card = h('section', { class: 'card', hidden: true, id: 'consolidation-card' }, h('div', { class: 'card-head' }, h('h3', {}, 'Consolidation')), consolidation_body);

  main.append(
    h('div', { class: 'crumbs' }, h('a', { href: '#/jobs' }, '← All jobs')),
    head,
    action_message,
    warnings,
    series_card,
    profiles_card,
    consolidation_card,
    snapshot_card,
    h('div', { class: 'two-col' },
      h('section', { class: 'card' }, h('div', { class: 'card-head' }, h('h3', {}, 'Result files')), results_body),
      h('section', { class: 'card' }, h('div', { class: 'card-head' }, h('h3', {}, 'Log'), log_note), log_pre)),
    h('section', { class: 'card' }, h('details', { open: true }, h('summary', {}, h('h3', { class: 'inline' }, 'Spec')), spec_pre)),
  );

  function later(fn, ms) {
    const t = setTimeout(() => {
      timers = timers.filter((x) => x !== t);
      if (!stopped) fn();
    }, ms);
    timers.push(t);
  }

  function fact(label, value) {
    return h('div', { class: 'fact' }, h('div', { class: 'fact-label' }, label), h('div', { class: 'fact-value' }, value));
  }

  // Steps and time step: what ran (the status document's `run`, once the
  // job has run) or, before, the estimate (`cost`), labelled as such.
  function run_facts(doc) {
    const run = doc.run;
    const cost = doc.cost || {};
    if (run && run.steps > 0) {
      const range = run.dt_max > 0 ? (num(run.dt_min) === num(run.dt_max) ? `${num(run.dt_min)} s` : `${num(run.dt_min)} – ${num(run.dt_max)} s`) : '—';
      return [
        fact(is_active(doc.status) ? 'Steps so far' : 'Steps run', h('span', { id: 'job-steps', 'data-source': 'run' }, String(run.steps))),
        fact('Time step', h('span', { id: 'job-dt', 'data-source': 'run' }, range)),
        fact('Simulated', h('span', { id: 'job-simulated' }, `${format_time(run.simulated_time)} of ${format_time(run.end_time)}`)),
      ];
    }
    return [
      fact('Steps (estimate)', h('span', { id: 'job-steps', 'data-source': 'estimate' }, cost.steps ?? '—')),
      fact('First time step', h('span', { id: 'job-dt', 'data-source': 'estimate' }, cost.dt !== undefined ? `${num(cost.dt)} s` : '—')),
      ...(doc.queue_position ? [fact('Queue position', h('span', { id: 'job-queue-position' }, String(doc.queue_position)))] : []),
    ];
  }

  function draw_head() {
    document.title = `${job.name || job.jobID.slice(0, 8)} · ${job.status} · hmpm`;
    const cancel = h('button', { class: 'btn', id: 'cancel-job', disabled: !is_active(job.status), onclick: cancel_job }, 'Cancel');
    const remove = h('button', { class: 'btn btn-danger', id: 'delete-job', disabled: job.status === 'dismissed', onclick: delete_job }, 'Delete');
    const again = h('button', { class: 'btn', id: 'edit-job', disabled: !spec_text, onclick: edit_again, title: 'open this spec on the submit page' }, 'Edit & resubmit');
    const cost = job.cost || {};
    head.replaceChildren(
      h('div', { class: 'job-title' },
        h('div', {}, h('h2', { id: 'job-name' }, job.name || '(unnamed)'), h('div', { class: 'muted' }, 'Job ', h('span', { id: 'job-id' }, job_id(job.jobID)))),
        h('div', { class: 'actions' }, again, cancel, remove)),
      h('div', { class: 'job-status-row' },
        h('span', { id: 'job-status' }, status_badge(job.status)),
        h('div', { class: 'grow', id: 'job-progress' }, progress_bar(job.progress, job.status)),
        h('span', { class: 'muted', id: 'job-message' }, job.reason || job.message || '')),
      h('div', { class: 'facts' },
        fact('Created', local_time(job.created)),
        fact('Started', local_time(job.started)),
        fact('Finished', local_time(job.finished)),
        fact('Run time', duration(job.run_seconds)),
        is_active(job.status) && expected_seconds(job) !== undefined ? fact('Expected (estimate)', duration(expected_seconds(job))) : null,
        fact('Particles', cost.particles ?? '—'),
        ...run_facts(job)),
        fact('Attempts', job.attempts ?? '—'),
    );
    const list = job.warnings || [];
    warnings.replaceChildren(
      ...(list.length
        ? [h('section', { class: 'card warnings' }, h('h3', {}, `Warnings (${list.length})`),
            h('ul', { class: 'problems' }, list.map((w) => h('li', { class: 'problem', 'data-path': w.path }, h('code', { class: 'path' }, w.path || '/'), h('span', {}, w.message)))))]
        : []),
    );
  }

  function update(doc) {
    const was_active = job ? is_active(job.status) : true;
    job = doc;
    draw_head();
    if (!is_active(job.status) && (was_active || !results_loaded)) finished();
  }

  function finished() {
    if (results_loaded) return;
    results_loaded = true;
    load_results();
    load_log();
  }

  async function load_job() {
    try {
      update(await get_json(base, { signal: abort.signal }));
    } catch (err) {
      if (err.name === 'AbortError') return;
      head.replaceChildren(notice('error', err.status === 404 ? `No job ${id} on this server.` : `Cannot load the job: ${err.message}`));
      return;
    }
    load_spec();
    if (is_active(job.status)) {
      watch();
      load_log();
    }
  }

  async function watch() {
    try {
      await read_events(`${base}/events`, (name, data) => {
        try {
          head.dataset.live = 'events';  // where the progress comes from (tests read it)
          update(JSON.parse(data));
        } catch { /* a malformed event: the next one or the poll repairs it */ }
      }, abort.signal);
      if (!stopped) update(await get_json(base, { signal: abort.signal }));
    } catch (err) {
      if (err.name === 'AbortError' || stopped) return;
      poll();  // 503 too-many-streams, a proxy without streaming, ...
      return;
    }
    if (is_active(job.status)) later(watch, STATUS_POLL_MS);
  }

  async function poll() {
    try {
      head.dataset.live = 'poll';
      update(await get_json(base, { signal: abort.signal }));
    } catch (err) {
      if (err.name === 'AbortError') return;
    }
    if (is_active(job.status)) later(poll, STATUS_POLL_MS);
  }

  async function load_spec() {
    try {
      const text = await get_text(`${base}/spec`, { signal: abort.signal });
      spec_text = text;
      if (job) draw_head();
      try {
        spec = JSON.parse(text);
        // the bytes as submitted when a person laid them out, else indented
        spec_pre.textContent = text.trim().includes('\n') ? text : pretty_json(spec);
      } catch {
        spec_pre.textContent = text;
      }
    } catch (err) {
      if (err.name !== 'AbortError') spec_pre.textContent = `Cannot load the spec: ${err.message}`;
    }
  }

  let log_missing = false;
  async function load_log() {
    if (log_missing) return;
    try {
      const text = await get_text(`${base}/log`, { signal: abort.signal });
      const lines = text.split('\n');
      const tail = lines.length > LOG_TAIL_LINES ? lines.slice(-LOG_TAIL_LINES) : lines;
      const at_bottom = log_pre.scrollTop + log_pre.clientHeight >= log_pre.scrollHeight - 4;
      log_pre.textContent = tail.join('\n') || '(empty)';
      if (at_bottom) log_pre.scrollTop = log_pre.scrollHeight;
      log_note.textContent = lines.length > LOG_TAIL_LINES ? `last ${LOG_TAIL_LINES} of ${lines.length} lines` : '';
    } catch (err) {
      if (err.name === 'AbortError') return;
      if (err.status === 404) {
        log_missing = true;
        log_pre.hidden = true;
        log_note.textContent = 'This server has no job log (GET /jobs/{id}/log answered 404).';
        return;
      }
      log_note.textContent = `Cannot load the log: ${err.message}`;
    }
    if (job && is_active(job.status)) later(load_log, LOG_POLL_MS);
  }

  async function load_results() {
    let manifest;
    try {
      manifest = await get_json(`${base}/results`, { signal: abort.signal });
    } catch (err) {
      if (err.name === 'AbortError') return;
      const text = err.status === 410 ? 'The job was dismissed: its result files are deleted.' : `No results: ${err.message}`;
      results_body.replaceChildren(h('p', { class: 'muted' }, text));
      series_card.hidden = snapshot_card.hidden = profiles_card.hidden = consolidation_card.hidden = true;
      return;
    }
    const files = manifest.files || [];
    series_card.hidden = snapshot_card.hidden = false;
    results_body.replaceChildren(
      h('table', { class: 'files', id: 'result-files' },
        h('thead', {}, h('tr', {}, h('th', {}, 'File'), h('th', { class: 'num' }, 'Size'), h('th', {}, 'Type'))),
        h('tbody', {}, files.map((f) => h('tr', {},
          h('td', {}, h('a', { href: f.href, download: f.name, class: 'download', onclick: (e) => download_click(e, f) }, f.name)),
          h('td', { class: 'num' }, bytes(f.size)),
          h('td', { class: 'muted' }, f.media_type || ''))))),
    );
    const href = (name) => (files.find((f) => f.name === name) || {}).href;
    if (href('series.json')) series_panel(series_body, href('series.json'), () => spec);
    else series_body.replaceChildren(h('p', { class: 'muted' }, 'This job wrote no series (output.series in the spec).'));
    const vtus = files.filter((f) => f.name.endsWith('.vtu'));
    profiles_card.hidden = !href('profiles.json');
    if (href('profiles.json')) profiles_panel(profiles_body, href('profiles.json'));
    consolidation_card.hidden = !href('consolidation.json');
    if (href('consolidation.json')) consolidation_panel(consolidation_body, href('consolidation.json'));
    if (vtus.length) snapshot_panel(snapshot_body, vtus, href('snapshots.pvd'), () => spec);
    else snapshot_body.replaceChildren(h('p', { class: 'muted' }, 'This job wrote no snapshots (output.snapshots in the spec).'));
  }

  function download_click(event, file) {
    if (!token()) return;  // a plain link works
    event.preventDefault();
    download(file.href, file.name).catch((err) => action_message.replaceChildren(notice('error', `Download failed: ${err.message}`)));
  }

  function edit_again() {
    localStorage.setItem(DRAFT_KEY, spec_text);  // the submit page opens its draft
    location.hash = '#/submit';
  }

  async function cancel_job() {
    if (!(await confirm_dialog('Cancel this job?', `Job ${job.name || ''} (${job.jobID.slice(0, 8)}) stops; whatever it wrote so far stays downloadable.`, 'Cancel job'))) return;
    try {
      const response = await request('POST', `${base}/cancel`);
      update(await response.json());
      action_message.replaceChildren(notice('info', 'The job was cancelled.'));
    } catch (err) {
      if (err.status === 409) action_message.replaceChildren(notice('warn', `Not cancelled (the job has ended; nothing changed): ${err.message}`));
      else if (err.status === 404 || err.status === 405) action_message.replaceChildren(notice('warn', 'This server has no separate cancel (POST /jobs/{id}/cancel); Delete stops the job and deletes its results.'));
      else action_message.replaceChildren(notice('error', `Cancel failed: ${err.message}`));
      load_job_quietly();
    }
  }

  async function delete_job() {
    if (!(await confirm_dialog('Delete this job?', `Job ${job.name || ''} (${job.jobID.slice(0, 8)}) is dismissed and its result files are deleted. This cannot be undone.`, 'Delete job'))) return;
    try {
      const response = await request('DELETE', base);
      results_loaded = false;
      update(await response.json());
      action_message.replaceChildren(notice('info', 'The job was dismissed and its results deleted.'));
    } catch (err) {
      action_message.replaceChildren(notice('error', `Delete failed: ${err.message}`));
    }
  }

  async function load_job_quietly() {
    try {
      update(await get_json(base, { signal: abort.signal }));
    } catch { /* the page keeps what it shows */ }
  }

  load_job();
  return () => {
    stopped = true;
    abort.abort();
    timers.forEach(clearTimeout);
  };
}
