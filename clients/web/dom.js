// Small DOM and formatting helpers shared by the views. Elements are built with h() (never from
// HTML strings: text from the API is always text), styles live in style.css (the CSP allows no
// inline style attribute).

// h('button', {class: 'x', onclick: f}, 'text', child…): an element with attributes and children.
export function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [name, value] of Object.entries(attrs || {})) {
    if (value === undefined || value === null || value === false) continue;
    if (name.startsWith('on')) el.addEventListener(name.slice(2), value);
    else if (name === 'class') el.className = value;
    else if (name === 'dataset') Object.assign(el.dataset, value);
    else if (name in el && typeof value !== 'string') el[name] = value;
    else el.setAttribute(name, value === true ? '' : value);
  }
  append(el, children);
  return el;
}

function append(el, children) {
  for (const c of children.flat(Infinity)) {
    if (c === undefined || c === null || c === false) continue;
    el.append(c instanceof Node ? c : document.createTextNode(String(c)));
  }
}

// Replaces an element's children.
export function fill(el, ...children) {
  el.replaceChildren();
  append(el, children);
  return el;
}

let toastTimer = 0;
// A short message at the bottom of the screen (errors in the API's words).
export function toast(message, kind = 'error') {
  const el = document.getElementById('toast');
  el.textContent = message;
  el.className = 'toast ' + kind;
  el.hidden = false;
  clearTimeout(toastTimer);
  toastTimer = setTimeout(() => (el.hidden = true), kind === 'error' ? 8000 : 3000);
}

// Tells screen readers of a change of state (not of every progress step: those stay quiet).
export function announce(message) {
  document.getElementById('announcer').textContent = message;
}

// A library the page imports from /vendor/ failed to load: the server's own words when it has
// some (a 404 naming the Debian package to install), else the browser's.
export async function whyNotLoaded(error) {
  // Relative to this module: the page may be served under a proxy's prefix (/salient/).
  const libraries = ['../vendor/three/three.module.js', '../vendor/chart.js/chart.esm.js'];
  for (const url of libraries.map((u) => new URL(u, import.meta.url))) {
    try {
      const r = await fetch(url, { method: 'GET', cache: 'no-store' });
      if (!r.ok) return (await r.json()).error.message;
    } catch {
      /* the server is not answering: the browser's message says so */
    }
  }
  return error.message;
}

// Runs an async action from a button: disabled while it runs, its error shown as the API says it.
export async function act(button, fn) {
  if (button) button.disabled = true;
  try {
    return await fn();
  } catch (e) {
    toast(e.message);
  } finally {
    if (button) button.disabled = false;
  }
}

export function minutes(seconds) {
  if (seconds === null || seconds === undefined || !isFinite(seconds)) return '–';
  const m = seconds / 60;
  if (Math.abs(m) < 60) return `${m.toFixed(1)} min`;
  const hours = Math.floor(Math.abs(m) / 60);
  return `${m < 0 ? '−' : ''}${hours} h ${Math.round(Math.abs(m) - hours * 60)} min`;
}

// A span of time in words with its units ("42 s", "7 min 06 s", "1 h 07 min"): "7:06" left a
// printer owner guessing between minutes and hours.
export function duration(seconds) {
  if (seconds === null || seconds === undefined || !isFinite(seconds)) return '–';
  const s = Math.max(0, Math.round(seconds));
  const two = (n) => String(n).padStart(2, '0');
  if (s < 60) return `${s} s`;
  if (s < 3600) return `${Math.floor(s / 60)} min ${two(s % 60)} s`;
  const m = Math.round(s / 60);
  return `${Math.floor(m / 60)} h ${two(m % 60)} min`;
}

export function percent(fraction, digits = 0) {
  return fraction === null || fraction === undefined ? '–' : `${(fraction * 100).toFixed(digits)} %`;
}

export function signed(value, digits = 1) {
  return (value > 0 ? '+' : value < 0 ? '−' : '') + Math.abs(value).toFixed(digits);
}

export function when(epochSeconds) {
  if (!epochSeconds) return '–';
  const d = new Date(epochSeconds * 1000);
  const today = new Date().toDateString() === d.toDateString();
  return today ? d.toLocaleTimeString() : d.toLocaleString();
}

export function celsius(t) {
  return t && t.actual !== null && t.actual !== undefined
    ? `${t.actual.toFixed(1)} °C` + (t.target ? ` → ${t.target.toFixed(0)} °C` : '')
    : '–';
}

// A progress bar with its label for screen readers.
export function progressBar(fraction, label) {
  return h('progress', { max: 1, value: Math.max(0, Math.min(1, fraction || 0)), 'aria-label': label });
}

export function badge(state) {
  return h('span', { class: 'badge state-' + state }, state);
}

// Asks before an action that costs a print (a modal dialog: Escape or "Keep" declines);
// resolves to true when the user agreed.
export function confirmed(question, yes = 'Yes') {
  return new Promise((resolve) => {
    const dialog = h(
      'dialog',
      { class: 'confirm', 'aria-label': question },
      h('p', {}, question),
      h(
        'form',
        { method: 'dialog', class: 'actions' },
        h('button', { value: 'no', class: 'quiet' }, 'Keep'),
        h('button', { value: 'yes', class: 'danger' }, yes),
      ),
    );
    dialog.addEventListener('close', () => {
      resolve(dialog.returnValue === 'yes');
      dialog.remove();
    });
    document.body.append(dialog);
    dialog.showModal();
  });
}

// SegOpt's regions, in the plan plot and on the model alike.
export const REGION_COLORS = ['#e11d48', '#16a34a', '#9333ea', '#ea580c', '#0891b2', '#ca8a04'];

// The theme's colours, read from CSS variables (charts and the 3D view follow light/dark).
export function themeColor(name) {
  return getComputedStyle(document.documentElement).getPropertyValue(name).trim();
}
