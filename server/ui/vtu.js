// Reads the VTK XML UnstructuredGrid files hmpm writes (api/src/writers.cpp):
// inline DataArrays, format "binary" (base64 of a UInt64 byte count followed
// by the raw little-endian values, uncompressed) or "ascii". Compressed and
// appended data, which hmpm never writes, are refused with a clear error.

const TYPES = {
  Float64: Float64Array,
  Float32: Float32Array,
  Int64: BigInt64Array,
  UInt64: BigUint64Array,
  Int32: Int32Array,
  UInt32: Uint32Array,
  Int16: Int16Array,
  UInt16: Uint16Array,
  Int8: Int8Array,
  UInt8: Uint8Array,
};

function base64_bytes(text) {
  const raw = atob(text.replace(/\s+/g, ''));
  const bytes = new Uint8Array(raw.length);
  for (let i = 0; i < raw.length; ++i) bytes[i] = raw.charCodeAt(i);
  return bytes;
}

// One DataArray as {name, components, values: Float64Array}.
function read_array(el, header_bytes, little_endian) {
  const type = el.getAttribute('type');
  const components = Number(el.getAttribute('NumberOfComponents') || 1);
  const format = el.getAttribute('format') || 'ascii';
  const name = el.getAttribute('Name') || '';
  let values;
  if (format === 'ascii') {
    values = Float64Array.from(el.textContent.trim().split(/\s+/).filter(Boolean), Number);
  } else if (format === 'binary') {
    const Typed = TYPES[type];
    if (!Typed) throw new Error(`DataArray ${name}: unsupported type ${type}`);
    if (!little_endian) throw new Error('big-endian VTU files are not supported');
    const bytes = base64_bytes(el.textContent);
    const view = new DataView(bytes.buffer);
    const count = header_bytes === 8 ? Number(view.getBigUint64(0, true)) : view.getUint32(0, true);
    const body = bytes.slice(header_bytes, header_bytes + count);  // copy: aligned for the typed view
    const typed = new Typed(body.buffer, 0, Math.floor(count / Typed.BYTES_PER_ELEMENT));
    values = Float64Array.from(typed, Number);
  } else {
    throw new Error(`DataArray ${name}: format "${format}" is not supported`);
  }
  return { name, components, values };
}

// Parses a .vtu document: {time, count, points: Float64Array (3 per point),
// fields: [{name, components, values}]} with the PointData arrays.
export function parse_vtu(text) {
  const doc = new DOMParser().parseFromString(text, 'application/xml');
  const error = doc.querySelector('parsererror');
  if (error) throw new Error('not a valid XML file');
  const root = doc.documentElement;
  if (root.getAttribute('compressor')) throw new Error('compressed VTU files are not supported');
  const header_bytes = root.getAttribute('header_type') === 'UInt64' ? 8 : 4;
  const little = (root.getAttribute('byte_order') || 'LittleEndian') === 'LittleEndian';
  const piece = doc.querySelector('Piece');
  if (!piece) throw new Error('no Piece in the VTU file');
  const count = Number(piece.getAttribute('NumberOfPoints'));
  const time_el = doc.querySelector('FieldData > DataArray[Name="TimeValue"]');
  const time = time_el ? Number(time_el.textContent.trim()) : NaN;
  const points_el = piece.querySelector('Points > DataArray');
  const points = points_el ? read_array(points_el, header_bytes, little).values : new Float64Array(3 * count);
  const fields = [...piece.querySelectorAll('PointData > DataArray')].map((el) => read_array(el, header_bytes, little));
  return { time, count, points, fields };
}

// Component names of a field with n components (vectors x y z, tensors in
// Voigt order as hmpm writes them).
export function component_names(n) {
  if (n === 1) return [''];
  if (n === 2) return ['x', 'y'];
  if (n === 3) return ['x', 'y', 'z'];
  if (n === 6) return ['xx', 'yy', 'zz', 'xy', 'yz', 'zx'];
  return Array.from({ length: n }, (_, i) => String(i));
}

// The scalar a field gives per point: one component, or the magnitude
// (component = -1) of a vector.
export function field_values(field, component) {
  const { components: n, values } = field;
  const count = Math.floor(values.length / n);
  const out = new Float64Array(count);
  for (let i = 0; i < count; ++i) {
    if (component >= 0) out[i] = values[i * n + component];
    else {
      let s = 0;
      for (let c = 0; c < n; ++c) s += values[i * n + c] ** 2;
      out[i] = Math.sqrt(s);
    }
  }
  return out;
}
