// A printer's queue on its page: what prints after the print under way (a file a slicer sent
// while the printer was busy, a job sent with "print"), in order, each removable; "Start the
// next" when the printer waits for someone to clear the bed.
import { api } from './api.js';
import { h, fill, act, toast, when, confirmed } from './dom.js';

// Fills `section` with the queue of the printer at `path` (/printers/ID); show(listing) redraws
// it from a queue event, idle(bool) says whether the printer could start the next now.
export function printQueue(section, path) {
  let listing = { entries: [] };
  let idle = false;
  const draw = () => {
    const entries = listing.entries || [];
    const list = entries.length
      ? h('ol', { class: 'print-queue', id: 'print-queue' }, entries.map((e) => entryRow(e, path, show)))
      : h('p', { class: 'muted', id: 'print-queue' }, 'Nothing waiting: a file a slicer sends while this printer is busy waits here.');
    const next =
      entries.length && idle && !listing.auto_start
        ? h(
            'button',
            { type: 'button', id: 'queue-next', onclick: (e) => act(e.currentTarget, () => api.post(path + '/queue/next')) },
            'Start the next (the bed is clear)',
          )
        : null;
    fill(section, h('h2', {}, 'Queue'), list, next ? h('div', { class: 'actions' }, next) : null);
  };
  const show = (l) => {
    listing = { ...listing, ...l };
    draw();
  };
  api
    .get(path + '/queue')
    .then(show)
    .catch((e) => toast(e.message));
  draw();
  return {
    show,
    idle(value) {
      if (value === idle) return;
      idle = value;
      draw();
    },
  };
}

function entryRow(e, path, show) {
  const what = e.file || (e.job ? `job ${e.job}` : `entry ${e.entry}`);
  return h(
    'li',
    { dataset: { entry: String(e.entry) } },
    h('span', { class: 'queue-name' }, what),
    h('span', { class: 'muted' }, `${e.state === 'slicing' ? 'slicing · ' : ''}since ${when(e.queued_at)}`),
    h(
      'button',
      {
        type: 'button',
        class: 'quiet remove',
        'aria-label': `Remove ${what} from the queue`,
        onclick: async (ev) => {
          const b = ev.currentTarget;
          if (!(await confirmed(`Take ${what} out of the queue? It will not print.`, 'Remove'))) return;
          act(b, async () => show(await api.del(`${path}/queue/${e.entry}`)));
        },
      },
      'Remove',
    ),
  );
}
