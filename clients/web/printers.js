// #/printers: every configured printer at a glance and the uploaded files (files.js);
// #/printers/ID: one printer to drive — its state, temperatures (a live chart of the last half
// hour, targets settable), the print under way with pause/resume/cancel/emergency stop and its
// queue (print_queue.js), connect/disconnect, a terminal, and its history with resume for an
// interrupted print.
import { api } from './api.js';
import { h, fill, toast, act, badge, progressBar, celsius, duration, percent, when, confirmed, announce, whyNotLoaded } from './dom.js';
import { filesCard } from './files.js';
import { printQueue } from './print_queue.js';

export async function printersView(main, context) {
  const { events } = context;
  const grid = h('div', { class: 'printers', id: 'printer-list' });
  const files = filesCard(events, context);
  fill(main, h('h1', {}, 'Printers'), grid, files.section);
  const cards = new Map();
  const show = (p) => {
    const card = h(
      'a',
      { class: 'card printer-card', href: '#/printers/' + p.id, dataset: { id: p.id, state: p.state } },
      h('h2', {}, p.id, ' ', badge(p.state)),
      h('p', { class: 'muted' }, `${p.profile} · ${p.kind} · ${p.protocol}`),
      h('p', {}, `hotend ${celsius(p.temperatures.hotend)} · bed ${celsius(p.temperatures.bed)}`),
      p.print ? [progressBar(p.print.progress, 'print progress'), h('p', {}, `${p.print.file} · ${percent(p.print.progress, 1)}`)] : null,
    );
    const old = cards.get(p.id);
    if (old) old.replaceWith(card);
    else grid.append(card);
    cards.set(p.id, card);
  };
  const offPrinters = events.on('printers', show);
  const off = () => (offPrinters(), files.off());
  try {
    const { printers } = await api.get('/printers');
    printers.forEach(show);
    if (!printers.length) grid.append(h('p', { class: 'muted' }, 'No printers configured ([[printers]] in the config).'));
  } catch (e) {
    toast(e.message);
  }
  return off;
}

export async function printerView(main, id, { events }) {
  const path = '/printers/' + encodeURIComponent(id);
  let printer;
  try {
    printer = await api.get(path);
  } catch (e) {
    fill(main, h('h1', {}, 'Printer ' + id), h('p', { class: 'error' }, e.message), h('a', { href: '#/printers' }, 'All printers'));
    return () => {};
  }
  const head = h('section', { class: 'printer-head' });
  const current = h('section', { class: 'card', id: 'current-print', 'aria-label': 'Current print' });
  const temps = h('section', { class: 'card', 'aria-label': 'Temperatures' });
  const terminal = h('section', { class: 'card', 'aria-label': 'Terminal' });
  const queueSection = h('section', { class: 'queue-box' });
  const history = h('section', { class: 'card', 'aria-label': 'Print history' });
  fill(main, h('p', {}, h('a', { href: '#/printers' }, '← All printers')), head, h('div', { class: 'printer-grid' }, current, temps, terminal, history));
  const queue = printQueue(queueSection, path);

  const controls = temperatureControls(path);
  const chartBox = h('div', { class: 'chart-box' }, h('p', { class: 'muted' }, 'Loading the temperatures…'));
  fill(temps, h('h2', {}, 'Temperatures'), h('p', { id: 'temp-now' }), chartBox, controls);
  let chart = null;
  const chartReady = Promise.all([import('./temperature_chart.js'), api.get(path + '/temperatures')])
    .then(([{ TemperatureChart }, history]) => (chart = new TemperatureChart(chartBox, history)))
    .catch(async (e) => fill(chartBox, h('p', { class: 'error' }, await whyNotLoaded(e))));

  let lastState = '';
  let shown = '';
  const update = (p, message) => {
    printer = p;
    // Rebuilt when the state changes (buttons keep their focus between progress events).
    const key = `${p.state}/${p.error}/${p.print ? p.print.id : ''}`;
    if (key !== shown) {
      if (shown) announce(`${p.id}: ${p.state}`);
      shown = key;
      fill(head, h('h1', {}, p.id, ' ', badge(p.state)), h('p', { class: 'muted' }, details(p)), p.error ? h('p', { class: 'error', role: 'alert' }, p.error) : null, connection(p, path));
      fill(current, ...printView(p, path), queueSection);
    } else if (p.print) {
      updatePrint(current, p.print);
    }
    queue.idle(p.state === 'operational' && !p.print);
    // The row of the print under way follows the card: the stored row is saved only now and then.
    if (p.print) {
      const done = history.querySelector(`tr[data-print="${p.print.id}"] .done`);
      if (done) done.textContent = percent(p.print.progress, 1);
    }
    temps.querySelector('#temp-now').textContent = `Hotend ${celsius(p.temperatures.hotend)} · bed ${celsius(p.temperatures.bed)}`;
    if (chart && message) chart.add(message.time, p.temperatures);
    if (message) window.salientMetrics.eventLatencies.push(performance.timeOrigin + performance.now() - message.time * 1000);
    if (p.state !== lastState) {
      lastState = p.state;
      refreshHistory(history, path, () => printer.print);
    }
  };
  update(printer);
  const offPrinter = events.on('printer/' + id, (data, message) =>
    message && message.type === 'queue' ? queue.show(data) : update(data, message),
  );
  const offTerminal = terminalView(terminal, id, path, events);
  return () => {
    offPrinter();
    offTerminal();
    chartReady.then(() => chart && chart.dispose());
  };
}

