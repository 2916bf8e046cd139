// The plan as plot.svg draws it, but interactive: each layer's thickness and the saliency against
// height; hovering (or the arrow keys, with the plot focused) shows a layer's heights, thickness,
// saliency and error (the layer's SM), and lights it on the 3D view. A SegOpt plan adds each
// region's own layers in its colour. Chart.js from Debian's libjs-chart.js.
import { Chart, registerables } from '../vendor/chart.js/chart.esm.js';
import { h, themeColor, REGION_COLORS } from './dom.js';

Chart.register(...registerables);


export class PlanChart {
  constructor(container, plan, onLayer) {
    this.plan = plan;
    this.onLayer = onLayer || (() => {});
    const canvas = h('canvas', {
      id: 'plan-chart',
      tabindex: 0,
      role: 'img',
      'aria-label': `Plan of ${plan.count} layers from ${plan.min_layer} to ${plan.max_layer} mm; arrow keys step through the layers`,
    });
    this.readout = h('p', { class: 'readout', id: 'layer-readout', 'aria-live': 'polite' }, 'Point at a layer');
    container.append(h('div', { class: 'chart-box' }, canvas), this.readout);
    const text = themeColor('--fg') || '#222';
    const grid = themeColor('--line') || '#ccc';
    const layers = plan.layers;
    const steps = layers.map((l) => ({ x: l.z_bottom, y: l.height }));
    if (layers.length) steps.push({ x: layers[layers.length - 1].z_top, y: layers[layers.length - 1].height });
    const datasets = [
      { label: 'thickness (mm)', data: steps, stepped: 'before', borderColor: themeColor('--accent') || '#2563eb', borderWidth: 1.5, pointRadius: 0, yAxisID: 'y' },
    ];
    if (layers.length && layers[0].saliency !== undefined)
      datasets.push({
        label: 'saliency',
        data: layers.map((l) => ({ x: (l.z_bottom + l.z_top) / 2, y: l.saliency })),
        borderColor: '#f59e0b',
        backgroundColor: 'rgba(245, 158, 11, 0.15)',
        fill: true,
        borderWidth: 1,
        pointRadius: 0,
        yAxisID: 'y2',
      });
    for (const [i, region] of ((plan.segmentation && plan.segmentation.regions) || []).entries()) {
      const b = region.boundaries || [];
      if (b.length < 2) continue;
      datasets.push({
        label: `region ${i + 1}`,
        data: b.slice(1).map((z, k) => ({ x: b[k], y: z - b[k] })),
        stepped: 'before',
        borderColor: REGION_COLORS[i % REGION_COLORS.length],
        borderWidth: 1,
        borderDash: [4, 3],
        pointRadius: 0,
        yAxisID: 'y',
      });
    }
    this.chart = new Chart(canvas, {
      type: 'line',
      data: { datasets },
      options: {
        animation: false,
        maintainAspectRatio: false,
        parsing: false,
        normalized: true,
        interaction: { mode: 'nearest', axis: 'x', intersect: false },
        scales: {
          x: { type: 'linear', title: { display: true, text: 'height (mm)', color: text }, ticks: { color: text }, grid: { color: grid } },
          y: {
            type: 'linear',
            min: 0,
            suggestedMax: plan.max_layer,
            title: { display: true, text: 'thickness (mm)', color: text },
            ticks: { color: text },
            grid: { color: grid },
          },
          y2: { type: 'linear', position: 'right', min: 0, max: 1, title: { display: true, text: 'saliency', color: text }, ticks: { color: text }, grid: { display: false } },
        },
        plugins: {
          legend: { labels: { color: text } },
          tooltip: {
            filter: (item) => item.datasetIndex === 0 && item.dataIndex < layers.length,
            callbacks: {
              title: (items) => (items.length ? this.title(items[0].dataIndex) : ''),
              label: (item) => this.lines(item.dataIndex),
            },
          },
        },
        onHover: (event, active) => {
          const hit = active.find((a) => a.datasetIndex === 0 && a.index < layers.length);
          this.show(hit ? hit.index : null);
        },
      },
    });
    canvas.addEventListener('mouseleave', () => this.show(null));
    canvas.addEventListener('keydown', (e) => this.key(e));
  }

  title(i) {
    const l = this.plan.layers[i];
    return `layer ${i + 1} of ${this.plan.count}: ${l.z_bottom.toFixed(2)}–${l.z_top.toFixed(2)} mm`;
  }

  lines(i) {
    const l = this.plan.layers[i];
    const out = [`thickness ${l.height.toFixed(2)} mm`];
    if (l.saliency !== undefined) out.push(`saliency ${l.saliency.toFixed(3)}`);
    if (l.sm !== undefined) out.push(`error (SM) ${l.sm.toFixed(4)}`);
    return out;
  }

  show(i) {
    if (i === this.current) return;
    this.current = i;
    if (i === null || i === undefined) {
      this.onLayer(null);
      return;
    }
    this.readout.textContent = `${this.title(i)} · ${this.lines(i).join(' · ')}`;
    this.onLayer(this.plan.layers[i]);
  }

  key(e) {
    const n = this.plan.layers.length;
    if (!n || !['ArrowLeft', 'ArrowRight', 'Home', 'End'].includes(e.key)) return;
    e.preventDefault();
    let i = this.current ?? -1;
    if (e.key === 'ArrowRight') i = Math.min(n - 1, i + 1);
    else if (e.key === 'ArrowLeft') i = Math.max(0, i - 1);
    else i = e.key === 'Home' ? 0 : n - 1;
    this.show(i);
    const point = this.chart.getDatasetMeta(0).data[i];
    if (point) {
      this.chart.setActiveElements([{ datasetIndex: 0, index: i }]);
      this.chart.tooltip.setActiveElements([{ datasetIndex: 0, index: i }], { x: point.x, y: point.y });
      this.chart.update();
    }
  }

  dispose() {
    this.chart.destroy();
  }
}
