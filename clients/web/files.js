// The file area on the Printers page: G-code that slicers uploaded (PrusaSlicer, Cura, OctoPrint's
// /api/files/local) without printing it, each printable on a chosen printer or deletable. Without
// this list an upload stayed invisible until it printed. Redrawn when the "files" topic says so.
import { api } from './api.js';
import { h, fill, act, toast, when, confirmed } from './dom.js';

// { section, off }: the card, and what stops its listening.
export function filesCard(events, { navigate }) {
  const list = h('div', { id: 'file-list' }, h('p', { class: 'muted' }, 'Loading the files…'));
  const printer = h('select', { id: 'file-printer', 'aria-label': 'printer for the file' });
  const section = h(
    'section',
    { class: 'card files', 'aria-label': 'Uploaded files' },
    h('h2', {}, 'Files'),
    h('div', { class: 'pair' }, h('label', { for: 'file-printer' }, 'Print on'), printer),
    list,
  );
  api
    .get('/printers')
    .then(({ printers }) => fill(printer, printers.map((p) => h('option', { value: p.id }, `${p.id} (${p.state})`))))
    .catch((e) => toast(e.message));
  const refresh = async () => {
    try {
      const { files } = await api.request('GET', '/files?recursive=true', { base: 'api' });
      show(list, flatten(files), printer, navigate);
    } catch (e) {
      fill(list, h('p', { class: 'error' }, e.message));
    }
  };
  refresh();
  // An upload or delete comes as a few events at once: one reload for them.
  let timer = 0;
  const off = events.on('files', () => {
    clearTimeout(timer);
    timer = setTimeout(refresh, 200);
  });
  return { section, off: () => (off(), clearTimeout(timer)) };
}

// OctoPrint's tree (folders with children) as one list of files, newest first.
function flatten(entries, out = []) {
  for (const e of entries || []) {
    if (e.type === 'folder') flatten(e.children, out);
    else out.push(e);
  }
  return out.sort((a, b) => (b.date || 0) - (a.date || 0));
}

function show(list, files, printer, navigate) {
  if (!files.length)
    return fill(list, h('p', { class: 'muted' }, 'No uploaded files: a slicer’s “upload” (OctoPrint) puts its G-code here.'));
  fill(
    list,
    h(
      'ul',
      { class: 'file-list' },
      files.map((f) =>
        h(
          'li',
          { dataset: { path: f.path } },
          h('span', { class: 'file-name' }, f.path),
          h('span', { class: 'muted' }, `${(f.size / 1024).toFixed(0)} KiB · ${when(f.date)}`),
          h(
            'span',
            { class: 'group' },
            h(
              'button',
              {
                type: 'button',
                class: 'print-file',
                onclick: (e) =>
                  act(e.currentTarget, async () => {
                    if (!printer.value) throw new Error('No printer to print on');
                    await api.post(`/printers/${encodeURIComponent(printer.value)}/print`, { file: f.path });
                    navigate('#/printers/' + printer.value);
                  }),
              },
              'Print',
            ),
            h(
              'button',
              {
                type: 'button',
                class: 'quiet delete-file',
                onclick: async (e) => {
                  const b = e.currentTarget;
                  if (!(await confirmed(`Delete ${f.path}?`, 'Delete'))) return;
                  const url = '/files/local/' + f.path.split('/').map(encodeURIComponent).join('/');
                  act(b, () => api.request('DELETE', url, { base: 'api' }));
                },
              },
              'Delete',
            ),
          ),
        ),
      ),
    ),
  );
}