function details(p) {
  return [p.profile, p.kind, p.protocol, p.firmware, p.device].filter(Boolean).join(' · ');
}

function connection(p, path) {
  const connected = !['disconnected', 'error'].includes(p.state);
  return h(
    'div',
    { class: 'actions' },
    connected
      ? h('button', { type: 'button', class: 'quiet', id: 'disconnect', onclick: (e) => act(e.currentTarget, () => api.post(path + '/disconnect')) }, 'Disconnect')
      : h('button', { type: 'button', id: 'connect', onclick: (e) => act(e.currentTarget, () => api.post(path + '/connect')) }, 'Connect'),
  );
}

// Pause/resume/cancel ask nothing twice but cancel and emergency stop, which end the print.
function printView(p, path) {
  const out = [h('h2', {}, 'Current print')];
  const run = p.print;
  if (!run) {
    const last = p.last_print;
    out.push(h('p', { class: 'muted', id: 'no-print' }, 'Nothing printing.'));
    if (last) out.push(h('p', {}, `Last: ${last.file}, ${last.state}` + (last.reason ? ` (${last.reason})` : '')));
    return out;
  }
  const layer = run.layer ? `layer ${run.layer} of ${run.layers}` : null;
  const picture = h('div', { class: 'picture-box' });
  if (run.job)
    import('./print_picture.js').then(({ PrintPicture }) => {
      picture.picture = new PrintPicture(picture, run.job);
      picture.picture.update(run.layer, run.layers);
    });
  const info = h(
    'div',
    { class: 'print-info' },
    h('p', {}, h('strong', {}, run.file), ' ', badge(run.state)),
    h('div', { class: 'print-progress' }, progressBar(run.progress, 'print progress'), h('span', { id: 'print-percent' }, percent(run.progress, 1))),
    h(
      'dl',
      { class: 'figures small' },
      h('div', {}, h('dt', {}, 'Layer'), h('dd', { id: 'print-layer' }, layer || '–')),
      h('div', {}, h('dt', {}, 'Commands'), h('dd', { id: 'print-lines' }, `${run.confirmed} / ${run.total}`)),
      h('div', {}, h('dt', {}, 'Elapsed'), h('dd', { id: 'print-elapsed' }, duration(run.elapsed))),
      h('div', {}, h('dt', {}, 'Time left'), h('dd', { id: 'print-left' }, duration(run.eta))),
    ),
  );
  out.push(h('div', { class: 'print-row' }, picture, info));
  const button = (label, id, action, question, cls) =>
    h(
      'button',
      {
        type: 'button',
        id,
        class: cls,
        onclick: async (e) => {
          const b = e.currentTarget;
          if (question && !(await confirmed(question, label))) return;
          act(b, () => api.post(`${path}/${action}`));
        },
      },
      label,
    );
  out.push(
    h(
      'div',
      { class: 'actions' },
      p.state === 'paused' ? button('Resume', 'resume', 'resume') : button('Pause', 'pause', 'pause'),
      button('Cancel', 'cancel', 'cancel', `Cancel the print of ${run.file}? It cannot be resumed.`, 'danger'),
      button('Emergency stop', 'emergency-stop', 'emergency-stop', 'Emergency stop (M112): heaters and motors off at once; the printer then needs a reconnect.', 'danger'),
    ),
  );
  return out;
}

function updatePrint(section, run) {
  const set = (selector, text) => {
    const el = section.querySelector(selector);
    if (el) el.textContent = text;
  };
  const picture = section.querySelector('.picture-box');
  if (picture && picture.picture) picture.picture.update(run.layer, run.layers);
  const bar = section.querySelector('progress');
  if (bar) bar.value = run.progress;
  set('#print-percent', percent(run.progress, 1));
  set('#print-layer', run.layer ? `layer ${run.layer} of ${run.layers}` : '–');
  set('#print-lines', `${run.confirmed} / ${run.total}`);
  set('#print-elapsed', duration(run.elapsed));
  set('#print-left', duration(run.eta));
}

