// Plots: force and yank, crane and robot speed, servo error: live (the console's decimated rows over
// SSE) or a task's run (kept on disk by the console with the run: GET /api/runs/{task}/plots).
import { api, token, el, fmtTime } from './api.js';
import { PlotCharts } from './plot_charts.js';

const WINDOW_S = 120;

export function plotsPage(main, _me, args) {
  const picker = el('select', { 'aria-label': 'Time span', onchange: () => start(picker.value) });
  const box = el('div', {});
  const notice = el('p', { role: 'status' });
  main.replaceChildren(el('h1', {}, 'Plots'), el('section', { class: 'panel' }, el('div', { class: 'toolbar' }, el('label', {}, 'Show ', picker)), notice, box));
  const charts = new PlotCharts(box, 'rigger');
  let rows = [];
  let source = null;
  let dirty = false;
  // For tests: the row count, and series(label), the times (s) and values a chart draws for that series.
  const page = { rows: 0, mode: 'live', series: (label) => charts.series(label) };
  window.rigger.plots = page;

  function redraw() {
    dirty = false;
    charts.setRows(rows);
    page.rows = rows.length;
  }

  async function start(mode) {
    if (source) { source.close(); source = null; }
    page.mode = mode || 'live';
    notice.textContent = '';
    try {
      if (!mode || mode === 'live') {
        rows = await api(`/api/plots?from=${Date.now() / 1000 - WINDOW_S}`);
        charts.build(rows);
        redraw();
        source = new EventSource(`/api/plots/stream?token=${encodeURIComponent(token())}`);
        source.addEventListener('plot', (ev) => {
          rows.push(JSON.parse(ev.data));
          const cut = Date.now() / 1000 - WINDOW_S;
          while (rows.length && rows[0].t < cut) rows.shift();
          dirty = true;
        });
      } else {
        rows = await api(`/api/runs/${encodeURIComponent(mode)}/plots`);
        charts.build(rows);
        redraw();
        if (!rows.length) notice.textContent = 'The run of that task holds no samples.';
      }
    } catch (e) { notice.textContent = e.message; notice.className = 'error'; }
  }
  const tick = setInterval(() => { if (dirty) redraw(); }, 250);

  api('/api/runs').then((r) => {
    picker.replaceChildren(el('option', { value: 'live' }, 'live (last 2 minutes)'),
      ...r.runs.map((run) => el('option', { value: run.task_id }, `task ${run.task_id} (${run.state}, ${fmtTime(run.started)})`)));
    if (args[0]) picker.value = decodeURIComponent(args[0]);
    start(picker.value);
  }).catch(() => start('live'));
  return () => { clearInterval(tick); if (source) source.close(); charts.destroy(); };
}
