// #/keys: who may use salientd. Apps waiting for a key (OctoPrint's application keys: Cura, phone
// apps) with Approve and Deny, for an admin; the keys (an admin's view: all of them) with Revoke.
// An admin also makes a key here (shown once). Polled every 3 s while open: a request waits only a
// few minutes.
import { api } from './api.js';
import { h, fill, toast, act, when, confirmed, announce } from './dom.js';

export async function keysView(main) {
  const pending = h('div', { id: 'key-requests', 'aria-live': 'polite' });
  const list = h('div', { id: 'key-list' });
  const maker = h('section', { class: 'card', hidden: true, 'aria-label': 'Make a key' });
  fill(
    main,
    h('h1', {}, 'Keys'),
    h('section', { class: 'card' }, h('h2', {}, 'Apps asking for a key'), pending),
    h('section', { class: 'card' }, h('h2', {}, 'API keys'), list),
    maker,
  );
  let admin = true;
  let shown = '';
  const refresh = async () => {
    try {
      const { keys, you } = await api.get('/keys');
      admin = you.role === 'admin';
      showKeys(list, keys, you, refresh);
      if (admin && maker.hidden) {
        fill(maker, keyForm(refresh));
        maker.hidden = false;
      }
      if (!admin) {
        fill(pending, h('p', { class: 'muted' }, 'Only an admin may approve or deny app requests.'));
        return;
      }
      const { requests } = await api.get('/keys/requests');
      const text = JSON.stringify(requests.map((r) => r.token));
      if (text === shown) return; // unchanged: keep the buttons where the pointer is
      shown = text;
      showRequests(pending, requests, refresh);
    } catch (e) {
      toast(e.message);
    }
  };
  await refresh();
  const timer = setInterval(refresh, 3000);
  return () => clearInterval(timer);
}

function showRequests(el, requests, refresh) {
  if (!requests.length) return fill(el, h('p', { class: 'muted' }, 'No app is waiting for a key.'));
  fill(
    el,
    h(
      'ul',
      { class: 'key-requests' },
      requests.map((r) => {
        const decide = (decision) => (e) =>
          act(e.target, async () => {
            await api.post('/keys/requests/' + encodeURIComponent(r.token), { decision });
            announce(`${r.app}: ${decision ? 'approved' : 'denied'}`);
            await refresh();
          });
        return h(
          'li',
          { dataset: { token: r.token } },
          h('strong', {}, r.app),
          ` from ${r.remote}`,
          r.user ? ` for ${r.user}` : '',
          ' ',
          h('button', { type: 'button', class: 'approve', onclick: decide(true) }, 'Approve'),
          ' ',
          h('button', { type: 'button', class: 'quiet deny', onclick: decide(false) }, 'Deny'),
        );
      }),
    ),
  );
}

// A new key for a person or an app: user, role (for a new user) and label; the key is shown
// once, as the API returns it once.
function keyForm(refresh) {
  const user = h('input', { id: 'new-key-user', required: true, autocomplete: 'off', spellcheck: false, placeholder: 'e.g. olive' });
  const role = h(
    'select',
    { id: 'new-key-role' },
    [['viewer', 'viewer: sees'], ['operator', 'operator: prints and controls'], ['admin', 'admin: also manages keys']].map(([v, t]) =>
      h('option', { value: v }, t),
    ),
  );
  const label = h('input', { id: 'new-key-label', autocomplete: 'off', placeholder: 'e.g. phone' });
  const made = h('div', { id: 'made-key-box', 'aria-live': 'polite' });
  const field = (text, input) => h('div', { class: 'field' }, h('label', { for: input.id }, text), input);
  const submit = h('button', { type: 'submit' }, 'Make the key');
  const form = h(
    'form',
    {
      id: 'new-key',
      class: 'settings',
      onsubmit: (e) => {
        e.preventDefault();
        act(submit, async () => {
          const body = { user: user.value.trim(), role: role.value, label: label.value.trim() };
          const k = await api.post('/keys', body);
          fill(
            made,
            h('p', {}, `Key ${k.id} for ${k.user} (${k.role}). Copy it now: salientd keeps only its hash and shows it just this once.`),
            h('code', { id: 'made-key', class: 'made-key' }, k.key),
          );
          user.value = label.value = '';
          await refresh();
        });
      },
    },
    field('User', user),
    field('Role (of a new user)', role),
    field('Label', label),
    h('div', { class: 'field checks' }, submit),
  );
  return [h('h2', {}, 'Make a key'), form, made];
}

function showKeys(el, keys, you, refresh) {
  fill(
    el,
    h(
      'table',
      {},
      h('thead', {}, h('tr', {}, ['Id', 'User', 'Role', 'Label', 'Made', ''].map((t) => h('th', {}, t)))),
      h(
        'tbody',
        {},
        keys.map((k) =>
          h(
            'tr',
            { dataset: { id: String(k.id) } },
            h('td', {}, String(k.id)),
            h('td', {}, k.user),
            h('td', {}, k.role),
            h('td', {}, k.label),
            h('td', {}, when(k.created_at)),
            h(
              'td',
              {},
              k.id === you.key
                ? h('span', { class: 'muted' }, 'this page’s key')
                : h(
                    'button',
                    {
                      type: 'button',
                      class: 'quiet',
                      onclick: (e) =>
                        act(e.target, async () => {
                          if (!(await confirmed(`Revoke key ${k.id} of ${k.user}?`, 'Revoke'))) return;
                          await api.del('/keys/' + k.id);
                          toast(`Key ${k.id} revoked`, 'info');
                          await refresh();
                        }),
                    },
                    'Revoke',
                  ),
            ),
          ),
        ),
      ),
    ),
  );
}
