// #/jobs: a model dropped (or picked) with its settings becomes a job; the list shows every job
// with its phase and progress as the events report them.
import { api } from './api.js';
import { h, fill, toast, badge, progressBar, when, percent, minutes, signed } from './dom.js';

const PROFILES = ['generic-i3', 'ender3', 'replicator2x'];
const MODEL_TYPES = '.stl,.obj,.ply,.off';

export async function jobsView(main, { events }) {
  const rows = new Map(); // job id -> row element
  const list = h('ul', { class: 'jobs', id: 'job-list' });
  const empty = h('p', { class: 'muted' }, 'No jobs yet: drop a model above.');
  fill(main, h('h1', { class: 'visually-hidden' }, 'Jobs'), await submitCard(), h('h2', {}, 'Jobs'), empty, list);

  const show = (job, message) => {
    const row = jobRow(job);
    const old = rows.get(job.id);
    if (old) old.replaceWith(row);
    else list.prepend(row);
    rows.set(job.id, row);
    empty.hidden = true;
    if (message) window.salientMetrics.eventLatencies.push(performance.timeOrigin + performance.now() - message.time * 1000);
  };
  const off = events.on('jobs', (job, message) => show(job, message));
  try {
    const { jobs } = await api.get('/jobs?limit=50');
    for (const job of jobs.reverse()) if (!rows.has(job.id)) show(job);
  } catch (e) {
    toast(e.message);
  }
  return off;
}

function jobRow(job) {
  const r = job.result;
  const detail =
    job.state === 'done' && r
      ? `${r.layers} layers · ${minutes(r.print_seconds)}` +
        (r.times ? ` · saves ${signed(r.times.saving_vs_default_percent, 0)} % vs uniform` : '')
      : job.state === 'failed'
        ? job.error || 'failed'
        : `${job.state === 'running' ? job.phase : job.state === 'queued' ? 'waiting' : job.state} · ${percent(job.progress)}`;
  return h(
    'li',
    { class: 'job', dataset: { id: job.id, state: job.state } },
    h('a', { href: '#/jobs/' + job.id, class: 'job-name' }, job.filename),
    badge(job.state),
    h('span', { class: 'job-detail' }, detail),
    job.state === 'running' || job.state === 'queued' ? progressBar(job.progress, 'progress of ' + job.filename) : null,
    h('time', { class: 'muted', datetime: new Date(job.created_at * 1000).toISOString() }, when(job.created_at)),
  );
}

// The model and the settings a user needs; the rest keep the server's defaults.
async function submitCard() {
  let profiles = PROFILES;
  try {
    const { printers } = await api.get('/printers');
    profiles = [...new Set([...printers.map((p) => p.profile), ...PROFILES])];
  } catch {
    /* the built-in profiles then */
  }
  let model = null;
  const drop = dropZone((f) => (model = f));
  const { fields, settings } = settingsForm(profiles);
  const status = h('p', { class: 'muted', role: 'status', id: 'submit-status' });
  const button = h('button', { type: 'submit', id: 'submit-job' }, 'Slice');
  const submit = async (e) => {
    e.preventDefault();
    if (!model) {
      status.textContent = 'Choose or drop a model first.';
      return;
    }
    button.disabled = true;
    try {
      const job = await api.submit(model, settings(), (f) => (status.textContent = `Uploading… ${percent(f)}`));
      status.textContent = `Submitted ${job.filename}: ${job.state}.`;
      location.hash = '#/jobs/' + job.id;
    } catch (err) {
      status.textContent = '';
      toast(err.message);
    } finally {
      button.disabled = false;
    }
  };
  return h(
    'form',
    { class: 'card submit', onsubmit: submit, 'aria-label': 'New job' },
    drop,
    fields,
    h('div', { class: 'actions' }, button, status),
  );
}

