// Picks on the CAD model and the bindings they make (docs/console.md, "Features from picks", "Screw
// holes from picks", "Poses from picks"): the list of picks, the Screw skill's holes from picked holes
// (the CAD service derives the screw list), a pose parameter from picks by a CAD frame rule, a feature
// chosen in the FeaturePicker; each kept in the node's `bindings`. An opened recipe's bindings are asked
// of the CAD service and the world model again, and a binding that no longer matches is flagged stale.
import { el } from '../api.js';
import { pickKey } from '../planner_view.js';
import { FeaturePicker } from '../planner_features.js';
import { deriveFrame, deriveScrews } from './api.js';
import { FRAME_RULES, frameFromPicks } from './picks.js';
import { nodeAt } from './tree_document.js';

const sha = (s) => `${s.slice(0, 12)}…`;
const position = (p) => p.position_m.map((v) => v.toFixed(4)).join(', ');

export class Bindings {
  /// `state`: the page's (`picks`, `staleBindings`, `selected`); `tree`: the TreeDocument; `view`: the
  /// PartsView; `form`: the NodeForm; `picksList`, `holesList`: where the picks and the models' holes
  /// are listed; `say(text, bad)`: the page's notice; `changed(redrawForm)`: after an edit; `settle()`:
  /// typing before a binding is its own undo step; `validate()`: the page's validation.
  constructor({ state, tree, view, form, picksList, holesList, say, changed, settle, validate }) {
    Object.assign(this, { state, tree, view, form, picksList, holesList, say, changed, settle, validate });
    this.generation = 0;  // of check(): only the newest reports
  }
  /// A binding of `pointer`'s parameter `name` was made again: its stale flag goes.
  fresh(pointer, name) {
    this.state.staleBindings = this.state.staleBindings.filter((e) => e.pointer !== `${pointer}/bindings/${name}`);
  }

  // --- a feature_ref parameter from the FeaturePicker ---
  /// The FeaturePicker's choice `f` for parameter `name` of the selected node.
  featureChosen(name, f) {
    this.settle();
    this.tree.bind(this.state.selected, name, f.ref, FeaturePicker.binding(f));
    this.fresh(this.state.selected, name);
    this.changed();
    this.say(`${name} is the world model's ${f.ref} (${f.label}).`);
  }

  // --- a pose parameter from picks: the CAD service's frame rules (the paper's point and two edges) ---
  frameField(node, ptr, name) {
    const want = frameFromPicks(this.state.picks);
    const box = el('div', { class: 'binding' });
    box.append(el('button', { id: `planner-frame-${name}`, disabled: Boolean(want.error), title: want.error || '',
      onclick: () => this.bindFrame(ptr, name) }, want.error ? 'Frame from picks' : `Frame from ${want.summary}`));
    if (want.error) box.append(el('span', { class: 'muted small' }, ` ${want.error}`));
    const b = node.bindings?.[name];
    if (b && FRAME_RULES.includes(b.rule)) {
      box.append(el('p', { class: 'muted small', 'data-frame-binding': name },
        `Bound by the ${b.rule} rule to ${b.model} (sha256 ${sha(b.model_sha256)}): origin ${position(b.pose)} m, `
        + `rpy ${b.pose.rpy_deg.map((v) => v.toFixed(2)).join(', ')}° in frame ${b.pose.frame}`));
    }
    return box;
  }
  async bindFrame(ptr, name) {
    const { error, summary, ...request } = frameFromPicks(this.state.picks);
    if (error) return this.say(error, true);
    try {
      const r = await deriveFrame(request);
      this.settle();
      const done = this.tree.bindFrame(ptr, name, r);
      if (done.error) return this.say(`The frame could not be kept: ${done.error}`, true);
      this.fresh(ptr, name);
      this.changed();
      this.say(`${name} is the frame of ${summary} on ${r.model}.`);
    } catch (e) {
      this.say(`No frame from these picks: ${e.message}`, true);
    }
  }