function temperatureControls(path) {
  const row = (label, id, code) => {
    const input = h('input', { type: 'number', id, min: 0, max: 300, step: 1, inputmode: 'numeric', 'aria-label': label + ' target (°C)' });
    const set = (value) => api.post(path + '/command', { commands: [`${code} S${value}`] });
    return h(
      'form',
      {
        class: 'pair',
        onsubmit: (e) => {
          e.preventDefault();
          if (input.value === '') return;
          act(e.submitter, () => set(Math.round(Number(input.value))));
        },
      },
      h('label', { for: id }, label),
      input,
      h('button', { type: 'submit' }, 'Set'),
      h('button', { type: 'button', class: 'quiet', onclick: (e) => act(e.currentTarget, () => set(0)) }, 'Off'),
    );
  };
  return h('div', { class: 'targets' }, row('Hotend', 'hotend-target', 'M104'), row('Bed', 'bed-target', 'M140'));
}

// Lines the printer sends and receives (topic terminal/ID), and a command box with its history
// (arrow up/down).
function terminalView(section, id, path, events) {
  const log = h('pre', { class: 'terminal', id: 'terminal', tabindex: 0, 'aria-label': 'Terminal output' });
  const input = h('input', { id: 'command', autocomplete: 'off', spellcheck: false, placeholder: 'G28, M105, M503…', 'aria-label': 'G-code command' });
  const sent = [];
  let back = 0;
  input.addEventListener('keydown', (e) => {
    if (e.key !== 'ArrowUp' && e.key !== 'ArrowDown') return;
    e.preventDefault();
    back = Math.max(0, Math.min(sent.length, back + (e.key === 'ArrowUp' ? 1 : -1)));
    input.value = back ? sent[sent.length - back] : '';
  });
  const form = h(
    'form',
    {
      class: 'pair',
      onsubmit: (e) => {
        e.preventDefault();
        const command = input.value.trim();
        if (!command) return;
        act(e.submitter, async () => {
          await api.post(path + '/command', { commands: [command] });
          sent.push(command);
          back = 0;
          input.value = '';
        });
      },
    },
    input,
    h('button', { type: 'submit' }, 'Send'),
  );
  const autoscroll = h('input', { type: 'checkbox', id: 'autoscroll', checked: true });
  fill(section, h('h2', {}, 'Terminal'), log, form, h('label', {}, autoscroll, ' follow'));
  // A print sends hundreds of lines a second: they are drawn once per frame, the last 300 kept.
  const lines = [];
  let frame = 0;
  const draw = () => {
    frame = 0;
    log.textContent = lines.join('\n');
    if (autoscroll.checked) log.scrollTop = log.scrollHeight;
  };
  const off = events.on('terminal/' + id, (data) => {
    lines.push((data.direction === 'sent' ? '> ' : '< ') + data.line);
    if (lines.length > 400) lines.splice(0, lines.length - 300);
    if (!frame) frame = requestAnimationFrame(draw);
  });
  return () => {
    off();
    cancelAnimationFrame(frame);
  };
}

// `live()`: the print under way, whose row shows its live progress rather than the stored one.
async function refreshHistory(section, path, live) {
  try {
    const { prints } = await api.get(path + '/prints');
    const now = live();
    const rows = prints.slice(0, 20).map((p) =>
      h(
        'tr',
        { dataset: { print: String(p.id) } },
        h('td', { class: 'history-file' }, p.file),
        h('td', {}, badge(p.state)),
        h('td', { class: 'done' }, now && now.id === p.id ? percent(now.progress, 1) : p.total ? percent(p.confirmed / p.total, 1) : '–'),
        h('td', { class: 'history-started' }, when(p.started_at)),
        h('td', {}, p.reason || ''),
        h('td', {}, resumable(p) ? h('button', { type: 'button', class: 'quiet', onclick: (e) => act(e.currentTarget, () => api.post(path + '/print', { resume: p.id })) }, 'Resume') : ''),
      ),
    );
    fill(
      section,
      h('h2', {}, 'History'),
      prints.length
        ? h('div', { class: 'scroll' }, h('table', { id: 'print-history' }, h('thead', {}, h('tr', {}, ['File', 'State', 'Done', 'Started', 'Why', ''].map((t) => h('th', { scope: 'col' }, t)))), h('tbody', {}, rows)))
        : h('p', { class: 'muted' }, 'No prints yet.'),
    );
  } catch (e) {
    fill(section, h('h2', {}, 'History'), h('p', { class: 'error' }, e.message));
  }
}

function resumable(p) {
  return (p.state === 'failed' || p.state === 'interrupted') && p.confirmed > 0 && p.confirmed < p.total;
}
