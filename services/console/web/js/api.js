// Authentication (the login link's ?token=… kept in sessionStorage), REST calls with the bearer token,
// and the live store: the console's state snapshot followed by its event stream (SSE), resumed with
// Last-Event-ID after a reconnect and reloaded when the console says "reset" (restarted console).
import { mergeCell } from './cell_picture.js';

const params = new URLSearchParams(location.search);
if (params.has('token')) {
  sessionStorage.setItem('rigger_token', params.get('token'));
  params.delete('token');
  history.replaceState(null, '', location.pathname + (params.toString() ? '?' + params : '') + location.hash);
}
export const token = () => sessionStorage.getItem('rigger_token') || '';

export class ApiError extends Error {
  constructor(status, body) {
    super(body.error || `HTTP ${status}`);
    this.status = status;
    this.where = body.where || '';
  }
}

/// `body`: sent as JSON; `bytes`: sent as they are (a file's ArrayBuffer or Blob); `raw`: the Response.
export async function api(path, { method = 'GET', body, bytes, raw = false } = {}) {
  const headers = { Authorization: `Bearer ${token()}` };
  if (body !== undefined) headers['Content-Type'] = 'application/json';
  if (bytes !== undefined) headers['Content-Type'] = 'application/octet-stream';
  const res = await fetch(path, { method, headers, body: bytes !== undefined ? bytes : body === undefined ? undefined : JSON.stringify(body) });
  if (!res.ok) {
    let err = {};
    try { err = await res.json(); } catch { /* not JSON */ }
    throw new ApiError(res.status, err);
  }
  return raw ? res : res.json();
}

/// The live picture: tasks, nodes per task, open prompts, executors. Listeners get (type, data).
/// `paths`: where its snapshot and stream come from (the cell's by default; the rehearsal cell's is
/// /api/rehearsal/state and /api/rehearsal/events); `indicator`: whether it shows the link state in the header.
export class Store {
  constructor({ state = '/api/state', events = '/api/events', indicator = true } = {}) {
    this.paths = { state, events };
    this.indicator = indicator;
    this.tasks = new Map();
    this.nodes = new Map();  // task id -> Map(node id -> node)
    this.prompts = new Map();
    this.executors = new Map();
    this.cell = {};  // where things are (cell_picture.js)
    this.revision = null;  // the cell's running revision (rigger/world/cell), when the console has seen one
    this.listeners = new Set();
    this.lastId = '';
    this.connected = false;
    this.transitions = 0;  // node events applied (tests read it)
    this.resets = 0;  // reloads after the console restarted
  }
  on(fn) { this.listeners.add(fn); return () => this.listeners.delete(fn); }
  emit(type, data) { for (const fn of this.listeners) fn(type, data); }

  load(snap) {
    this.tasks.clear(); this.nodes.clear(); this.prompts.clear(); this.executors.clear();
    for (const t of snap.tasks) this.tasks.set(t.task_id, t);
    for (const [task, list] of Object.entries(snap.nodes)) {
      const m = new Map();
      for (const n of list) m.set(n.node_id, n);
      this.nodes.set(task, m);
    }
    for (const p of snap.prompts) this.prompts.set(p.prompt_id, p);
    for (const e of snap.executors) this.executors.set(e.executor_id, e);
    this.cell = mergeCell({}, snap.cell);
    this.revision = snap.revision || null;
    this.lastId = snap.id;
    this.emit('load', snap);
  }
  apply(type, d) {
    if (type === 'task') this.tasks.set(d.task_id, d);
    else if (type === 'node') {
      if (!this.nodes.has(d.task_id)) this.nodes.set(d.task_id, new Map());
      this.nodes.get(d.task_id).set(d.node_id, d);
      this.transitions++;
    } else if (type === 'prompt') {
      if (d.active) this.prompts.set(d.prompt_id, d); else this.prompts.delete(d.prompt_id);
    } else if (type === 'executor') {
      if (d.alive) this.executors.set(d.executor_id, d); else this.executors.delete(d.executor_id);
    } else if (type === 'cell') {
      mergeCell(this.cell, d);
    } else if (type === 'revision') {
      this.revision = d;
    }
    this.emit(type, d);
  }

