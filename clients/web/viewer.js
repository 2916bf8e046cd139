// The model as the job placed it on the bed, coloured by its saliency (the job's saliency.ply,
// per-vertex `quality` 0..1), with the plan's layer boundaries drawn on its surface as contour
// lines: where the model is salient the lines crowd together. WebGL through Debian's three.js.
import * as THREE from '../vendor/three/three.module.js';
import { Orbit } from './orbit.js';
import { parsePly } from './ply.js';
import { h, themeColor, REGION_COLORS } from './dom.js';

// Low saliency dark blue, high yellow (the "plasma" map; the legend in style.css matches).
const STOPS = [
  [0.05, 0.03, 0.53],
  [0.49, 0.01, 0.66],
  [0.8, 0.28, 0.47],
  [0.97, 0.59, 0.25],
  [0.94, 0.98, 0.13],
];

export function saliencyColor(q) {
  const t = Math.min(1, Math.max(0, q || 0)) * (STOPS.length - 1);
  const i = Math.min(STOPS.length - 2, Math.floor(t));
  const f = t - i;
  return STOPS[i].map((c, k) => c + (STOPS[i + 1][k] - c) * f);
}

export class SaliencyViewer {
  constructor(container, plyBuffer, plan) {
    const mesh = parsePly(plyBuffer);
    this.canvas = h('canvas', {
      class: 'viewer',
      id: 'saliency-view',
      tabindex: 0,
      role: 'img',
      'aria-label': `${plan.model}: saliency on the surface, ${plan.count} layers. Drag, or arrow keys, to turn; wheel, pinch or + and − to zoom; Home to reset.`,
    });
    const boundaries = h('input', { type: 'checkbox', id: 'show-layers', checked: true });
    container.append(
      this.canvas,
      h(
        'div',
        { class: 'legend' },
        h('span', {}, 'saliency 0'),
        h('span', { class: 'ramp', 'aria-hidden': 'true' }),
        h('span', {}, '1'),
        h('label', {}, boundaries, plan.segmentation && plan.segmentation.cut ? ' layer boundaries, a colour per region' : ' layer boundaries'),
      ),
    );
    this.renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(themeColor('--view-bg') || '#20242c');
    this.model = this.surface(mesh);
    this.layers = this.boundaries(mesh, plan);
    this.scene.add(this.model, this.layers);
    boundaries.addEventListener('change', () => ((this.layers.visible = boundaries.checked), this.requestRender()));
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    const light = new THREE.DirectionalLight(0xffffff, 0.6);
    light.position.set(1, -1, 2);
    this.scene.add(light);

    const box = new THREE.Box3().setFromBufferAttribute(this.model.geometry.getAttribute('position'));
    this.box = box;
    const center = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3()).length();
    this.camera = new THREE.PerspectiveCamera(35, 1, size / 100, size * 20);
    this.band = this.highlightBand(box);
    this.scene.add(this.band);
    this.orbit = new Orbit(this.canvas, this.camera, [center.x, center.y, center.z], size * 1.6, () => this.requestRender());
    this.resizer = new ResizeObserver(() => this.resize());
    this.resizer.observe(this.canvas);
    this.resize();
  }

  surface({ positions, quality, index }) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    const colors = new Float32Array(quality.length * 3);
    for (let i = 0; i < quality.length; ++i) colors.set(saliencyColor(quality[i]), i * 3);
    geometry.setAttribute('color', new THREE.BufferAttribute(colors, 3));
    geometry.setIndex(new THREE.BufferAttribute(index, 1));
    geometry.computeVertexNormals();
    const material = new THREE.MeshLambertMaterial({
      vertexColors: THREE.VertexColors,
      side: THREE.DoubleSide,
      polygonOffset: true, // the contour lines sit on the surface without flickering
      polygonOffsetFactor: 1,
      polygonOffsetUnits: 1,
    });
    return new THREE.Mesh(geometry, material);
  }

  // The layer boundaries as lines on the surface: the plan's printed layers in one colour, or for
  // a SegOpt plan each region's own layers in its colour (inside its clip polygon and slab, in
  // the bed's coordinates as the PLY's), the plan plot's colours.
  boundaries(mesh, plan) {
    const regions = (plan.segmentation && plan.segmentation.cut && plan.segmentation.regions) || [];
    const parts = regions.length
      ? regions.map((r, i) => ({
          points: this.contours(mesh, r.boundaries.slice(1, -1), (x, y, z) => z >= r.z_bottom && z <= r.z_top && inside(r.clip, x, y)),
          color: new THREE.Color(REGION_COLORS[i % REGION_COLORS.length]),
        }))
      : [{ points: this.contours(mesh, plan.layers.map((l) => l.z_top).slice(0, -1)), color: new THREE.Color(0x111111) }];
    const count = parts.reduce((n, part) => n + part.points.length, 0);
    const positions = new Float32Array(count);
    const colors = new Float32Array(count);
    let at = 0;
    for (const { points, color } of parts) {
      positions.set(points, at);
      for (let i = 0; i < points.length; i += 3) colors.set([color.r, color.g, color.b], at + i);
      at += points.length;
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    geometry.setAttribute('color', new THREE.BufferAttribute(colors, 3));
    const material = new THREE.LineBasicMaterial({ vertexColors: THREE.VertexColors, transparent: true, opacity: 0.6 });
    return new THREE.LineSegments(geometry, material);
  }

  // Where each boundary height cuts the surface: for every triangle, the boundaries between its
  // lowest and highest corner, each giving one segment across two of its edges (kept when
  // keep(x, y, z) holds at its middle). Returns the segments' ends, x y z each.
  contours({ positions: p, index }, heights, keep = () => true) {
    const zs = Float64Array.from(heights).sort();
    const out = [];
    const cross = (a, b, z) => {
      const t = (z - p[a * 3 + 2]) / (p[b * 3 + 2] - p[a * 3 + 2]);
      out.push(p[a * 3] + (p[b * 3] - p[a * 3]) * t, p[a * 3 + 1] + (p[b * 3 + 1] - p[a * 3 + 1]) * t, z);
    };
    for (let f = 0; f < index.length; f += 3) {
      let lo = index[f];
      let mid = index[f + 1];
      let hi = index[f + 2];
      if (p[lo * 3 + 2] > p[mid * 3 + 2]) [lo, mid] = [mid, lo];
      if (p[mid * 3 + 2] > p[hi * 3 + 2]) [mid, hi] = [hi, mid];
      if (p[lo * 3 + 2] > p[mid * 3 + 2]) [lo, mid] = [mid, lo];
      const zlo = p[lo * 3 + 2];
      const zmid = p[mid * 3 + 2];
      const zhi = p[hi * 3 + 2];
      if (zhi <= zlo) continue;
      let i = lowerBound(zs, zlo);
      for (; i < zs.length && zs[i] < zhi; ++i) {
        const z = zs[i];
        if (z <= zlo) continue;
        cross(lo, hi, z);
        if (z < zmid) cross(lo, mid, z);
        else cross(mid, hi, z);
        const n = out.length;
        if (!keep((out[n - 6] + out[n - 3]) / 2, (out[n - 5] + out[n - 2]) / 2, z)) out.length = n - 6;
      }
    }
    return Float32Array.from(out);
  }

  // A translucent slab showing the layer the plot's pointer is on.
  highlightBand(box) {
    const size = box.getSize(new THREE.Vector3());
    const geometry = new THREE.BoxGeometry(size.x * 1.06, size.y * 1.06, 1);
    const material = new THREE.MeshBasicMaterial({ color: 0x22d3ee, transparent: true, opacity: 0.3, depthWrite: false });
    const band = new THREE.Mesh(geometry, material);
    const c = box.getCenter(new THREE.Vector3());
    band.position.set(c.x, c.y, 0);
    band.visible = false;
    return band;
  }

  // layer: {z_bottom, z_top} from the plan, or null to hide the band.
  highlight(layer) {
    this.band.visible = !!layer;
    if (layer) {
      this.band.scale.z = Math.max(0.01, layer.z_top - layer.z_bottom);
      this.band.position.z = (layer.z_top + layer.z_bottom) / 2;
    }
    this.requestRender();
  }

  resize() {
    const width = this.canvas.clientWidth || 300;
    const height = this.canvas.clientHeight || 300;
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  requestRender() {
    if (this.pending || !this.renderer) return;
    this.pending = requestAnimationFrame(() => {
      this.pending = 0;
      this.renderer.render(this.scene, this.camera);
      const frames = Number(this.canvas.dataset.frames || 0) + 1;
      this.canvas.dataset.frames = String(frames);
      if (frames === 1) performance.mark('saliency-drawn'); // the browser tests time the page by it
    });
  }

  dispose() {
    cancelAnimationFrame(this.pending);
    this.resizer.disconnect();
    this.orbit.dispose();
    for (const o of [this.model, this.layers, this.band]) {
      o.geometry.dispose();
      o.material.dispose();
    }
    this.renderer.dispose();
    this.renderer = null;
  }
}

// Whether (x, y) is inside the polygon [[x, y], …] (an empty one is the whole section).
function inside(polygon, x, y) {
  if (!polygon || !polygon.length) return true;
  let within = false;
  for (let i = 0, j = polygon.length - 1; i < polygon.length; j = i++) {
    const [xi, yi] = polygon[i];
    const [xj, yj] = polygon[j];
    if (yi > y !== yj > y && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) within = !within;
  }
  return within;
}

function lowerBound(sorted, value) {
  let lo = 0;
  let hi = sorted.length;
  while (lo < hi) {
    const m = (lo + hi) >> 1;
    if (sorted[m] < value) lo = m + 1;
    else hi = m;
  }
  return lo;
}
