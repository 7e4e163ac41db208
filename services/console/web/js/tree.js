// The behaviour tree of one task as a collapsible, searchable list: one row per node, updated in place
// (a change touches one row, so a 10,000-node tree follows thousands of changes a second). Used live
// by the Tasks page and, fed from the journal, by the Replay page.
//
// Cost per node is what keeps a 10,000-node tree fast (docs/console.md, bench_console_tree): a row is
// a clone of one template and later changes set only the texts and attributes that differ; a new node
// finds its place among its siblings by binary search on a key computed once; a batch of new nodes is
// sorted first, so that building a whole tree appends; rows off screen are not laid out or painted
// (content-visibility in style.css); a search is re-run over the whole tree only when a change can
// alter what it shows.
import { el, STATE_ICONS, fmtTime, fmtDuration } from './api.js';

/// The sort key of a node id ("root/2/10"): numeric parts compare as numbers.
function pathKey(id) {
  return id.split('/').map((p) => (/^\d+$/.test(p) ? p.padStart(6, '0') : p));
}
function keyBefore(ka, kb) {
  for (let i = 0; i < Math.min(ka.length, kb.length); i++) if (ka[i] !== kb[i]) return ka[i] < kb[i];
  return ka.length < kb.length;
}
const parentOf = (id) => (id.includes('/') ? id.substring(0, id.lastIndexOf('/')) : '');

// One node: its row (toggle, state badge with icon and text as stateBadge() draws it, name with type and
// id, progress, executor and message, times); a parent's children follow in a group list.
const ITEM = document.createElement('template');
ITEM.innerHTML = '<li role="treeitem" aria-expanded="true"><div class="row"><span class="toggle" aria-hidden="true"></span>'
  + '<span class="state"><span class="icon" aria-hidden="true"></span>-</span>'
  + '<span class="name">-<small></small></span><span></span><span class="msg"></span><span class="time"></span></div></li>';

export class TreeView {
  constructor(taskId) {
    this.taskId = taskId;
    this.root = el('ul', { class: 'tree', role: 'tree', 'aria-label': `Behaviour tree of task ${taskId}` });
    this.items = new Map();  // node id -> {li, row, ul, data}
    this.pending = new Map();
    this.query = '';
    this.scheduled = false;
    this.top = [];  // the root list's items in order (each item's children: it.kids)
    this.grown = new Set();  // parents whose number of descendants changed
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
    let changes = [...this.pending.values()];
    this.pending.clear();
    // Many new nodes at once (a whole tree): parents before children and siblings in order, so that
    // each new row is appended to its list.
    const fresh = changes.filter((n) => !this.items.has(n.node_id));
    if (fresh.length > 64) {
      const keyed = fresh.map((n) => [pathKey(n.node_id), n]);
      keyed.sort((a, b) => (keyBefore(a[0], b[0]) ? -1 : keyBefore(b[0], a[0]) ? 1 : 0));
      changes = [...keyed.map((k) => k[1]), ...changes.filter((n) => this.items.has(n.node_id))];
    }
    let refilter = false;
    for (const n of changes) {
      const known = this.items.has(n.node_id);
      const it = this.render(n);
      // A search shows other rows only when a node is new or whether it matches changed.
      if (this.query && (!known || this.matches(it) !== it.row.classList.contains('match'))) refilter = true;
    }
    if (refilter) this.filter(this.query);
    // A group off screen is neither laid out nor painted (style.css); until it was drawn once it takes
    // the height of its rows.
    for (const it of this.grown) it.ul.style.setProperty('--rows', String(it.size - 1));
    this.grown.clear();
  }
  setAll(nodes) {
    for (const n of nodes) this.pending.set(n.node_id, n);
    this.flush();
  }

  item(id, parentId) {
    let it = this.items.get(id);
    if (it) return it;
    const li = ITEM.content.firstChild.cloneNode(true);
    li.dataset.node = id;
    it = { li, row: li.firstChild, ul: null, data: { node_id: id, state: 'IDLE', type: '', name: '' }, key: pathKey(id), kids: null,
      parent: null, size: 1, shown: { toggle: '', progress: '', progressText: '', msg: '', times: '' } };
    this.items.set(id, it);
    const parent = parentId ? this.item(parentId, parentOf(parentId)) : null;
    it.parent = parent;
    for (let p = parent; p; p = p.parent) { p.size++; this.grown.add(p); }
    let list = this.root, kids = this.top;
    if (parent) {
      if (!parent.ul) {
        parent.ul = el('ul', { role: 'group' });
        parent.kids = [];
        parent.li.append(parent.ul);
        this.drawRow(parent);
      }
      list = parent.ul;
      kids = parent.kids;
    }
    // The first sibling after this node: none when it goes last (a tree drawn in order), else by
    // binary search.
    let at = kids.length;
    if (at > 0 && !keyBefore(kids[at - 1].key, it.key)) {
      let lo = 0;
      while (lo < at) {
        const mid = (lo + at) >> 1;
        if (keyBefore(it.key, kids[mid].key)) at = mid; else lo = mid + 1;
      }
    }
    list.insertBefore(li, at < kids.length ? kids[at].li : null);
    kids.splice(at, 0, it);
    this.drawRow(it);
    return it;
  }

