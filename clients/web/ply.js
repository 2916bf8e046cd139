// Reads a PLY file (binary little-endian, as salientd writes saliency.ply, or ASCII): vertex
// positions, the per-vertex saliency (`quality`) and the triangles (polygons fanned).

const TYPES = {
  char: ['getInt8', 1], int8: ['getInt8', 1], uchar: ['getUint8', 1], uint8: ['getUint8', 1],
  short: ['getInt16', 2], int16: ['getInt16', 2], ushort: ['getUint16', 2], uint16: ['getUint16', 2],
  int: ['getInt32', 4], int32: ['getInt32', 4], uint: ['getUint32', 4], uint32: ['getUint32', 4],
  float: ['getFloat32', 4], float32: ['getFloat32', 4], double: ['getFloat64', 8], float64: ['getFloat64', 8],
};

function parseHeader(bytes) {
  const text = new TextDecoder('latin1').decode(bytes.subarray(0, Math.min(bytes.length, 4096)));
  const end = text.indexOf('end_header');
  if (!text.startsWith('ply') || end < 0) throw new Error('saliency.ply is not a PLY file');
  const elements = [];
  let format = '';
  for (const line of text.slice(0, end).split(/\r?\n/)) {
    const w = line.trim().split(/\s+/);
    if (w[0] === 'format') format = w[1];
    else if (w[0] === 'element') elements.push({ name: w[1], count: Number(w[2]), props: [] });
    else if (w[0] === 'property' && elements.length) {
      const e = elements[elements.length - 1];
      if (w[1] === 'list') e.props.push({ name: w[4], list: true, countType: w[2], type: w[3] });
      else e.props.push({ name: w[2], type: w[1] });
    }
  }
  const nl = text.indexOf('\n', end);
  return { format, elements, offset: nl + 1 };
}

export function parsePly(buffer) {
  const bytes = new Uint8Array(buffer);
  const { format, elements, offset } = parseHeader(bytes);
  const vertex = elements.find((e) => e.name === 'vertex');
  const face = elements.find((e) => e.name === 'face');
  if (!vertex || !face) throw new Error('saliency.ply has no vertices or faces');
  if (format === 'binary_little_endian') {
    const fast = parseFixedBinary(buffer, offset, elements, vertex, face);
    if (fast) return fast;
  }
  const read = format === 'ascii' ? asciiReader(bytes, offset) : binaryReader(buffer, offset, format);
  const positions = new Float32Array(vertex.count * 3);
  const quality = new Float32Array(vertex.count);
  const index = [];
  for (const e of elements) {
    for (let i = 0; i < e.count; ++i) {
      for (const p of e.props) {
        if (p.list) {
          const n = read(p.countType);
          const first = read(p.type);
          let prev = read(p.type);
          for (let k = 2; k < n; ++k) {
            const v = read(p.type);
            if (e === face) index.push(first, prev, v);
            prev = v;
          }
          continue;
        }
        const v = read(p.type);
        if (e !== vertex) continue;
        if (p.name === 'x') positions[i * 3] = v;
        else if (p.name === 'y') positions[i * 3 + 1] = v;
        else if (p.name === 'z') positions[i * 3 + 2] = v;
        else if (p.name === 'quality') quality[i] = v;
      }
    }
  }
  return { positions, quality, index: Uint32Array.from(index) };
}

function binaryReader(buffer, offset, format) {
  const view = new DataView(buffer);
  const little = format !== 'binary_big_endian';
  let at = offset;
  return (type) => {
    const [getter, size] = TYPES[type] || [];
    if (!getter) throw new Error(`saliency.ply: unknown type ${type}`);
    if (at + size > view.byteLength) throw new Error('saliency.ply ends early');
    const v = view[getter](at, little);
    at += size;
    return v;
  };
}

function asciiReader(bytes, offset) {
  const words = new TextDecoder().decode(bytes.subarray(offset)).trim().split(/\s+/);
  let at = 0;
  return () => {
    if (at >= words.length) throw new Error('saliency.ply ends early');
    return Number(words[at++]);
  };
}

// The common case, read without a call per value: little-endian vertices of fixed-size
// properties, then triangles with a uchar count and int indices (as salientd writes them).
// Null when the file is laid out otherwise.
function parseFixedBinary(buffer, offset, elements, vertex, face) {
  if (elements[0] !== vertex || elements[1] !== face || elements.length !== 2) return null;
  const fp = face.props;
  if (fp.length !== 1 || !fp[0].list || !['uchar', 'uint8'].includes(fp[0].countType) || !['int', 'int32', 'uint', 'uint32'].includes(fp[0].type))
    return null;
  const at = {};
  let stride = 0;
  for (const p of vertex.props) {
    if (p.list || !TYPES[p.type]) return null;
    at[p.name] = [stride, p.type];
    stride += TYPES[p.type][1];
  }
  for (const k of ['x', 'y', 'z']) if (!at[k] || at[k][1] !== 'float' && at[k][1] !== 'float32') return null;
  const view = new DataView(buffer);
  const n = vertex.count;
  if (offset + n * stride + face.count * 13 > buffer.byteLength) return null;
  const positions = new Float32Array(n * 3);
  const quality = new Float32Array(n);
  const q = at.quality && (at.quality[1] === 'float' || at.quality[1] === 'float32') ? at.quality[0] : -1;
  for (let i = 0, o = offset; i < n; ++i, o += stride) {
    positions[i * 3] = view.getFloat32(o + at.x[0], true);
    positions[i * 3 + 1] = view.getFloat32(o + at.y[0], true);
    positions[i * 3 + 2] = view.getFloat32(o + at.z[0], true);
    if (q >= 0) quality[i] = view.getFloat32(o + q, true);
  }
  const index = new Uint32Array(face.count * 3);
  let o = offset + n * stride;
  for (let f = 0; f < face.count; ++f) {
    if (o >= buffer.byteLength || view.getUint8(o) !== 3) return null; // polygons: the general reader fans them
    index[f * 3] = view.getUint32(o + 1, true);
    index[f * 3 + 1] = view.getUint32(o + 5, true);
    index[f * 3 + 2] = view.getUint32(o + 9, true);
    o += 13;
  }
  for (let i = 0; i < index.length; ++i) if (index[i] >= n) throw new Error('saliency.ply: a face names a vertex it does not have');
  return { positions, quality, index };
}
