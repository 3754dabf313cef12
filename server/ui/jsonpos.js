// Where each JSON pointer of a JSON text sits, so that a validation error
// ("/materials/bar/youngs_modulus: must be > 0") can be shown at its line.
// A tolerant scanner: on a syntax error it keeps what it found so far.

function escape(token) {
  return String(token).replace(/~/g, '~0').replace(/\//g, '~1');
}

// Map pointer -> {start, end} character offsets (start at the member's key
// for object members, at the value otherwise).
export function pointer_positions(text) {
  const map = new Map();
  let i = 0;
  const ws = () => {
    while (i < text.length && ' \t\r\n'.includes(text[i])) ++i;
  };
  const fail = () => {
    throw new SyntaxError(`unexpected ${text[i] ?? 'end'} at ${i}`);
  };
  function string() {
    const start = i++;
    while (i < text.length && text[i] !== '"') i += text[i] === '\\' ? 2 : 1;
    ++i;
    try {
      return JSON.parse(text.slice(start, i));
    } catch {
      return text.slice(start + 1, i - 1);
    }
  }
  function value(pointer, start_at) {
    ws();
    const entry = { start: start_at ?? i, end: i };
    map.set(pointer, entry);
    const c = text[i];
    if (c === '{') {
      ++i;
      ws();
      if (text[i] === '}') ++i;
      else
        for (;;) {
          ws();
          if (text[i] !== '"') fail();
          const key_start = i;
          const key = string();
          ws();
          if (text[i++] !== ':') fail();
          value(`${pointer}/${escape(key)}`, key_start);
          ws();
          if (text[i] === ',') ++i;
          else if (text[i] === '}') {
            ++i;
            break;
          } else fail();
        }
    } else if (c === '[') {
      ++i;
      ws();
      if (text[i] === ']') ++i;
      else
        for (let k = 0; ; ++k) {
          value(`${pointer}/${k}`);
          ws();
          if (text[i] === ',') ++i;
          else if (text[i] === ']') {
            ++i;
            break;
          } else fail();
        }
    } else if (c === '"') string();
    else if (c !== undefined && !',]}'.includes(c)) while (i < text.length && !' \t\r\n,]}'.includes(text[i])) ++i;
    else fail();
    entry.end = i;
  }
  try {
    value('');
  } catch {
    /* partial map */
  }
  return map;
}

// The position of `pointer`, or of its nearest ancestor present in the text
// (a missing required key is reported at the object that lacks it).
export function locate(map, pointer) {
  let p = pointer || '';
  for (;;) {
    if (map.has(p)) return { ...map.get(p), exact: p === pointer };
    if (p === '') return null;
    p = p.slice(0, p.lastIndexOf('/'));
  }
}

export function line_of(text, offset) {
  let line = 1;
  for (let k = 0; k < offset && k < text.length; ++k) if (text.charCodeAt(k) === 10) ++line;
  return line;
}