  // --- the Screw skill's holes from picked holes ---
  screwField(node, ptr) {
    const b = node.bindings?.holes;
    const box = el('div', { class: 'binding' });
    const holes = this.state.picks.filter((p) => p.kind === 'hole');
    box.append(el('button', { id: 'planner-bind-holes', disabled: holes.length === 0, onclick: () => this.bindHoles(ptr) },
      `Use the ${holes.length} picked hole${holes.length === 1 ? '' : 's'}`));
    if (!b) return box;
    box.append(el('p', { class: 'muted small' }, `Bound to ${b.model} (sha256 ${sha(b.model_sha256)}), derived by the CAD service:`));
    const table = el('table', { id: 'planner-screws' }, el('tr', {}, el('th', {}, '#'), el('th', {}, 'feature'), el('th', {}, 'CAD hole (face, signature)'),
      el('th', {}, 'entry (m)'), el('th', {}, 'screw type'), el('th', {}, 'torque (Nm)')));
    b.screws.forEach((s, i) => {
      const type = el('input', { type: 'text', value: s.screw_type, 'aria-label': `screw type of hole ${i + 1}`, 'data-screw': i,
        oninput: () => this.setScrew(ptr, i, 'screw_type', type.value) });
      const torque = el('input', { type: 'number', min: '0', step: 'any', value: s.torque_nm, 'aria-label': `torque of hole ${i + 1}`,
        oninput: () => this.setScrew(ptr, i, 'torque_nm', Number(torque.value)) });
      table.append(el('tr', {}, el('td', {}, String(i + 1)), el('td', {}, s.feature),
        el('td', { title: JSON.stringify(s.ref.signature) }, `${s.hole} (face ${s.ref.index}, ${s.ref.signature.type} r ${(s.ref.signature.radius_m * 1000).toFixed(2)} mm)`),
        el('td', {}, position(s.pose)), el('td', {}, type), el('td', {}, torque)));
    });
    box.append(table);
    return box;
  }
  /// A typed screw type or torque: a typed step; the form's holes field shows the holes again.
  setScrew(ptr, index, key, value) {
    if (!this.tree.setScrew(ptr, index, key, value).error) this.screwsChanged(ptr);
  }
  screwsChanged(ptr) {
    this.changed(false);
    this.form.show('params/holes', nodeAt(this.tree.doc, ptr).params.holes.join(', '));
  }
  async bindHoles(ptr) {
    const holes = this.state.picks.filter((p) => p.kind === 'hole');
    const entities = new Set(holes.map((p) => p.entity));
    if (entities.size !== 1) return this.say('Pick the holes on one part.', true);
    const entity = [...entities][0];
    try {
      const r = await deriveScrews({ model: `object:${entity}`, holes: holes.map((p) => p.ref) });
      const done = this.tree.bindScrews(ptr, r);
      if (done.error) return this.say(`The screw list could not be kept: ${done.error}`, true);
      this.state.staleBindings = this.state.staleBindings.filter((e) => !e.pointer.startsWith(`${ptr}/bindings/`));
      this.screwsChanged(ptr);
      this.form.render();
      this.say(`Screw list derived from ${r.screws.length} picked holes.`);
    } catch (e) {
      this.say(`The screw list could not be derived: ${e.message}`, true);
    }
  }

