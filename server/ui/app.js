// The dashboard's entry point: hash routing (#/jobs, #/jobs/{id}, #/submit,
// #/ensembles, #/ensembles/{id}),
// the header's token field and the server health dot. Each page module
// exports render(main, params) returning an optional cleanup function,
// called when the route changes (to stop polling and event streams).

import { get_json, set_token, token } from '/ui/api.js';
import { set_field_units } from '/ui/dom.js';
import * as job_list from '/ui/jobs.js';
import * as job_page from '/ui/job.js';
import * as ensemble_list from '/ui/ensembles.js';
import * as ensemble_page from '/ui/ensemble.js';
import * as submit_page from '/ui/submit.js';

const routes = [
  [/^#\/jobs\/([^/]+)$/, job_page, 'jobs'],
  [/^#\/submit$/, submit_page, 'submit'],
  [/^#\/jobs$/, job_list, 'jobs'],
  [/^#\/ensembles\/([^/]+)$/, ensemble_page, 'ensembles'],
  [/^#\/ensembles$/, ensemble_list, 'ensembles'],
];

let cleanup = null;

function route() {
  const hash = location.hash || '#/jobs';
  const match = routes.find(([pattern]) => pattern.test(hash));
  if (!match) {
    location.replace('#/jobs');
    return;
  }
  const [pattern, page, nav] = match;
  if (cleanup) cleanup();
  const main = document.getElementById('main');
  main.replaceChildren();
  main.dataset.page = nav === 'jobs' && page === job_page ? 'job' : nav;
  for (const a of document.querySelectorAll('[data-nav]')) a.classList.toggle('active', a.dataset.nav === nav);
  const params = hash.match(pattern).slice(1).map(decodeURIComponent);
  cleanup = page.render(main, ...params) || null;
  window.scrollTo(0, 0);
}

async function check_health() {
  const dot = document.getElementById('health');
  try {
    const body = await get_json('/health');
    dot.className = `health health-${body.status === 'ok' ? 'ok' : 'bad'}`;
    dot.textContent = body.status === 'ok' ? 'server ok' : body.status;
  } catch (err) {
    dot.className = 'health health-bad';
    dot.textContent = err.status ? `server ${err.status}` : 'offline';
  }
}

function setup_token() {
  const form = document.getElementById('token-form');
  const input = document.getElementById('token-input');
  input.value = token();
  form.addEventListener('submit', (event) => {
    event.preventDefault();
    set_token(input.value.trim());
    route();
  });
}

// The fields' units (GET /fields, no token) label every plot; a page drawn
// without them would show bare field names, so the first route waits (a
// failure only leaves the units out).
async function load_field_units() {
  try {
    set_field_units(await get_json('/fields'));
  } catch (err) {
    console.warn('GET /fields failed: plots carry no units', err);
  }
}

setup_token();
window.addEventListener('hashchange', route);
await load_field_units();
route();
check_health();
setInterval(check_health, 15000);