  async connect() {
    const snap = await api(this.paths.state);
    this.load(snap);
    const url = `${this.paths.events}?token=${encodeURIComponent(token())}&last_event_id=${encodeURIComponent(snap.id)}`;
    const es = new EventSource(url);
    this.source = es;
    const link = this.indicator ? document.getElementById('link') : null;
    es.onopen = () => { this.connected = true; if (link) { link.textContent = 'live'; link.className = 'link live'; } };
    es.onerror = () => { this.connected = false; if (link) { link.textContent = 'reconnecting…'; link.className = 'link down'; } };
    for (const type of ['task', 'node', 'prompt', 'executor', 'cell', 'revision']) {
      es.addEventListener(type, (ev) => { this.lastId = ev.lastEventId; this.apply(type, JSON.parse(ev.data)); });
    }
    // The console restarted (or we fell too far behind): its state is the truth again.
    es.addEventListener('reset', async () => {
      this.resets++;
      const again = await api(this.paths.state);
      this.load(again);
    });
  }
  /// Ends the stream (a page that made its own store closes it when left).
  close() {
    if (this.source) this.source.close();
    this.source = null;
    this.connected = false;
  }
}
export const store = new Store();
window.rigger = Object.assign(window.rigger || {}, { store });

const dialog = () => document.getElementById('confirm');
/// Asks the person to confirm `text`; resolves true on Confirm.
export function confirmDialog(title, text, yes = 'Confirm') {
  const d = dialog();
  d.querySelector('#confirm-title').textContent = title;
  d.querySelector('#confirm-text').textContent = text;
  d.querySelector('#confirm-yes').textContent = yes;
  d.returnValue = '';
  d.showModal();
  return new Promise((resolve) => d.addEventListener('close', () => resolve(d.returnValue === 'ok'), { once: true }));
}

export const STATE_ICONS = {
  IDLE: '○', RUNNING: '▶', STOPPING: '◼', SUCCESS: '✔', FAILURE: '✖', STOPPED: '■',
  ACCEPTED: '…', REJECTED: '⊘', PAUSED: '❚❚', SUCCEEDED: '✔', FAILED: '✖', CANCELED: '■', UNKNOWN: '?',
};
/// A state by icon and text (never colour alone).
export function stateBadge(state) {
  const span = document.createElement('span');
  span.className = `state st-${state}`;
  span.innerHTML = `<span class="icon" aria-hidden="true">${STATE_ICONS[state] || '?'}</span>`;
  span.append(document.createTextNode(state));
  return span;
}
/// hh:mm:ss (UTC) of a time in seconds since the epoch; '' for none. Arithmetic rather than a Date: the
/// Tasks page formats two per row of a 10,000-node tree.
export function fmtTime(s) {
  if (!s) return '';
  const t = ((Math.floor(s) % 86400) + 86400) % 86400;
  const two = (v) => (v < 10 ? '0' : '') + v;
  return `${two(Math.floor(t / 3600))}:${two(Math.floor(t / 60) % 60)}:${two(t % 60)}`;
}
export function fmtDuration(a, b) {
  if (!a) return '';
  const end = b || Date.now() / 1000;
  const s = Math.max(0, end - a);
  return s < 60 ? `${s.toFixed(1)} s` : `${Math.floor(s / 60)} min ${Math.round(s % 60)} s`;
}
export function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') e.className = v;
    else if (k.startsWith('on')) e.addEventListener(k.substring(2), v);
    else if (v !== undefined && v !== null && v !== false) e.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children) if (c !== null && c !== undefined) e.append(c instanceof Node ? c : document.createTextNode(String(c)));
  return e;
}