// Where a model is dropped, or picked with the file chooser (a label for a real file input:
// the keyboard reaches it); onPick(file) with the one chosen.
function dropZone(onPick) {
  const file = h('input', { type: 'file', id: 'model-file', accept: MODEL_TYPES, class: 'visually-hidden' });
  const chosen = h('span', { class: 'chosen', id: 'chosen-file' }, 'No model chosen');
  const drop = h(
    'div',
    { class: 'drop', id: 'drop-zone' },
    h('p', {}, 'Drop a model here (STL, OBJ, PLY, OFF) or '),
    h('label', { for: 'model-file', class: 'button' }, 'choose a file'),
    file,
    chosen,
  );
  const pick = (f) => {
    onPick(f || null);
    chosen.textContent = f ? `${f.name} (${(f.size / 1024).toFixed(0)} KiB)` : 'No model chosen';
  };
  file.addEventListener('change', () => pick(file.files[0]));
  drop.addEventListener('dragover', (e) => {
    e.preventDefault();
    drop.classList.add('over');
  });
  drop.addEventListener('dragleave', () => drop.classList.remove('over'));
  drop.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('over');
    if (e.dataTransfer.files.length) pick(e.dataTransfer.files[0]);
  });
  return drop;
}

// The settings a user needs (the server's defaults for the rest, as README's table lists them):
// the fields, and a function that reads them as the job's settings.
function settingsForm(profiles) {
  const field = (label, input, hint) =>
    h('div', { class: 'field' }, h('label', { for: input.id }, label), input, hint ? h('small', { class: 'muted' }, hint) : null);
  const select = (id, options, value) =>
    h('select', { id }, options.map(([v, text]) => h('option', { value: v, selected: v === value }, text)));
  const printer = select('s-printer', profiles.map((p) => [p, p]), profiles[0]);
  const target = select('s-target', [['rho', 'quality ρ'], ['layers', 'layer count']], 'rho');
  const amount = h('input', { id: 's-amount', type: 'number', step: 'any', min: 0, value: '0.05', 'aria-label': 'ρ or layers' });
  target.addEventListener('change', () => {
    amount.value = target.value === 'rho' ? '0.05' : '100';
    amount.step = target.value === 'rho' ? 'any' : '1';
  });
  const height = h('input', { id: 's-height', type: 'number', step: 'any', min: 0.1, placeholder: 'as the file' });
  const up = select('s-up', [['z', 'z up'], ['y', 'y up'], ['x', 'x up'], ['auto', 'auto (paper §6)']], 'z');
  const saliency = select(
    's-saliency',
    [['spectral', 'spectral (the paper’s)'], ['lee05', 'lee05'], ['painted', 'painted in the file'], ['uniform', 'uniform']],
    'spectral',
  );
  const segment = h('input', { id: 's-segment', type: 'checkbox' });
  const support = h('input', { id: 's-support', type: 'checkbox' });
  const grid = h(
    'div',
    { class: 'settings' },
    field('Printer profile', printer),
    h('div', { class: 'field' }, h('label', { for: 's-target' }, 'Plan to'), h('div', { class: 'pair' }, target, amount)),
    field('Orientation', up),
    field('Saliency', saliency),
    h(
      'div',
      { class: 'field checks' },
      h('label', {}, segment, ' SegOpt: cut where it saves time'),
      h('label', {}, support, ' Support under overhangs'),
    ),
  );
  // On a phone the settings fold away (the defaults serve), so the job list shows beneath; the
  // model's height stays in sight: a model in metres or inches needs it on every screen.
  const fields = [
    h('div', { class: 'settings height-row' }, field('Model height (mm)', height, 'scale the model to it')),
    h('details', { class: 'settings-box', open: window.matchMedia('(min-width: 600px)').matches }, h('summary', {}, 'Settings'), grid),
  ];
  const settings = () => {
    const s = { printer: printer.value, up: up.value, saliency: saliency.value };
    const n = Number(amount.value);
    if (amount.value !== '') s[target.value] = target.value === 'layers' ? Math.round(n) : n;
    if (height.value !== '') s.height = Number(height.value);
    if (segment.checked) s.segment = true;
    if (support.checked) s.support = true;
    return s;
  };
  return { fields, settings };
}
