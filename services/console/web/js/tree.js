// The behaviour tree of one task as a collapsible, searchable list: one row per node, updated in place
// (a change touches one row, so a 10,000-node tree follows thousands of changes a second). Used live
// by the Tasks page and, fed from the journal, by the Replay page.
import { el, stateBadge, fmtTime, fmtDuration } from './api.js';

function pathKey(id) {
  return id.split('/').map((p) => (/^\d+$/.test(p) ? p.padStart(6, '0') : p));
}
function before(a, b) {
  const ka = pathKey(a), kb = pathKey(b);
  for (let i = 0; i < Math.min(ka.length, kb.length); i++) if (ka[i] !== kb[i]) return ka[i] < kb[i];
  return ka.length < kb.length;
}

export class TreeView {
  constructor(taskId) {
    this.taskId = taskId;
    this.root = el('ul', { class: 'tree', role: 'tree', 'aria-label': `Behaviour tree of task ${taskId}` });
    this.items = new Map();  // node id -> {li, row, ul, data}
    this.pending = new Map();
    this.query = '';
    this.scheduled = false;
  }

  /// Queues a node's new status; rows are updated on the next animation frame.
  update(node) {
    this.pending.set(node.node_id, node);
    if (!this.scheduled) {
      this.scheduled = true;
      requestAnimationFrame(() => this.flush());
    }
  }
  /// Applies every queued change now.
  flush() {
    this.scheduled = false;
    for (const n of this.pending.values()) this.render(n);
    this.pending.clear();
    if (this.query) this.filter(this.query);
  }
  setAll(nodes) {
    for (const n of nodes) this.pending.set(n.node_id, n);
    this.flush();
  }

  item(id, parentId) {
    let it = this.items.get(id);
    if (it) return it;
    const li = el('li', { role: 'treeitem', 'data-node': id, 'aria-expanded': 'true' });
    const row = el('div', { class: 'row' });
    li.append(row);
    it = { li, row, ul: null, data: { node_id: id, state: 'IDLE', type: '', name: '' } };
    this.items.set(id, it);
    const parent = parentId ? this.item(parentId, parentId.includes('/') ? parentId.substring(0, parentId.lastIndexOf('/')) : '') : null;
    let list = this.root;
    if (parent) {
      if (!parent.ul) {
        parent.ul = el('ul', { role: 'group' });
        parent.li.append(parent.ul);
        this.drawRow(parent);
      }
      list = parent.ul;
    }
    let next = null;
    for (const child of list.children) if (before(id, child.dataset.node)) { next = child; break; }
    list.insertBefore(li, next);
    this.drawRow(it);
    return it;
  }

  render(n) {
    const it = this.item(n.node_id, n.parent_id);
    it.data = n;
    this.drawRow(it);
  }

  drawRow(it) {
    const n = it.data;
    const expanded = it.li.getAttribute('aria-expanded') !== 'false';
    const toggle = it.ul
      ? el('button', { class: 'toggle', 'aria-label': `${expanded ? 'Collapse' : 'Expand'} ${n.name || n.node_id}`,
        onclick: () => this.toggle(it) }, expanded ? '▾' : '▸')
      : el('span', { class: 'toggle', 'aria-hidden': 'true' }, '');
    const running = n.state === 'RUNNING' || n.state === 'STOPPING';
    const progress = running && n.progress >= 0
      ? el('progress', { max: '1', value: String(n.progress), 'aria-label': `progress of ${n.name || n.node_id}` }) : null;
    const msg = [n.code, n.message].filter(Boolean).join(': ');
    const times = n.started ? `${fmtTime(n.started)}${n.finished ? '–' + fmtTime(n.finished) : ''} · ${fmtDuration(n.started, n.finished)}` : '';
    it.row.replaceChildren(
      toggle,
      stateBadge(n.state),
      el('span', { class: 'name' }, n.name || n.type || n.node_id, ' ', el('small', {}, `${n.type} ${n.node_id}`)),
      el('span', {}, progress, running && n.progress_text ? el('small', { class: 'muted' }, ' ' + n.progress_text) : null),
      el('span', { class: 'msg' }, n.executor ? `@${n.executor} ` : '', msg),
      el('span', { class: 'time' }, times));
    it.row.dataset.state = n.state;
  }

  toggle(it, open) {
    const expanded = open !== undefined ? open : it.li.getAttribute('aria-expanded') === 'false';
    it.li.setAttribute('aria-expanded', expanded ? 'true' : 'false');
    if (it.ul) it.ul.style.display = expanded ? '' : 'none';
    this.drawRow(it);
  }
  setAllOpen(open) { for (const it of this.items.values()) if (it.ul) this.toggle(it, open); }

  /// Shows the nodes whose name, type, id, code, message or executor contains `query` (case-insensitive),
  /// with their ancestors; everything when empty.
  filter(query) {
    this.query = query.trim().toLowerCase();
    const q = this.query;
    const keep = new Set();
    for (const [id, it] of this.items) {
      const d = it.data;
      const hit = q && [d.name, d.type, id, d.code, d.message, d.executor].some((s) => s && s.toLowerCase().includes(q));
      it.row.classList.toggle('match', Boolean(hit));
      if (!q || hit) {
        for (let p = id; p; p = p.includes('/') ? p.substring(0, p.lastIndexOf('/')) : '') keep.add(p);
      }
    }
    for (const [id, it] of this.items) it.li.classList.toggle('hidden', !keep.has(id));
    if (q) for (const id of keep) { const it = this.items.get(id); if (it && it.ul) this.toggle(it, true); }
  }

  /// States by node id (tests and the replay read it).
  states() {
    const out = {};
    for (const [id, it] of this.items) out[id] = it.data.state;
    return out;
  }
}
