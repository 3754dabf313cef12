// Submit page (#/submit): a spec pasted, read from a file or loaded from the
// examples (GET /ui/examples/{name}.json), checked as you type (JSON syntax
// here, then POST /validate, debounced), each error shown beside its JSON
// path and at its line; POST /jobs on submit, then the job page.

import { get_json, get_text, send_json } from '/ui/api.js';
import { h, notice, num, pretty_json } from '/ui/dom.js';
import { line_of, locate, pointer_positions } from '/ui/jsonpos.js';

const DEBOUNCE_MS = 500;
// Used when the server has no /ui/examples/index.json.
const KNOWN_EXAMPLES = ['bar-vibration', 'column-collapse', 'darcy-flow', 'embankment', 'geostatic', 'mandel', 'slope-failure', 'soft-clay', 'terzaghi'];
export const DRAFT_KEY = 'hmpm.draft';  // the editor's text, kept across visits

// The expected wall time in seconds, wherever the server puts it.
export function expected_seconds(doc) {
  const candidates = [doc?.estimate?.wall_seconds, doc?.cost?.wall_seconds, doc?.cost?.expected_wall_seconds, doc?.expected_wall_seconds];
  return candidates.find((v) => Number.isFinite(v));
}

export function render(main) {
  document.title = 'New job · hmpm';
  const examples = h('select', { id: 'example-select', 'aria-label': 'example' }, h('option', { value: '' }, 'Load an example…'));
  const file = h('input', { id: 'spec-file', type: 'file', accept: '.json,application/json', class: 'file-input' });
  const file_label = h('label', { class: 'btn', for: 'spec-file' }, 'Open file…');
  const format = h('button', { class: 'btn', id: 'format-spec', type: 'button' }, 'Format');
  const editor = h('textarea', { id: 'spec-text', spellcheck: false, wrap: 'off', autocomplete: 'off', placeholder: 'Paste a job spec (JSON) here, open a file, or load an example.' });
  const gutter = h('div', { class: 'gutter', 'aria-hidden': 'true' });
  const state = h('div', { id: 'validation-state', class: 'validation idle' }, 'Nothing to check yet.');
  const problems = h('ul', { id: 'validation-errors', class: 'problems' });
  const warnings = h('ul', { id: 'validation-warnings', class: 'problems warnings-list' });
  const cost = h('div', { id: 'validation-cost' });
  const submit = h('button', { class: 'btn btn-primary btn-large', id: 'submit-job', type: 'button' }, 'Submit job');
  const submit_message = h('div', { id: 'submit-message' });

  main.append(
    h('div', { class: 'submit-layout' },
      h('section', { class: 'card editor-card' },
        h('div', { class: 'card-head' }, h('h2', {}, 'New job'), h('div', { class: 'toolbar' }, examples, file_label, file, format)),
        h('div', { class: 'editor' }, gutter, editor)),
      h('section', { class: 'card side-card' },
        h('h3', {}, 'Validation'), state, problems, warnings, cost,
        h('div', { class: 'submit-row' }, submit), submit_message)),
  );

  let validate_available = true;
  let generation = 0;
  let debounce = null;
  let marked_lines = new Set();

  function draw_gutter() {
    const lines = editor.value.split('\n').length;
    const parts = [];
    for (let k = 1; k <= lines; ++k) parts.push(h('div', { class: marked_lines.has(k) ? 'marked' : '' }, k));
    gutter.replaceChildren(...parts);
    gutter.scrollTop = editor.scrollTop;
  }

  function reveal(range) {
    editor.focus();
    editor.setSelectionRange(range.start, range.end);
    const line = line_of(editor.value, range.start);
    const line_height = parseFloat(getComputedStyle(editor).lineHeight) || 18;
    editor.scrollTop = Math.max(0, (line - 4) * line_height);
  }

  // Renders [{path, message}] into `list`, each at its path and line.
  function show(list, items) {
    const text = editor.value;
    const map = pointer_positions(text);
    list.replaceChildren(
      ...items.map((item) => {
        const where = locate(map, item.path) || (Number.isFinite(item.offset) ? { start: item.offset, end: item.offset + 1, exact: true } : null);
        const line = where ? line_of(text, where.start) : null;
        if (line && list === problems) marked_lines.add(line);
        return h('li', { class: 'problem', 'data-path': item.path ?? '' },
          h('button', { type: 'button', class: 'path', title: 'show in the editor', onclick: () => where && reveal(where) }, item.path || '(document)'),
          h('span', { class: 'problem-message' }, item.message),
          line ? h('span', { class: 'line muted small' }, `line ${line}${where.exact ? '' : ' (inside)'}`) : null);
      }),
    );
  }

  function set_state(kind, text) {
    state.className = `validation ${kind}`;
    state.textContent = text;
  }

  function show_cost(c, estimate) {
    if (!c) {
      cost.replaceChildren();
      return;
    }
    const facts = [['particles', c.particles], ['nodes', c.nodes], ['steps', c.steps], ['time step', c.dt !== undefined ? `${num(c.dt)} s` : undefined],
      ['expected wall time', estimate !== undefined ? `${num(estimate)} s` : undefined]].filter(([, v]) => v !== undefined);
    cost.replaceChildren(h('dl', { class: 'cost' }, facts.flatMap(([k, v]) => [h('dt', {}, k), h('dd', {}, String(v))])));
  }

  function show_result(result) {
    marked_lines = new Set();
    show(problems, result.errors || []);
    show(warnings, result.warnings || []);
    show_cost(result.cost, expected_seconds(result));
    draw_gutter();
  }

  function local_syntax_error(text) {
    try {
      JSON.parse(text);
      return null;
    } catch (err) {
      const at = /position (\d+)/.exec(err.message);
      return { path: '', message: `not valid JSON: ${err.message}`, offset: at ? Number(at[1]) : undefined };
    }
  }

  async function validate() {
    const mine = ++generation;
    const text = editor.value;
    localStorage.setItem(DRAFT_KEY, text);
    submit_message.replaceChildren();
    if (!text.trim()) {
      set_state('idle', 'Nothing to check yet.');
      show_result({});
      return;
    }
    const syntax = local_syntax_error(text);
    if (syntax) {
      set_state('invalid', 'Not valid JSON.');
      show_result({ errors: [syntax] });
      return;
    }
    if (!validate_available) {
      set_state('idle', 'Valid JSON. The server checks the spec when you submit (it has no POST /validate).');
      show_result({});
      return;
    }
    set_state('checking', 'Checking…');
    let result;
    try {
      const answer = await send_json('POST', '/validate', text);
      result = { ...answer.body, errors: [] };
    } catch (err) {
      if (mine !== generation) return;
      if (err.status === 400 && err.problem.errors) {
        set_state('invalid', `${err.problem.errors.length} problem${err.problem.errors.length === 1 ? '' : 's'} in the spec.`);
        show_result({ errors: err.problem.errors });
        return;
      }
      if (err.status === 404 || err.status === 405) {
        validate_available = false;
        set_state('idle', 'Valid JSON. This server cannot check a spec before it is submitted (POST /validate answered 404); it is checked on submit.');
      } else set_state('error', `Cannot validate: ${err.message}`);
      show_result({});
      return;
    }
    if (mine !== generation) return;
    const count = (result.warnings || []).length;
    set_state('valid', count ? `Valid, with ${count} warning${count === 1 ? '' : 's'}.` : 'Valid spec.');
    show_result(result);
  }

  function changed() {
    draw_gutter();
    if (editor.value.trim()) set_state('checking', 'Checking…');
    clearTimeout(debounce);
    debounce = setTimeout(validate, DEBOUNCE_MS);
  }

  async function submit_job() {
    clearTimeout(debounce);
    const text = editor.value;
    submit.disabled = true;
    submit_message.replaceChildren(notice('info', 'Submitting…'));
    try {
      const answer = await send_json('POST', '/jobs', text);
      localStorage.removeItem(DRAFT_KEY);
      location.hash = `#/jobs/${encodeURIComponent(answer.body.jobID)}`;
    } catch (err) {
      if (err.status === 400 && err.problem.errors) {
        set_state('invalid', `The server refused the spec: ${err.problem.errors.length} problem${err.problem.errors.length === 1 ? '' : 's'}.`);
        show_result({ errors: err.problem.errors });
        submit_message.replaceChildren();
      } else submit_message.replaceChildren(notice('error', `Submit failed: ${err.message}`));
    } finally {
      submit.disabled = false;
    }
  }

  async function load_example(name) {
    try {
      editor.value = await get_text(`/ui/examples/${encodeURIComponent(name)}.json`);
      editor.scrollTop = 0;
      draw_gutter();
      validate();
    } catch (err) {
      submit_message.replaceChildren(notice('error', `Cannot load the example ${name}: ${err.message}`));
    }
  }

  async function list_examples() {
    let names = KNOWN_EXAMPLES;
    try {
      const index = await get_json('/ui/examples/index.json');
      if (Array.isArray(index) && index.length) names = index;
    } catch { /* the built-in list */ }
    examples.append(...names.map((n) => h('option', { value: n }, n)));
  }

  editor.addEventListener('input', changed);
  editor.addEventListener('scroll', () => (gutter.scrollTop = editor.scrollTop));
  editor.addEventListener('keydown', (e) => {
    if (e.key === 'Tab') {
      e.preventDefault();
      editor.setRangeText('  ', editor.selectionStart, editor.selectionEnd, 'end');
      changed();
    }
  });
  examples.addEventListener('change', () => examples.value && load_example(examples.value));
  file.addEventListener('change', async () => {
    if (!file.files.length) return;
    editor.value = await file.files[0].text();
    file.value = '';
    draw_gutter();
    validate();
  });
  format.addEventListener('click', () => {
    try {
      editor.value = pretty_json(JSON.parse(editor.value));
      changed();
    } catch { validate(); }
  });
  submit.addEventListener('click', submit_job);

  list_examples();
  editor.value = localStorage.getItem(DRAFT_KEY) || '';
  draw_gutter();
  if (editor.value) validate();
  return () => clearTimeout(debounce);
}
