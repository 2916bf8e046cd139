// A printer's temperatures over the last half hour: the history from
// GET /api/v1/printers/{id}/temperatures, then each "printer" event added as it comes. The time
// axis is minutes before now (Chart.js's time axis would need a date library Debian does not
// ship), as long as the history goes back, up to 30.
import { Chart, registerables } from '../vendor/chart.js/chart.esm.js';
import { h, themeColor } from './dom.js';

Chart.register(...registerables);

const WINDOW = 1800; // seconds kept, as the server does
const SERIES = [
  ['hotend', 'hotend', '#ef4444', []],
  ['hotend_target', 'hotend target', '#ef4444', [5, 4]],
  ['bed', 'bed', '#3b82f6', []],
  ['bed_target', 'bed target', '#3b82f6', [5, 4]],
];

export class TemperatureChart {
  constructor(container, history) {
    const canvas = h('canvas', { id: 'temperature-chart', role: 'img', 'aria-label': 'Temperatures over the last 30 minutes at most' });
    container.replaceChildren(canvas);
    this.points = []; // [time, hotend, hotend_target, bed, bed_target]
    const columns = history.columns || [];
    const at = (name) => columns.indexOf(name);
    for (const row of history.samples || [])
      this.points.push([row[at('time')], row[at('hotend')], row[at('hotend_target')], row[at('bed')], row[at('bed_target')]]);
    const text = themeColor('--fg') || '#222';
    const grid = themeColor('--line') || '#ccc';
    this.chart = new Chart(canvas, {
      type: 'line',
      data: {
        datasets: SERIES.map(([, label, color, dash]) => ({ label, data: [], borderColor: color, borderDash: dash, borderWidth: dash.length ? 1 : 2, pointRadius: 0, spanGaps: false })),
      },
      options: {
        animation: false,
        maintainAspectRatio: false,
        parsing: false,
        interaction: { mode: 'nearest', axis: 'x', intersect: false },
        scales: {
          x: {
            type: 'linear',
            min: -30,
            max: 0,
            title: { display: true, text: 'minutes ago', color: text },
            ticks: { color: text, callback: (v) => (v === 0 ? 'now' : String(-v)) },
            grid: { color: grid },
          },
          y: { type: 'linear', suggestedMin: 0, suggestedMax: 250, title: { display: true, text: '°C', color: text }, ticks: { color: text }, grid: { color: grid } },
        },
        plugins: {
          legend: { labels: { color: text } },
          tooltip: { callbacks: { label: (item) => `${item.dataset.label}: ${item.parsed.y?.toFixed(1)} °C` } },
        },
      },
    });
    this.redraw();
    this.timer = setInterval(() => this.redraw(), 5000); // the axis moves with time
  }

  // time: the event's (seconds since the epoch); temperatures: the printer's {hotend, bed}.
  add(time, temperatures) {
    const last = this.points[this.points.length - 1];
    if (last && time - last[0] < 1) return; // one a second, as the server keeps them
    const { hotend, bed } = temperatures;
    this.points.push([time, hotend.actual, hotend.target, bed.actual, bed.target]);
    this.redraw();
  }

  redraw() {
    const now = Date.now() / 1000;
    while (this.points.length && this.points[0][0] < now - WINDOW) this.points.shift();
    // The axis spans what there is, from 2 minutes up to the half hour kept.
    const span = this.points.length ? (now - this.points[0][0]) / 60 : 0;
    this.chart.options.scales.x.min = -Math.min(30, Math.max(2, Math.ceil(span)));
    this.chart.data.datasets.forEach((d, k) => {
      d.data = this.points.map((p) => ({ x: (p[0] - now) / 60, y: p[k + 1] ?? null }));
    });
    this.chart.update('none');
  }

  dispose() {
    clearInterval(this.timer);
    this.chart.destroy();
  }
}
