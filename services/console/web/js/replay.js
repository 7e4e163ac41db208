// Replay: a finished task's timeline from the controller's journal, stepped with a slider and drawn by
// the same tree renderer as the live page, with the run's plots (kept on disk by the console) and a
// line at the slider's moment, and the 3D cell as it was at that moment (the run's cell rows, kept with
// its plots).
import { api, store, el, fmtTime, stateBadge } from './api.js';
import { TreeView } from './tree.js';
import { PlotCharts } from './plot_charts.js';
import { cellAt } from './cell_picture.js';

export function replayPage(main, _me, args) {
  const picker = el('select', { 'aria-label': 'Task to replay', onchange: () => open(picker.value) });
  const slider = el('input', { type: 'range', min: '0', max: '0', value: '0', 'aria-label': 'Position in the timeline', disabled: true });
  const clock = el('span', { class: 'muted', 'aria-live': 'off' });
  const event = el('p', { class: 'muted' });
  const treeBox = el('div', {});
  const notice = el('p', { role: 'status' });
  const plotBox = el('div', {});
  const plotNotice = el('p', { role: 'status', class: 'muted' });
  const charts = new PlotCharts(plotBox, 'rigger-replay');
  const cellBox = el('div', { class: 'cell3d' });
  const cellNotice = el('p', { role: 'status', class: 'muted' });
  const play = el('button', { onclick: () => toggle(), disabled: true }, '▶ Play');
  main.replaceChildren(el('h1', {}, 'Replay'), el('section', { class: 'panel replay' },
    el('div', { class: 'toolbar' }, el('label', {}, 'Task ', picker), play, clock), slider, event, notice), el('section', { class: 'panel' }, treeBox),
    el('section', { class: 'panel', 'aria-label': 'Plots of the run' }, el('h2', {}, 'Plots of the run'), plotNotice, plotBox),
    el('section', { class: 'panel', 'aria-label': 'The cell at the slider\'s moment' }, el('h2', {}, 'The cell at the slider\'s moment'), cellNotice, cellBox));
  // For tests: the step shown, the tree, and the plots: series(label) as the charts draw it and the
  // time (s) of the line at the slider's moment.
  // cell: the run's cell rows and the 3D view's state (cell3d.js), whose picture is the slider's moment.
  const page = { task: '', position: 0, length: 0, tree: null, plots: { rows: 0, marker: null, series: (label) => charts.series(label) },
    cell: { rows: [], view: null } };
  window.rigger.replay = page;
  let steps = [];
  let timer = null;
  let cell = null;  // the Cell3d, once its parts are drawn

  function toggle() {
    if (timer) { clearInterval(timer); timer = null; play.textContent = '▶ Play'; return; }
    play.textContent = '❚❚ Pause';
    timer = setInterval(() => {
      if (+slider.value >= steps.length) return toggle();
      slider.value = String(+slider.value + 1);
      show(+slider.value);
    }, 150);
  }

  function show(k) {
    const states = new Map();
    for (let i = 0; i < k; i++) states.set(steps[i].node_id, steps[i]);
    for (const id of page.tree.items.keys()) {
      const s = states.get(id);
      const base = page.base.get(id) || { node_id: id };
      page.tree.update({ ...base, state: s ? s.code : 'IDLE', message: s ? s.message : '', code: '', progress: -1, executor: s ? base.executor : '',
        started: 0, finished: 0 });
    }
    page.tree.flush();
    page.position = k;
    const cur = steps[k - 1];
    clock.textContent = cur ? `${fmtTime(cur.stamp)} · step ${k} of ${steps.length}` : `start · ${steps.length} steps`;
    event.replaceChildren(...(cur ? [`${cur.node_id} → `, stateBadge(cur.code), cur.message ? ` ${cur.message}` : ''] : []));
    page.plots.marker = cur ? cur.stamp : (steps[0] ? steps[0].stamp : null);
    charts.setMarker(page.plots.marker);
    if (cell) cell.show(cellAt(page.cell.rows, page.plots.marker ?? -Infinity));
  }

  async function open(taskId) {
    if (!taskId) return;
    notice.textContent = '';
    try {
      const r = await api(`/api/journal?task=${encodeURIComponent(taskId)}`);
      steps = r.entries.filter((e) => e.kind === 'NODE').sort((a, b) => a.stamp - b.stamp);
      const known = store.nodes.get(taskId) || new Map();
      const tree = new TreeView(taskId);
      const ids = new Set([...known.keys(), ...steps.map((s) => s.node_id)]);
      tree.setAll([...ids].map((id) => ({ ...(known.get(id) || { node_id: id, type: '', name: '' }),
        parent_id: known.get(id)?.parent_id ?? (id.includes('/') ? id.substring(0, id.lastIndexOf('/')) : ''), state: 'IDLE' })));
      page.task = taskId; page.tree = tree; page.length = steps.length;
      page.base = new Map([...tree.items].map(([id, it]) => [id, it.data]));
      treeBox.replaceChildren(el('h2', {}, taskId), tree.root);
      slider.max = String(steps.length);
      slider.disabled = false; play.disabled = false;
      slider.value = String(steps.length);
      slider.oninput = () => show(+slider.value);
      await Promise.all([loadPlots(taskId), loadCell(taskId)]);
      show(steps.length);
    } catch (e) { notice.textContent = `Journal of ${taskId}: ${e.message}`; notice.className = 'error'; }
  }

  async function loadPlots(taskId) {
    plotNotice.textContent = '';
    let rows = [];
    try {
      rows = await api(`/api/runs/${encodeURIComponent(taskId)}/plots`);
    } catch (e) {
      plotNotice.textContent = `No plots are kept for this run (${e.message}).`;
    }
    charts.build(rows);
    page.plots.rows = rows.length;
  }

  async function loadCell(taskId) {
    cellNotice.textContent = '';
    try {
      page.cell.rows = await api(`/api/runs/${encodeURIComponent(taskId)}/cell`);
    } catch (e) {
      page.cell.rows = [];
      cellNotice.textContent = `No cell positions are kept for this run (${e.message}).`;
    }
    if (cell) return;
    const say = (text, bad) => { cellNotice.textContent = text; cellNotice.className = bad ? 'error' : 'muted'; };
    try {
      const { Cell3d } = await import('./cell3d.js');
      const view = new Cell3d(cellBox, say);
      page.cell.view = view.state;
      await view.load();
      cell = view;
    } catch (e) { say(`The cell's parts: ${e.message}`, true); }
  }

  api('/api/journal').then((r) => {
    const done = r.entries.filter((e) => ['SUCCEEDED', 'FAILED', 'CANCELED', 'REJECTED'].includes(e.code));
    picker.replaceChildren(el('option', { value: '' }, 'choose a finished task'),
      ...done.map((e) => el('option', { value: e.node_id }, `${e.node_id} (${e.code}, ${fmtTime(e.stamp)})`)));
    const want = args[0] ? decodeURIComponent(args[0]) : '';
    if (want) { picker.value = want; open(want); }
  }).catch((e) => { notice.textContent = `Journal: ${e.message}`; notice.className = 'error'; });
  return () => { if (timer) clearInterval(timer); charts.destroy(); if (cell) cell.dispose(); };
}