  // --- picks ---
  /// A pick in the 3D view (or the holes' list): picked, or unpicked when it was.
  toggle(pick) {
    const i = this.state.picks.findIndex((p) => pickKey(p) === pickKey(pick));
    if (i >= 0) this.state.picks.splice(i, 1); else this.state.picks.push(pick);
    this.renderPicks();
  }
  clearPicks() {
    this.state.picks = [];
    this.renderPicks();
  }
  renderPicks() {
    this.view.setPicked(this.state.picks);
    const what = (p) => ({
      hole: () => `hole ${p.hole} (Ø ${(p.diameter_m * 1000).toFixed(1)} mm)`,
      edge: () => `edge ${p.edge} (${(Math.hypot(...p.end_m.map((v, k) => v - p.start_m[k])) * 1000).toFixed(1)} mm)`,
      vertex: () => `vertex ${p.vertex} (${p.point_m.map((v) => (v * 1000).toFixed(1)).join(', ')} mm)`,
    }[p.kind] || (() => `face ${p.face}`))();
    this.picksList.replaceChildren(...this.state.picks.map((p, i) => el('li', { 'data-kind': p.kind },
      `${p.entity} · ${what(p)} · `,
      el('code', {}, `ref ${p.ref.kind} ${p.ref.index} of ${p.ref.model_sha256.slice(0, 8)}…`), ' ',
      el('code', { class: 'sig' }, JSON.stringify(p.ref.signature)), ' ',
      el('button', { 'aria-label': `unpick ${i + 1}`, onclick: () => { this.state.picks.splice(i, 1); this.renderPicks(); } }, '✕'))));
    if (this.state.selected) this.form.render();
    this.onPicks?.();
  }
  /// Every hole of the drawn parts' CAD features, as a button that picks it.
  renderHoles() {
    const { view } = this;
    this.holesList.replaceChildren(...[...view.parts].flatMap(([entity, part]) => part.features.holes.map((h) =>
      el('li', {}, el('button', { 'data-hole': `${entity}:${h.index}`, onclick: () => view.onPick(view.describe(entity, h.faces[0], h)) },
        `${entity} hole ${h.index}: Ø ${(h.diameter_m * 1000).toFixed(1)} mm, ${(h.depth_m * 1000).toFixed(1)} mm${h.through ? ' through' : ''}`)))));
  }

  // --- an opened recipe's bindings, checked again ---
  /// Asks the CAD service (the world model for features) again for every binding of the recipe: a
  /// reference that no longer resolves (CAD_STALE_REFERENCE), another model or a screw that moved flags
  /// the binding, never used. A check still in flight when another recipe is opened is superseded: only
  /// the newest one reports; then the recipe is validated and `state.bindingsChecked` counts it.
  async check() {
    const generation = ++this.generation;
    const stale = [];
    for (const [ptr, node] of this.tree.nodes()) {
      // A Screw's holes (a screw list is only made there) after the node's other bindings.
      const bindings = Object.entries(node.bindings || {}).filter(([, b]) => b.rule !== 'screw_list');
      if (node.bindings?.holes?.rule === 'screw_list') bindings.push(['holes', node.bindings.holes]);
      for (const [name, b] of bindings) {
        const why = await this.staleBinding(b);
        if (why) stale.push({ pointer: `${ptr}/bindings/${name}`, message: why });
      }
    }
    if (generation !== this.generation) return;
    this.state.staleBindings = stale;
    await this.validate();
    if (generation !== this.generation) return;
    this.state.bindingsChecked = (this.state.bindingsChecked || 0) + 1;
  }
  /// Why binding `b` no longer holds ('' when it does, or is not one this page makes).
  async staleBinding(b) {
    if (b.rule === 'feature') return FeaturePicker.check(b);
    const changedModel = (r) => `stale binding: ${b.model} is now model ${sha(r.model_sha256)}, the recipe was made on ${sha(b.model_sha256)}`;
    if (FRAME_RULES.includes(b.rule)) {
      try {
        const r = await deriveFrame({ model: b.model, ...b.args });
        if (r.model_sha256 !== b.model_sha256) return `${changedModel(r)}; pick again`;
        if (JSON.stringify(r.pose) !== JSON.stringify(b.pose)) return `stale binding: the ${b.rule} frame is now ${JSON.stringify(r.pose)}; pick again`;
      } catch (e) {
        return `stale binding: ${e.message}; pick again`;
      }
      return '';
    }
    if (b.rule !== 'screw_list') return '';
    try {
      const r = await deriveScrews({ model: b.model, holes: b.screws.map((x) => x.ref) });
      const moved = r.screws.filter((x, i) => x.feature !== b.screws[i]?.feature
        || JSON.stringify(x.pose.position_m) !== JSON.stringify(b.screws[i]?.pose.position_m)).map((x) => x.feature);
      if (r.model_sha256 !== b.model_sha256) return `${changedModel(r)}; pick the holes again`;
      if (moved.length) return `stale binding: ${moved.join(', ')} moved; pick the holes again`;
    } catch (e) {
      return `stale binding: ${e.message}; pick the holes again`;
    }
    return '';
  }
}
