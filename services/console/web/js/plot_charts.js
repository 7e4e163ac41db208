// The force, velocity and servo charts on one synchronised time axis, for the Plots page (live or a
// task's run) and the Replay page (a run, with a cursor at the slider's moment).
import uPlot from 'uplot';
import { el } from './api.js';

const CHARTS = [
  { title: 'Force and yank', series: [['f', '|F| (N)', '#0b5cad'], ['yank', 'yank (N/s)', '#a4161a', 'yank']] },
  { title: 'Velocity', series: [['crane_v', 'crane speed (m/s)', '#7a4b00'], ['robot_v', 'robot tool speed (m/s)', '#146c2e']] },
  { title: 'Servo error', series: [['servo_m', 'servo error (m)', '#5b2a86']] },
];

// Charts drawn into `box` from plot rows ({t: seconds, f, yank, crane_v, ...}).
export class PlotCharts {
  constructor(box, syncKey) {
    this.box = box;
    this.sync = uPlot.sync(syncKey);
    this.rows = [];
    this.plots = [];
    this.marker = null;
  }

  // Rebuilds the charts for the box's width and draws `rows`.
  build(rows) {
    this.rows = rows;
    const width = Math.max(500, this.box.clientWidth - 20);
    this.plots.forEach((p) => p.destroy());
    this.box.replaceChildren();
    this.plots = CHARTS.map((c) => {
      const figure = el('figure', { class: 'plot', 'aria-label': `${c.title} over time` });
      this.box.append(figure);
      return new uPlot({ title: c.title, width, height: 200, cursor: { sync: { key: this.sync.key } },
        scales: { x: { time: true } },
        series: [{}, ...c.series.map(([, label, stroke, scale]) => ({ label, stroke, width: 1.5, spanGaps: true, scale: scale || 'y' }))],
        axes: [{}, { size: 60, scale: 'y' }, ...(c.series.some((x) => x[3]) ? [{ size: 60, scale: 'yank', side: 1, grid: { show: false } }] : [])],
        hooks: { draw: [(u) => this.drawMarker(u)] } },
      this.data(c), figure);
    });
  }

  // Draws `rows` (the same charts).
  setRows(rows) {
    this.rows = rows;
    this.plots.forEach((p, i) => p.setData(this.data(CHARTS[i])));
  }

  // A vertical line at time `t` (s since the epoch) on every chart; null removes it.
  setMarker(t) {
    this.marker = t;
    this.plots.forEach((p) => p.redraw(false, false));
  }

  // The times (s) and values a chart draws for the series labelled `label`, or null.
  series(label) {
    for (const p of this.plots) {
      const i = p.series.findIndex((s) => s.label === label);
      if (i > 0) return { t: Array.from(p.data[0]), values: Array.from(p.data[i]) };
    }
    return null;
  }

  destroy() { this.plots.forEach((p) => p.destroy()); this.plots = []; }

  data(c) {
    return [this.rows.map((r) => r.t), ...c.series.map(([k]) => this.rows.map((r) => (r[k] === undefined ? null : r[k])))];
  }

  drawMarker(u) {
    if (this.marker == null) return;
    const x = Math.round(u.valToPos(this.marker, 'x', true));
    const { top, height } = u.bbox;
    u.ctx.save();
    u.ctx.strokeStyle = '#d00000';
    u.ctx.lineWidth = 2;
    u.ctx.beginPath();
    u.ctx.moveTo(x, top);
    u.ctx.lineTo(x, top + height);
    u.ctx.stroke();
    u.ctx.restore();
  }
}
