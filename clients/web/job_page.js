// #/jobs/ID: one job, live while it runs; when done its result (layers, time against the finest
// and the uniform plan, filament), downloads, "print on …", delete, and the science: the model
// coloured by saliency with its layer boundaries (viewer.js) and the plan plot (plan_chart.js).
import { api } from './api.js';
import { h, fill, toast, act, badge, progressBar, minutes, percent, signed, confirmed, when, announce, whyNotLoaded } from './dom.js';

const DOWNLOADS = [
  ['gcode', 'G-code', '.gcode'],
  ['model.3mf', '3MF (PrusaSlicer)', '.3mf'],
  ['plan', 'Plan (JSON)', '.plan.json'],
  ['saliency.ply', 'Saliency (PLY)', '.saliency.ply'],
  ['plot.svg', 'Plot (SVG)', '.plot.svg'],
];

export async function jobView(main, id, { events, navigate }) {
  let job;
  try {
    job = await api.get('/jobs/' + encodeURIComponent(id));
  } catch (e) {
    fill(main, h('h1', {}, 'Job ' + id), h('p', { class: 'error' }, e.message), h('a', { href: '#/jobs' }, 'All jobs'));
    return () => {};
  }
  const head = h('section', { class: 'job-head' });
  const body = h('div', { class: 'job-body' });
  fill(main, h('p', {}, h('a', { href: '#/jobs' }, '← All jobs')), head, body);
  let science = null;
  let shownState = '';

  const update = (j, message) => {
    job = j;
    fill(head, header(j));
    if (message) window.salientMetrics.eventLatencies.push(performance.timeOrigin + performance.now() - message.time * 1000);
    if (j.state === shownState) return;
    if (shownState) announce(`${j.filename}: ${j.state}`);
    shownState = j.state;
    if (j.state === 'done' && j.result) {
      fill(body, summary(j), warnings(j.result), actions(j, navigate));
      science = showScience(body, j);
    } else if (j.state === 'running' || j.state === 'queued') {
      fill(body, h('div', { class: 'actions' }, cancelButton(j)));
    } else {
      fill(body, h('div', { class: 'actions' }, deleteButton(j, navigate)));
    }
  };
  update(job);
  const off = events.on('job/' + id, update);
  return () => {
    off();
    if (science) science.then((s) => s && s.dispose());
  };
}

function header(j) {
  return [
    h('h1', {}, j.filename, ' ', badge(j.state)),
    j.state === 'running' || j.state === 'queued'
      ? h(
          'p',
          { class: 'phase' },
          h('span', { id: 'job-phase' }, j.state === 'queued' ? 'queued' : j.phase),
          ' ',
          progressBar(j.progress, 'job progress'),
          ' ',
          h('span', { id: 'job-progress' }, percent(j.progress)),
        )
      : null,
    j.error ? h('p', { class: 'error', role: 'alert' }, j.error) : null,
    h(
      'details',
      { class: 'settings-used' },
      h('summary', {}, `Submitted ${when(j.created_at)} · settings`),
      h('code', {}, JSON.stringify(j.settings)),
    ),
  ];
}

function summary(j) {
  const r = j.result;
  const t = r.times || {};
  const fig = (label, value, note, id) =>
    h('div', { class: 'figure', id }, h('dt', {}, label), h('dd', {}, value, note ? h('small', {}, note) : null));
  const saving = (s, p) => (s === undefined ? '–' : `${signed(s / 60)} min (${signed(p)} %)`);
  return h(
    'dl',
    { class: 'figures', id: 'job-result' },
    fig('Layers', String(r.layers), `finest ${r.finest_layers}, uniform ${t.default_layers ?? '–'}`, 'fig-layers'),
    fig('Estimated time', minutes(r.print_seconds), `${r.printer}, from the G-code`, 'fig-time'),
    fig('Saved vs finest', saving(t.saving_vs_fine_s, t.saving_vs_fine_percent), `uniform ${t.fine_layers ?? '–'} layers at α`, 'fig-fine'),
    fig(
      'Saved vs uniform',
      saving(t.saving_vs_default_s, t.saving_vs_default_percent),
      t.default_layer_height ? `${t.default_layer_height} mm layers, RSMD ${t.default_rsmd?.toFixed(3)} vs ${r.rsmd?.toFixed(3)}` : null,
      'fig-uniform',
    ),
    fig('Filament', `${(r.filament_mm / 1000).toFixed(2)} m`, null, 'fig-filament'),
    r.segmentation ? fig('SegOpt', r.segmentation.cut ? 'cut' : 'not cut', r.segmentation.note, 'fig-segopt') : null,
    r.orientation ? fig('Orientation', String(r.orientation.up ?? JSON.stringify(r.orientation))) : null,
  );
}

