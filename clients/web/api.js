// The page's one way to the daemon: REST calls under /api/v1 with the key in X-Api-Key, and the
// WebSocket /api/v1/events, which gets the key as a subprotocol ("salient-key.KEY") because a
// browser cannot set headers on it, and a URL would carry the key into logs.

const KEY_STORAGE = 'salient.apiKey';

// An error as the API words it: {"error": {"code", "message"}} with its status.
export class ApiError extends Error {
  constructor(status, code, message) {
    super(message);
    this.status = status;
    this.code = code;
  }
}

let onUnauthorized = () => {};

export const api = {
  key: () => localStorage.getItem(KEY_STORAGE) || '',
  setKey(key) {
    localStorage.setItem(KEY_STORAGE, key);
  },
  clearKey() {
    localStorage.removeItem(KEY_STORAGE);
  },
  // Called with the API's message when a call is refused for its key (401).
  onUnauthorized(fn) {
    onUnauthorized = fn;
  },

  // `base`: 'api' for OctoPrint's surface (its file area, where slicers upload).
  async request(method, path, { json, raw, base = 'api/v1' } = {}) {
    const headers = { 'X-Api-Key': api.key() };
    let body;
    if (json !== undefined) {
      headers['Content-Type'] = 'application/json';
      body = JSON.stringify(json);
    }
    let response;
    try {
      response = await fetch(base + path, { method, headers, body, cache: 'no-store' });
    } catch (e) {
      throw new ApiError(0, 'unreachable', 'salientd cannot be reached: ' + e.message);
    }
    if (!response.ok) throw await errorOf(response);
    if (raw) return response;
    if (response.status === 204) return null;
    return response.json();
  },
  get: (path) => api.request('GET', path),
  post: (path, json = {}) => api.request('POST', path, { json }),
  del: (path) => api.request('DELETE', path),

  // A model and its settings as multipart/form-data; onProgress(fraction) while it uploads.
  submit(file, settings, onProgress) {
    return new Promise((resolve, reject) => {
      const form = new FormData();
      form.append('file', file, file.name);
      form.append('settings', JSON.stringify(settings));
      const xhr = new XMLHttpRequest();
      xhr.open('POST', 'api/v1/jobs');
      xhr.setRequestHeader('X-Api-Key', api.key());
      xhr.upload.onprogress = (e) => e.lengthComputable && onProgress && onProgress(e.loaded / e.total);
      xhr.onerror = () => reject(new ApiError(0, 'unreachable', 'salientd cannot be reached'));
      xhr.onload = () => {
        let doc = null;
        try {
          doc = JSON.parse(xhr.responseText);
        } catch {
          /* not JSON: reported below */
        }
        if (xhr.status >= 200 && xhr.status < 300 && doc) return resolve(doc);
        const e = doc && doc.error ? doc.error : { code: 'http_' + xhr.status, message: xhr.statusText };
        if (xhr.status === 401) onUnauthorized(e.message);
        reject(new ApiError(xhr.status, e.code, e.message));
      };
      xhr.send(form);
    });
  },

  // Fetches with the key and hands the bytes to the browser as a download named `filename`.
  async download(path, filename) {
    const response = await api.request('GET', path, { raw: true });
    const url = URL.createObjectURL(await response.blob());
    const a = document.createElement('a');
    a.href = url;
    a.download = filename;
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(url), 10000);
  },
};

async function errorOf(response) {
  let code = 'http_' + response.status;
  let message = response.statusText || 'HTTP ' + response.status;
  try {
    const doc = await response.json();
    if (doc && doc.error) ({ code, message } = doc.error);
  } catch {
    /* a body that is not the API's JSON error */
  }
  if (response.status === 401) onUnauthorized(message);
  return new ApiError(response.status, code, message);
}

// The event stream: one WebSocket, topics subscribed while someone listens, reconnected with a
// back-off; listeners get (data, message) for the events about their topic.
export class Events {
  constructor(onState) {
    this.listeners = new Map(); // topic -> Set of functions
    this.ws = null;
    this.retry = 500;
    this.stopped = true;
    this.onState = onState || (() => {});
  }

  start() {
    this.stopped = false;
    this.open();
  }

  stop() {
    this.stopped = true;
    if (this.ws) this.ws.close(1000, 'signed out');
    this.ws = null;
  }

  open() {
    if (this.stopped || !api.key()) return;
    // Relative to the page, like every URL here: behind a proxy's prefix (/salient/) too.
    const url = new URL('api/v1/events', document.baseURI);
    url.protocol = url.protocol === 'https:' ? 'wss:' : 'ws:';
    const ws = new WebSocket(url.href, [
      'salient.v1',
      'salient-key.' + api.key(),
    ]);
    this.ws = ws;
    this.onState('connecting');
    ws.onopen = () => {
      this.retry = 500;
      this.onState('live');
      const topics = [...this.listeners.keys()];
      if (topics.length) ws.send(JSON.stringify({ subscribe: topics }));
    };
    ws.onmessage = (e) => this.dispatch(JSON.parse(e.data));
    ws.onclose = () => {
      if (this.ws !== ws) return;
      this.ws = null;
      if (this.stopped) return;
      this.onState('offline');
      setTimeout(() => this.open(), this.retry);
      this.retry = Math.min(this.retry * 2, 10000);
    };
  }

  // Events about a job go to "jobs" and "job/ID", about a printer to "printers" and "printer/ID",
  // a printer's queue to "printer/ID" (its listeners tell it by message.type), the file area to
  // "files": routed by what they are about, each listener hears each event once.
  dispatch(message) {
    const { type, data } = message;
    let topics = [];
    if (type === 'job' && data) topics = ['jobs', 'job/' + data.id];
    else if (type === 'printer' && data) topics = ['printers', 'printer/' + data.id];
    else if (type === 'queue' && data && data.printer) topics = ['printer/' + data.printer];
    else if (type === 'files') topics = ['files'];
    else if (type === 'terminal') topics = [message.topic];
    else if (type === 'error') console.warn('events:', data);
    for (const topic of topics)
      for (const fn of this.listeners.get(topic) || []) {
        try {
          fn(data, message);
        } catch (err) {
          console.error(err);
        }
      }
  }

  // Listens to `topic` until the returned function is called.
  on(topic, fn) {
    if (!this.listeners.has(topic)) {
      this.listeners.set(topic, new Set());
      this.send({ subscribe: [topic] });
    }
    this.listeners.get(topic).add(fn);
    return () => {
      const set = this.listeners.get(topic);
      if (!set) return;
      set.delete(fn);
      if (set.size === 0) {
        this.listeners.delete(topic);
        this.send({ unsubscribe: [topic] });
      }
    };
  }

  send(message) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(message));
  }
}
