// Plots: force and yank, crane and robot speed, servo error: three charts on one synchronised time
// axis, live (the console's decimated rows over SSE) or for a finished task's time span.
import uPlot from 'uplot';
import { api, token, el, fmtTime } from './api.js';

const CHARTS = [
  { title: 'Force and yank', series: [['f', '|F| (N)', '#0b5cad'], ['yank', 'yank (N/s)', '#a4161a', 'yank']] },
  { title: 'Velocity', series: [['crane_v', 'crane speed (m/s)', '#7a4b00'], ['robot_v', 'robot tool speed (m/s)', '#146c2e']] },
  { title: 'Servo error', series: [['servo_m', 'servo error (m)', '#5b2a86']] },
];
const WINDOW_S = 120;

export function plotsPage(main, _me, args) {
  const picker = el('select', { 'aria-label': 'Time span', onchange: () => start(picker.value) });
  const box = el('div', {});
  const notice = el('p', { role: 'status' });
  main.replaceChildren(el('h1', {}, 'Plots'), el('section', { class: 'panel' }, el('div', { class: 'toolbar' }, el('label', {}, 'Show ', picker)), notice, box));
  const sync = uPlot.sync('rigger');
  let rows = [];
  let plots = [];
  let source = null;
  let dirty = false;
  // For tests: the row count, and series(label), the times (s) and values a chart draws for that series.
  const page = {
    rows: 0, mode: 'live',
    series(label) {
      for (const p of plots) {
        const i = p.series.findIndex((s) => s.label === label);
        if (i > 0) return { t: Array.from(p.data[0]), values: Array.from(p.data[i]) };
      }
      return null;
    },
  };
  window.rigger.plots = page;

  function build() {
    const width = Math.max(500, box.clientWidth - 20);
    plots.forEach((p) => p.destroy());
    box.replaceChildren();
    plots = CHARTS.map((c) => {
      const div = el('figure', { class: 'plot', 'aria-label': `${c.title} over time` });
      box.append(div);
      return new uPlot({ title: c.title, width, height: 200, cursor: { sync: { key: sync.key } },
        scales: { x: { time: true } },
        series: [{}, ...c.series.map(([, label, stroke, scale]) => ({ label, stroke, width: 1.5, spanGaps: true, scale: scale || 'y' }))],
        axes: [{}, { size: 60, scale: 'y' }, ...(c.series.some((x) => x[3]) ? [{ size: 60, scale: 'yank', side: 1, grid: { show: false } }] : [])] },
      data(c), div);
    });
  }
  function data(c) {
    return [rows.map((r) => r.t), ...c.series.map(([k]) => rows.map((r) => (r[k] === undefined ? null : r[k])))];
  }
  function redraw() {
    dirty = false;
    plots.forEach((p, i) => p.setData(data(CHARTS[i])));
    page.rows = rows.length;
  }

  async function start(mode) {
    if (source) { source.close(); source = null; }
    page.mode = mode || 'live';
    notice.textContent = '';
    try {
      if (!mode || mode === 'live') {
        rows = await api(`/api/plots?from=${Date.now() / 1000 - WINDOW_S}`);
        build();
        redraw();
        source = new EventSource(`/api/plots/stream?token=${encodeURIComponent(token())}`);
        source.addEventListener('plot', (ev) => {
          rows.push(JSON.parse(ev.data));
          const cut = Date.now() / 1000 - WINDOW_S;
          while (rows.length && rows[0].t < cut) rows.shift();
          dirty = true;
        });
      } else {
        const j = await api(`/api/journal?task=${encodeURIComponent(mode)}`);
        const t = j.entries.map((e) => e.stamp);
        rows = await api(`/api/plots?from=${Math.min(...t) - 1}&to=${Math.max(...t) + 1}`);
        build();
        redraw();
        if (!rows.length) notice.textContent = 'The console holds no samples of that time span (it keeps the last 30 minutes).';
      }
    } catch (e) { notice.textContent = e.message; notice.className = 'error'; }
  }
  const tick = setInterval(() => { if (dirty) redraw(); }, 250);

  api('/api/journal').then((r) => {
    picker.replaceChildren(el('option', { value: 'live' }, 'live (last 2 minutes)'),
      ...r.entries.map((e) => el('option', { value: e.node_id }, `task ${e.node_id} (${e.code}, ${fmtTime(e.stamp)})`)));
    if (args[0]) picker.value = decodeURIComponent(args[0]);
    start(picker.value);
  }).catch(() => start('live'));
  return () => { clearInterval(tick); if (source) source.close(); plots.forEach((p) => p.destroy()); };
}
