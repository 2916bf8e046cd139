// The progress picture of a print made from a job: its plan's layers stacked by height, each as
// wide as it is thick, the printed ones filled — where the print is, and how thin the layers
// still to come are.
import { api } from './api.js';
import { h, themeColor } from './dom.js';

const plans = new Map(); // job id -> the plan's promise (a print asks once)

export class PrintPicture {
  constructor(container, jobId) {
    this.canvas = h('canvas', { class: 'print-picture', id: 'print-picture', width: 160, height: 240, role: 'img', 'aria-label': 'The layers printed so far' });
    container.append(this.canvas);
    if (!plans.has(jobId)) plans.set(jobId, api.get(`/jobs/${encodeURIComponent(jobId)}/plan`));
    this.layer = 0;
    this.layers = 0;
    plans
      .get(jobId)
      .then((plan) => ((this.plan = plan), this.draw()))
      .catch(() => this.canvas.remove()); // a job deleted since: no picture
  }

  // layer, layers: the print's (from the G-code's layer marks; its first "layer" is the start code).
  update(layer, layers) {
    if (layer === this.layer && layers === this.layers) return;
    this.layer = layer;
    this.layers = layers;
    this.draw();
  }

  draw() {
    const plan = this.plan;
    if (!plan || !plan.layers.length) return;
    const g = this.canvas.getContext('2d');
    const { width, height } = this.canvas;
    const top = plan.layers[plan.layers.length - 1].z_top;
    const thickest = Math.max(...plan.layers.map((l) => l.height));
    const done = this.layers > 1 ? Math.round(((this.layer - 1) / (this.layers - 1)) * plan.layers.length) : 0;
    g.clearRect(0, 0, width, height);
    const accent = themeColor('--accent') || '#1d4ed8';
    const line = themeColor('--line') || '#ccc';
    plan.layers.forEach((l, i) => {
      const y0 = height - (l.z_bottom / top) * height;
      const y1 = height - (l.z_top / top) * height;
      const w = (l.height / thickest) * (width - 10);
      g.fillStyle = i < done ? accent : line;
      g.fillRect(5 + (width - 10 - w) / 2, y1, w, Math.max(0.5, y0 - y1 - 0.3));
    });
  }
}
