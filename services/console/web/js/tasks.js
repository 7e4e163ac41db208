// Tasks: every task the journal and the live stream know, the live tree of any number of tasks, the
// running nodes, and the task commands (pause/stop: operator; cancel/resume/publish: programmer).
import { api, store, el, stateBadge, fmtTime, confirmDialog } from './api.js';
import { TreeView } from './tree.js';
import { mergeCell } from './cell_picture.js';
import { cellRevisionsPanel } from './cell_revisions.js';

const TERMINAL = new Set(['SUCCEEDED', 'FAILED', 'CANCELED', 'REJECTED']);

export function tasksPage(main, me) {
  const selected = new Set();
  const trees = new Map();
  const list = el('ul', { class: 'tasklist', 'aria-label': 'Tasks' });
  const treesBox = el('div', {});
  const running = el('ul', { class: 'running', 'aria-label': 'Running nodes' });
  const notice = el('p', { role: 'status', 'aria-live': 'polite' });
  const search = el('input', { type: 'search', placeholder: 'Search nodes (name, type, id, code, message)', 'aria-label': 'Search nodes',
    oninput: () => { for (const t of trees.values()) t.filter(search.value); } });
  const canProgram = me.role === 'programmer';
  const canOperate = canProgram || me.role === 'operator';
  const history = new Map();  // task id -> journal state (finished tasks from before this console started)

  const publishBox = canProgram ? el('details', { class: 'panel' },
    el('summary', {}, 'Publish a recipe'),
    el('p', { class: 'muted' }, 'Paste a recipe (JSON). Publishing is two steps: select, then confirm within a few seconds.'),
    el('textarea', { id: 'recipe-text', rows: '6', cols: '60', 'aria-label': 'Recipe JSON' }),
    el('div', { class: 'toolbar' }, el('button', { class: 'primary', onclick: () => publish() }, 'Publish…'))) : null;

  // The 3D cell, drawn once opened (its parts come from the CAD service), then moved by the stream.
  const cellBox = el('div', { class: 'cell3d' });
  let cell = null;
  const cellPanel = el('details', { class: 'panel', ontoggle: () => {
    if (!cellPanel.open || cell) return;
    cellBox.textContent = 'Loading the cell…';
    cell = import('./cell3d.js').then(async ({ Cell3d }) => {
      const view = new Cell3d(cellBox, say);
      window.rigger.cell3d = view.state;
      view.picture = store.cell;
      await view.load();
      return view;
    }).catch((e) => {
      say(`3D cell: ${e.message} (close and open the panel to try again)`, true);
      cell = null;
      return null;
    });
  } }, el('summary', {}, '3D cell'), cellBox);

  const revisions = cellRevisionsPanel(me, (text, bad) => say(text, bad));  // say is defined below

  main.replaceChildren(el('h1', {}, 'Tasks'), cellPanel, revisions.panel, el('div', { class: 'cols' },
    el('section', { class: 'panel', 'aria-labelledby': 'tl' }, el('h2', { id: 'tl' }, 'Tasks'), list,
      el('h2', { id: 'rn' }, 'Running nodes'), running),
    el('section', {}, publishBox, notice, el('div', { class: 'panel' }, el('div', { class: 'toolbar' }, search,
      el('button', { onclick: () => { for (const t of trees.values()) t.setAllOpen(true); } }, 'Expand all'),
      el('button', { onclick: () => { for (const t of trees.values()) t.setAllOpen(false); } }, 'Collapse all')), treesBox))));

  const say = (text, bad = false) => { notice.textContent = text; notice.className = bad ? 'error' : ''; };

  async function command(taskId, kind) {
    try {
      if (kind === 'resume') {
        const sel = await api(`/api/tasks/${encodeURIComponent(taskId)}/resume`, { method: 'POST' });
        if (!(await confirmDialog('Resume the task?', `Resume ${taskId}: the robot and the crane may move.`, 'Resume'))) return say('Resume not confirmed.');
        await api('/api/confirm', { method: 'POST', body: { confirmation_id: sel.confirmation_id } });
      } else {
        await api(`/api/tasks/${encodeURIComponent(taskId)}/${kind}`, { method: 'POST', body: {} });
      }
      say(`${kind} sent for ${taskId}.`);
    } catch (e) { say(`${kind} ${taskId}: ${e.message}`, true); }
  }
  async function publish() {
    const text = document.getElementById('recipe-text').value;
    let recipe;
    try { recipe = JSON.parse(text); } catch (e) { return say(`The recipe is not JSON: ${e.message}`, true); }
    try {
      const sel = await api('/api/recipes', { method: 'POST', body: recipe });
      if (!(await confirmDialog('Publish the recipe?', `Publish ${recipe.task_id}: the task starts and the robot and the crane move.`, 'Publish'))) return say('Publish not confirmed.');
      await api('/api/confirm', { method: 'POST', body: { confirmation_id: sel.confirmation_id } });
      say(`Published ${recipe.task_id}.`);
      selected.add(recipe.task_id);
      draw();
    } catch (e) { say(`Publish: ${e.message}`, true); }
  }

  function taskState(id) { return store.tasks.get(id)?.state || history.get(id) || 'UNKNOWN'; }
  function drawList() {
    const ids = new Set([...store.tasks.keys(), ...history.keys()]);
    const rows = [...ids].map((id) => ({ id, t: store.tasks.get(id) }))
      .sort((a, b) => (b.t?.submitted || 0) - (a.t?.submitted || 0));
    list.replaceChildren(...rows.map(({ id, t }) => el('li', {}, el('button', { 'aria-pressed': selected.has(id) ? 'true' : 'false', 'data-task': id,
      onclick: () => { if (selected.has(id)) selected.delete(id); else selected.add(id); draw(); } },
    el('span', {}, id, el('br'), el('small', { class: 'muted' }, t ? fmtTime(t.submitted) : 'journal')), stateBadge(taskState(id))))));
  }
  // The running nodes, kept as node events come (not found by walking every node of every task).
  const active = new Map();  // "task\nnode" -> node
  const isActive = (n) => n.state === 'RUNNING' || n.state === 'STOPPING';
  function noteActive(task, n) {
    const key = `${task}\n${n.node_id}`;
    if (isActive(n)) active.set(key, [task, n]); else active.delete(key);
  }
  function collectActive() {
    active.clear();
    for (const [task, nodes] of store.nodes) for (const n of nodes.values()) noteActive(task, n);
  }
  function drawRunning() {
    const items = [];
    for (const [task, n] of active.values()) items.push(el('li', {}, stateBadge(n.state), ` ${n.name || n.type} `, el('small', { class: 'muted' }, `${task} ${n.node_id}${n.executor ? ' @' + n.executor : ''}`)));
    running.replaceChildren(...(items.length ? items : [el('li', { class: 'muted' }, 'none')]));
  }
  // A task's section stays in the page while it is selected; a redraw replaces its heading only, so
  // that a task's change of state does not take a 10,000-node tree out of the document and back.
  const sections = new Map();  // task id -> section
  function drawTrees() {
    for (const id of [...trees.keys()]) if (!selected.has(id)) trees.delete(id);
    for (const id of [...sections.keys()]) if (!trees.has(id)) sections.delete(id);
    const boxes = [];
    for (const id of selected) {
      let t = trees.get(id);
      if (!t) {
        t = new TreeView(id);
        trees.set(id, t);
        sections.delete(id);
        t.setAll([...(store.nodes.get(id)?.values() || [])]);
        if (search.value) t.filter(search.value);
      }
      const st = taskState(id);
      const task = store.tasks.get(id);
      const live = !TERMINAL.has(st);
      const buttons = [];
      if (live && canOperate) buttons.push(el('button', { onclick: () => command(id, 'pause') }, 'Pause'), el('button', { class: 'danger', onclick: () => command(id, 'stop') }, 'Stop'));
      if (live && canProgram) buttons.push(el('button', { onclick: () => command(id, 'cancel') }, 'Cancel'), el('button', { onclick: () => command(id, 'resume') }, 'Resume…'));
      const heading = el('div', { class: 'toolbar' }, el('h2', {}, id), stateBadge(st),
        task?.code ? el('span', { class: 'muted' }, `${task.code}${task.message ? ': ' + task.message : ''}`) : null, ...buttons);
      let box = sections.get(id);
      if (box) box.firstChild.replaceWith(heading);
      else sections.set(id, box = el('section', { class: 'task', 'data-task': id, 'aria-label': `Task ${id}` }, heading, t.root));
      boxes.push(box);
    }
    const shown = [...treesBox.children];
    if (boxes.length !== shown.length || boxes.some((b, i) => b !== shown[i]) || !boxes.length) {
      treesBox.replaceChildren(...(boxes.length ? boxes : [el('p', { class: 'muted' }, 'Select one or more tasks on the left to see their trees.')]));
    }
  }
  function draw() { drawList(); drawRunning(); drawTrees(); }

  // The newest running tasks open by themselves.
  for (const [id, t] of store.tasks) if (!TERMINAL.has(t.state)) selected.add(id);
  collectActive();
  draw();
  api('/api/journal').then((r) => {
    for (const e of r.entries) if (!store.tasks.has(e.node_id)) history.set(e.node_id, e.code);
    drawList();
  }).catch((e) => say(`Journal: ${e.message}`, true));

  let runningScheduled = false;
  const off = store.on((type, d) => {
    if ((type === 'cell' || type === 'load') && cell) cell.then((v) => v?.show(store.cell));
    if (type === 'revision' && cell) cell.then((v) => v?.reload());
    if (type === 'load') { trees.clear(); collectActive(); draw(); return; }
    if (type === 'node') {
      noteActive(d.task_id, d);
      if (!store.tasks.has(d.task_id) && !selected.has(d.task_id)) return;
      const t = trees.get(d.task_id);
      if (t) t.update(d);
      if (!runningScheduled) { runningScheduled = true; setTimeout(() => { runningScheduled = false; drawRunning(); }, 200); }
    } else if (type === 'task') {
      if (d.state === 'ACCEPTED' || d.state === 'RUNNING') selected.add(d.task_id);
      drawList(); drawTrees();
    }
  });
  window.rigger.tasksPage = { trees, selected };
  return () => { off(); revisions.off(); if (cell) cell.then((v) => v?.dispose()); };
}