  render(n) {
    const it = this.item(n.node_id, n.parent_id);
    it.data = n;
    this.drawRow(it);
    return it;
  }

  /// Sets what differs from what the row shows.
  drawRow(it) {
    const n = it.data;
    const shown = it.shown;
    const cells = it.row.children;
    const label = n.name || n.node_id;
    const expanded = it.li.getAttribute('aria-expanded') !== 'false';
    const toggle = it.ul ? `${expanded ? 'Collapse' : 'Expand'} ${label}` : '';
    if (shown.toggle !== toggle) {
      shown.toggle = toggle;
      if (it.ul && cells[0].tagName === 'BUTTON') {  // the same button: it keeps the keyboard focus
        cells[0].setAttribute('aria-label', toggle);
        cells[0].textContent = expanded ? '▾' : '▸';
      } else {
        cells[0].replaceWith(it.ul
          ? el('button', { class: 'toggle', 'aria-label': toggle, onclick: () => this.toggle(it) }, expanded ? '▾' : '▸')
          : el('span', { class: 'toggle', 'aria-hidden': 'true' }, ''));
      }
    }
    if (shown.state !== n.state) {
      shown.state = n.state;
      const badge = cells[1];
      badge.className = `state st-${n.state}`;
      badge.firstChild.textContent = STATE_ICONS[n.state] || '?';
      badge.lastChild.data = n.state;
      it.row.dataset.state = n.state;
    }
    const name = `${n.name || n.type || n.node_id} `, small = `${n.type} ${n.node_id}`;
    if (shown.name !== name || shown.small !== small) {
      shown.name = name;
      shown.small = small;
      const cell = cells[2];
      cell.firstChild.data = name;
      cell.lastChild.textContent = small;
    }
    const running = n.state === 'RUNNING' || n.state === 'STOPPING';
    const progress = running && n.progress >= 0 ? String(n.progress) : '';
    const progressText = running && n.progress_text ? n.progress_text : '';
    if (shown.progress !== progress || shown.progressText !== progressText || (progress && shown.label !== label)) {
      shown.progress = progress;
      shown.progressText = progressText;
      shown.label = label;
      cells[3].replaceChildren(...[
        progress ? el('progress', { max: '1', value: progress, 'aria-label': `progress of ${label}` }) : null,
        progressText ? el('small', { class: 'muted' }, ' ' + progressText) : null].filter(Boolean));
    }
    const msg = `${n.executor ? `@${n.executor} ` : ''}${[n.code, n.message].filter(Boolean).join(': ')}`;
    if (shown.msg !== msg) {
      shown.msg = msg;
      cells[4].textContent = msg;
    }
    const times = n.started ? `${fmtTime(n.started)}${n.finished ? '–' + fmtTime(n.finished) : ''} · ${fmtDuration(n.started, n.finished)}` : '';
    if (shown.times !== times) {
      shown.times = times;
      cells[5].textContent = times;
    }
  }

  toggle(it, open) {
    const expanded = open !== undefined ? open : it.li.getAttribute('aria-expanded') === 'false';
    it.li.setAttribute('aria-expanded', expanded ? 'true' : 'false');
    if (it.ul) it.ul.style.display = expanded ? '' : 'none';
    this.drawRow(it);
  }
  setAllOpen(open) { for (const it of this.items.values()) if (it.ul) this.toggle(it, open); }

  matches(it) {
    const d = it.data;
    const q = this.query;
    return Boolean(q) && [d.name, d.type, d.node_id, d.code, d.message, d.executor].some((s) => s && s.toLowerCase().includes(q));
  }

  /// Shows the nodes whose name, type, id, code, message or executor contains `query` (case-insensitive),
  /// with their ancestors; everything when empty.
  filter(query) {
    this.query = query.trim().toLowerCase();
    const q = this.query;
    const keep = new Set();
    for (const [id, it] of this.items) {
      const hit = this.matches(it);
      it.row.classList.toggle('match', hit);
      if (!q || hit) {
        for (let p = id; p; p = parentOf(p)) keep.add(p);
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