// What the slicer wants the owner to know about the result ({code, message} each), when it says.
function warnings(r) {
  const list = Array.isArray(r.warnings) ? r.warnings.filter((w) => w && w.message) : [];
  if (!list.length) return null;
  return h(
    'section',
    { class: 'card warnings', id: 'job-warnings', 'aria-label': 'Warnings' },
    h('h2', {}, 'Warnings'),
    h('ul', {}, list.map((w) => h('li', { dataset: { code: String(w.code || '') } }, String(w.message)))),
  );
}

function actions(j, navigate) {
  const stem = j.filename.replace(/\.[^.]*$/, '');
  const downloads = DOWNLOADS.map(([path, label, suffix]) =>
    h('button', { type: 'button', class: 'quiet', onclick: (e) => act(e.currentTarget, () => api.download(`/jobs/${j.id}/${path}`, stem + suffix)) }, label),
  );
  const printer = h('select', { id: 'print-printer', 'aria-label': 'printer' });
  const print = h('button', { type: 'button', id: 'print-job' }, 'Print');
  api
    .get('/printers')
    .then(({ printers }) => {
      fill(printer, printers.map((p) => h('option', { value: p.id }, `${p.id} (${p.state})`)));
      print.textContent = printers.length ? `Print on ${printers[0].id}` : 'No printer';
      print.disabled = !printers.length;
    })
    .catch((e) => toast(e.message));
  printer.addEventListener('change', () => (print.textContent = `Print on ${printer.value}`));
  print.addEventListener('click', () =>
    act(print, async () => {
      await api.post(`/printers/${encodeURIComponent(printer.value)}/print`, { job: j.id });
      navigate('#/printers/' + printer.value);
    }),
  );
  return h(
    'div',
    { class: 'actions' },
    h('div', { class: 'group' }, printer, print),
    h('div', { class: 'group', role: 'group', 'aria-label': 'Downloads' }, downloads),
    deleteButton(j, navigate),
  );
}

function cancelButton(j) {
  return h(
    'button',
    {
      type: 'button',
      class: 'danger',
      onclick: async (e) => {
        const b = e.currentTarget;
        if (await confirmed(`Cancel slicing ${j.filename}?`, 'Cancel the job')) act(b, () => api.del('/jobs/' + j.id));
      },
    },
    'Cancel',
  );
}

function deleteButton(j, navigate) {
  return h(
    'button',
    {
      type: 'button',
      class: 'danger',
      id: 'delete-job',
      onclick: async (e) => {
        const b = e.currentTarget;
        if (!(await confirmed(`Delete ${j.filename} and its files?`, 'Delete'))) return;
        await act(b, async () => {
          await api.del('/jobs/' + j.id);
          navigate('#/jobs');
        });
      },
    },
    'Delete',
  );
}

// The 3D view and the plot side by side; their modules (three.js, Chart.js) load only here.
async function showScience(body, j) {
  const view = h('figure', { class: 'panel' }, h('figcaption', {}, 'Saliency on the model, with the layer boundaries'));
  const plot = h('figure', { class: 'panel' }, h('figcaption', {}, 'The plan: thickness and saliency against height'));
  body.append(h('section', { class: 'science', 'aria-label': 'The science' }, view, plot));
  try {
    const [{ SaliencyViewer }, { PlanChart }, plyResponse, plan] = await Promise.all([
      import('./viewer.js'),
      import('./plan_chart.js'),
      api.request('GET', `/jobs/${j.id}/saliency.ply`, { raw: true }),
      api.get(`/jobs/${j.id}/plan`),
    ]);
    const ply = await plyResponse.arrayBuffer();
    const viewer = new SaliencyViewer(view, ply, plan);
    const chart = new PlanChart(plot, plan, (layer) => viewer.highlight(layer));
    return { dispose: () => (viewer.dispose(), chart.dispose()) };
  } catch (e) {
    view.append(h('p', { class: 'error', role: 'alert' }, await whyNotLoaded(e)));
    return null;
  }
}
