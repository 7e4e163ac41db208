// The live view of a rehearsal (the planner's Rehearse): the recipe runs on the simulated cell of the
// console's rehearsal domain, and this shows that run with the Tasks page's tree (tree.js), from the
// rehearsal's own snapshot and stream (/api/rehearsal/state, /api/rehearsal/events), never mixed with
// the cell's. See docs/console.md, "Rehearsal".
import { el, stateBadge, Store } from './api.js';
import { TreeView } from './tree.js';

const TERMINAL = new Set(['SUCCEEDED', 'FAILED', 'CANCELED', 'REJECTED']);

export class RehearsalView {
  /// `onBack`: called by the "Back to the plan" button.
  constructor(onBack) {
    this.title = el('h2', { id: 'rehearsal-title' });
    this.intro = el('p', { class: 'muted' });
    this.status = el('div', { class: 'toolbar', role: 'status', 'aria-live': 'polite', id: 'rehearsal-status' });
    this.treeBox = el('div', {});
    this.root = el('section', { class: 'panel rehearsal', id: 'rehearsal', 'aria-labelledby': 'rehearsal-title', hidden: true },
      el('div', { class: 'toolbar' }, this.title, el('button', { id: 'rehearsal-back', onclick: () => onBack() }, 'Back to the plan')),
      this.intro, this.status, this.treeBox);
    this.store = null;
    this.tree = null;
    this.taskId = '';
  }

  /// Shows the run of `taskId` on rehearsal domain `domain`, live, to its end state.
  async show(taskId, domain) {
    this.close();
    this.taskId = taskId;
    this.domain = domain;
    this.title.textContent = `Rehearsal — simulated cell, domain ${domain}`;
    this.intro.textContent = `Task ${taskId} runs on the simulated cell of DDS domain ${domain}: nothing real moves. `
      + 'Publishing it to the cell afterwards is still two steps (select, then confirm).';
    this.tree = new TreeView(taskId);
    this.tree.root.setAttribute('aria-label', `Behaviour tree of the rehearsal of ${taskId}`);
    this.treeBox.replaceChildren(this.tree.root);
    this.root.hidden = false;
    this.drawStatus();
    const store = new Store({ state: '/api/rehearsal/state', events: '/api/rehearsal/events', indicator: false });
    this.store = store;
    store.on((type, d) => {
      if (type === 'load') {
        this.tree.setAll([...(store.nodes.get(this.taskId)?.values() || [])]);
        this.drawStatus();
      } else if (type === 'node' && d.task_id === this.taskId) {
        this.tree.update(d);
      } else if (type === 'task' && d.task_id === this.taskId) {
        this.drawStatus();
      }
    });
    await store.connect();
  }

  /// The task's state as the rehearsal controller last published it ('' before its first status).
  state() { return this.store?.tasks.get(this.taskId)?.state || ''; }
  ended() { return TERMINAL.has(this.state()); }

  drawStatus() {
    const t = this.store?.tasks.get(this.taskId);
    const st = t?.state || 'UNKNOWN';
    const text = !t ? 'sent; waiting for the rehearsal controller'
      : TERMINAL.has(st) ? `ended ${st}${t.code ? ` (${t.code}${t.message ? ': ' + t.message : ''})` : ''}`
        : 'running';
    const errors = (t?.errors || []).map((e) => el('li', {}, `${e.pointer}: ${e.message}`));
    this.status.replaceChildren(stateBadge(st), el('span', {}, ` Rehearsal of ${this.taskId} ${text}`),
      ...(errors.length ? [el('ul', { class: 'error' }, ...errors)] : []));
    this.status.dataset.state = st;
  }

  hide() { this.root.hidden = true; }
  close() {
    if (this.store) this.store.close();
    this.store = null;
  }
}
