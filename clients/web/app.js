// The page: sign-in, the event stream, and the views by address (#/jobs, #/jobs/ID,
// #/printers, #/printers/ID, #/keys). Each view is a function (main, params, context) that fills `main`
// and returns what undoes it (listeners, timers, WebGL) when the user goes elsewhere.
import { api, Events } from './api.js';
import { h, fill, toast } from './dom.js';
import { jobsView } from './jobs.js';
import { jobView } from './job_page.js';
import { printersView, printerView } from './printers.js';
import { keysView } from './keys.js';

// Figures the browser tests read: when each event reached the page's DOM.
window.salientMetrics = { eventLatencies: [] };

const main = document.getElementById('main');
const linkState = document.getElementById('link-state');
const signOut = document.getElementById('sign-out');
const events = new Events((state) => {
  linkState.textContent = { live: 'live', connecting: 'connecting…', offline: 'offline: reconnecting…' }[state];
  linkState.className = 'link-state ' + state;
});
let undo = null;
let rendered = '';
let signingIn = false;

const routes = [
  [/^#\/jobs\/([\w-]+)$/, (m) => jobView(main, m[1], context())],
  [/^#\/printers\/([\w-]+)$/, (m) => printersOrPrinter(m[1])],
  [/^#\/printers$/, () => printersView(main, context())],
  [/^#\/keys$/, () => keysView(main)],
  [/^(#\/jobs)?$/, () => jobsView(main, context())],
];

function printersOrPrinter(id) {
  return printerView(main, id, context());
}

function context() {
  return { events, navigate: (hash) => (location.hash = hash) };
}

async function render() {
  if (!api.key()) return showSignIn();
  const hash = location.hash === '#/' ? '' : location.hash;
  if (undo && rendered === hash) return;
  if (undo) undo();
  undo = null;
  rendered = hash;
  for (const a of document.querySelectorAll('[data-nav]'))
    a.toggleAttribute('aria-current', hash.startsWith('#/' + a.dataset.nav) || (!hash && a.dataset.nav === 'jobs'));
  for (const [pattern, view] of routes) {
    const m = hash.match(pattern);
    if (!m) continue;
    main.replaceChildren();
    undo = (await view(m)) || (() => {});
    return;
  }
  fill(main, h('h1', {}, 'Not found'), h('p', {}, 'Nothing here: ', h('a', { href: '#/jobs' }, 'the jobs')));
  undo = () => {};
}

function showSignIn(message) {
  if (undo) undo();
  undo = null;
  rendered = '';
  events.stop();
  signOut.hidden = true;
  linkState.textContent = '';
  const input = h('input', {
    id: 'api-key',
    type: 'password',
    autocomplete: 'current-password',
    required: true,
    spellcheck: false,
    'aria-describedby': 'key-help',
  });
  const error = h('p', { id: 'sign-in-error', class: 'error', role: 'alert' }, message || '');
  const button = h('button', { type: 'submit' }, 'Sign in');
  const form = h(
    'form',
    { class: 'card sign-in', onsubmit: (e) => signIn(e, input, error, button) },
    h('h1', {}, 'Sign in to salientd'),
    h('label', { for: 'api-key' }, 'API key'),
    input,
    h(
      'p',
      { id: 'key-help', class: 'muted' },
      'salientd prints its key once, at its first start, and keeps it in its data directory as ',
      h('code', {}, 'api-key'),
      ' (',
      h('code', {}, 'var/api-key'),
      ' after ',
      h('code', {}, 'make run'),
      '). The page keeps it in this browser.',
    ),
    error,
    button,
  );
  fill(main, form);
  input.focus();
}

async function signIn(e, input, error, button) {
  e.preventDefault();
  const key = input.value.trim();
  button.disabled = true;
  error.textContent = '';
  signingIn = true; // a refusal now is this form's to report
  api.setKey(key);
  try {
    await api.get('/printers'); // any keyed call: the server judges the key
    startSession();
  } catch (err) {
    api.clearKey();
    // A typed key that is refused is unknown (mistyped or revoked): the API's words for a request
    // without one ("a key is required") would mislead.
    error.textContent =
      err.status === 401
        ? 'The server refused this key: it is not one salientd knows (mistyped, or revoked). Check it against the api-key file in salientd’s data directory.'
        : `Cannot sign in: ${err.message}`;
    input.select();
  } finally {
    signingIn = false;
    button.disabled = false;
  }
}

function startSession() {
  signOut.hidden = false;
  events.start();
  render();
}

api.onUnauthorized((message) => {
  if (!api.key() || signingIn) return;
  api.clearKey();
  showSignIn(`The server refused the stored key: ${message}`);
});
signOut.addEventListener('click', () => {
  api.clearKey();
  showSignIn();
});
window.addEventListener('hashchange', () => {
  render().catch((e) => toast(e.message));
  main.focus({ preventScroll: true });
});

if (api.key()) startSession();
else showSignIn();
