// The dashboard's one door to the hmpm HTTP API (docs/api.md).
// Every request carries the optional bearer token kept in localStorage;
// every non-2xx answer becomes an ApiError holding the problem document
// (application/problem+json: type, title, status, detail, errors).

const TOKEN_KEY = 'hmpm.token';

export function token() {
  return localStorage.getItem(TOKEN_KEY) || '';
}

export function set_token(value) {
  if (value) localStorage.setItem(TOKEN_KEY, value);
  else localStorage.removeItem(TOKEN_KEY);
}

export function auth_headers(extra = {}) {
  const headers = { ...extra };
  const t = token();
  if (t) headers.Authorization = `Bearer ${t}`;
  return headers;
}

// A failed request: `status` (0 when the server could not be reached) and
// `problem`, the server's problem document (or a stand-in with `detail`).
export class ApiError extends Error {
  constructor(status, problem) {
    const text = problem.detail || problem.title || `HTTP ${status}`;
    super(status === 401 ? `${text} (enter the server's token in the Token field at the top)` : text);
    this.status = status;
    this.problem = problem;
  }
}

async function problem_of(response) {
  const type = response.headers.get('Content-Type') || '';
  if (type.includes('json')) {
    try {
      return await response.json();
    } catch {
      /* fall through */
    }
  }
  return { status: response.status, title: response.statusText, detail: `HTTP ${response.status} ${response.statusText}` };
}

// Sends one request; resolves with the Response when it is 2xx, rejects
// with ApiError otherwise. `body` is sent as is (a string or a Blob).
export async function request(method, path, { body, signal, headers = {} } = {}) {
  let response;
  try {
    response = await fetch(path, {
      method,
      body: body ?? (method === 'POST' ? '' : undefined),
      headers: auth_headers(headers),
      signal,
      cache: 'no-store',
    });
  } catch (err) {
    if (err.name === 'AbortError') throw err;
    throw new ApiError(0, { detail: `cannot reach the server (${err.message})` });
  }
  if (!response.ok) throw new ApiError(response.status, await problem_of(response));
  return response;
}

export async function get_json(path, options) {
  return (await request('GET', path, options)).json();
}

export async function get_text(path, options) {
  return (await request('GET', path, options)).text();
}

export async function send_json(method, path, body, options = {}) {
  const response = await request(method, path, {
    ...options,
    body,
    headers: { 'Content-Type': 'application/json' },
  });
  const text = await response.text();
  return { status: response.status, location: response.headers.get('Location'), body: text ? JSON.parse(text) : null };
}

// Reads a Server-Sent Events stream with fetch (EventSource cannot send an
// Authorization header). Calls on_event(name, data) per event; resolves when
// the stream ends, rejects with ApiError when it cannot be opened.
export async function read_events(path, on_event, signal) {
  const response = await request('GET', path, { signal, headers: { Accept: 'text/event-stream' } });
  const reader = response.body.pipeThrough(new TextDecoderStream()).getReader();
  let buffer = '';
  let name = 'message';
  let data = [];
  for (;;) {
    const { value, done } = await reader.read();
    if (done) return;
    buffer += value;
    let newline;
    while ((newline = buffer.indexOf('\n')) >= 0) {
      const line = buffer.slice(0, newline).replace(/\r$/, '');
      buffer = buffer.slice(newline + 1);
      if (line === '') {
        if (data.length) on_event(name, data.join('\n'));
        name = 'message';
        data = [];
      } else if (line.startsWith('event:')) {
        name = line.slice(6).trim();
      } else if (line.startsWith('data:')) {
        data.push(line.slice(5).replace(/^ /, ''));
      }
    }
  }
}

// Fetches a result file with the token and hands it to the browser as a
// download (a plain link cannot carry the Authorization header).
export async function download(path, name) {
  const blob = await (await request('GET', path)).blob();
  const url = URL.createObjectURL(blob);
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}
