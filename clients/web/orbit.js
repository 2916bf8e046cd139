// A small orbit control (Debian's three.js r111 ships its examples' OrbitControls, but not as a
// module we can rely on): drag to turn around the model, wheel or pinch to zoom, and from the
// keyboard, with the canvas focused, arrows to turn, + and − to zoom, Home to start again.
// Z is up, as on the printer's bed.

export class Orbit {
  // camera: a three.js PerspectiveCamera; target: [x, y, z]; radius: the starting distance.
  constructor(element, camera, target, radius, onChange) {
    this.element = element;
    this.camera = camera;
    this.target = target;
    this.home = { theta: -Math.PI / 3, phi: Math.PI / 3, radius };
    Object.assign(this, this.home);
    this.onChange = onChange;
    this.pointers = new Map();
    this.listen();
    this.apply();
  }

  listen() {
    const el = this.element;
    this.handlers = {
      pointerdown: (e) => {
        el.setPointerCapture(e.pointerId);
        this.pointers.set(e.pointerId, [e.clientX, e.clientY]);
      },
      pointermove: (e) => {
        const last = this.pointers.get(e.pointerId);
        if (!last) return;
        if (this.pointers.size === 1) {
          this.turn(-(e.clientX - last[0]) * 0.01, -(e.clientY - last[1]) * 0.01);
        } else if (this.pointers.size === 2) {
          const [a, b] = [...this.pointers.values()];
          const before = Math.hypot(a[0] - b[0], a[1] - b[1]);
          this.pointers.set(e.pointerId, [e.clientX, e.clientY]);
          const [c, d] = [...this.pointers.values()];
          const after = Math.hypot(c[0] - d[0], c[1] - d[1]);
          if (before > 0 && after > 0) this.zoom(before / after);
        }
        this.pointers.set(e.pointerId, [e.clientX, e.clientY]);
      },
      pointerup: (e) => this.pointers.delete(e.pointerId),
      pointercancel: (e) => this.pointers.delete(e.pointerId),
      wheel: (e) => {
        e.preventDefault();
        this.zoom(Math.exp(e.deltaY * 0.001));
      },
      keydown: (e) => {
        const step = 0.1;
        const keys = {
          ArrowLeft: () => this.turn(step, 0),
          ArrowRight: () => this.turn(-step, 0),
          ArrowUp: () => this.turn(0, step),
          ArrowDown: () => this.turn(0, -step),
          '+': () => this.zoom(0.9),
          '=': () => this.zoom(0.9),
          '-': () => this.zoom(1.1),
          Home: () => (Object.assign(this, this.home), this.apply()),
        };
        if (!keys[e.key]) return;
        e.preventDefault();
        keys[e.key]();
      },
    };
    for (const [name, fn] of Object.entries(this.handlers)) el.addEventListener(name, fn, { passive: name !== 'wheel' });
  }

  turn(dTheta, dPhi) {
    this.theta += dTheta;
    this.phi = Math.min(Math.PI - 0.01, Math.max(0.01, this.phi + dPhi));
    this.apply();
  }

  zoom(factor) {
    this.radius = Math.min(this.home.radius * 10, Math.max(this.home.radius * 0.1, this.radius * factor));
    this.apply();
  }

  apply() {
    const [x, y, z] = this.target;
    const s = Math.sin(this.phi);
    this.camera.position.set(
      x + this.radius * s * Math.cos(this.theta),
      y + this.radius * s * Math.sin(this.theta),
      z + this.radius * Math.cos(this.phi),
    );
    this.camera.up.set(0, 0, 1);
    this.camera.lookAt(x, y, z);
    this.onChange();
  }

  dispose() {
    for (const [name, fn] of Object.entries(this.handlers)) this.element.removeEventListener(name, fn);
  }
}
