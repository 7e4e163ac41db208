// The Planner's "Declare a feature" panel (docs/console.md, "Declare a feature"): a grasp frame, an
// approach waypoint, screw holes, the insertion, the rope attachment or a marker from the picks, as a new
// cell revision. The console builds the rule
// from the CAD service's references (POST /api/planner/declare: the world model's dry run), the person
// confirms the changes, and the new revision's features come back through the page's "revision" event.
// After a commit the panel offers the undo: the rollback to the revision it was declared on.
import { api, confirmDialog, el } from '../api.js';
import { describeChanges } from '../cell_revisions.js';
import { DECLARE_KINDS, declareFromPicks } from './picks.js';
import { proposals } from './proposals.js';

const LABELS = { grasp_frame: 'grasp frame (a face, an edge of it for x)', approach_waypoint: 'approach waypoint (a face, a stand-off)',
  screw_holes: 'screw holes (a hole)', insertion: 'insertion (a face of the part, then the face it mates; a hole of each to pin them)',
  rope_attachment: 'rope attachment (a hole, a point on a face, or a sling)', marker: 'marker (a point on a face)' };
const DICTIONARIES = ['DICT_4X4_50', 'DICT_4X4_100', 'DICT_4X4_250', 'DICT_5X5_50', 'DICT_5X5_100', 'DICT_6X6_50'];

export class DeclarePanel {
  /// `state`: the page's (`picks`); `say(text, bad)`: the page's notice.
  constructor(state, say) {
    this.state = state;
    this.say = say;
    const input = (id, label, attrs = {}) => el('label', {}, `${label} `, el('input', { id: `planner-declare-${id}`, 'aria-label': label, ...attrs }));
    this.kind = el('select', { id: 'planner-declare-kind', 'aria-label': 'Feature kind', onchange: () => this.render() },
      ...DECLARE_KINDS.map((k) => el('option', { value: k }, LABELS[k])));
    this.fields = {
      name: input('name', 'Name', { type: 'text', placeholder: 'grasp_top, or m for m1, m2, …' }),
      x_reversed: input('xrev', 'x reversed', { type: 'checkbox' }),
      standoff_mm: input('standoff', 'Stand-off (mm)', { type: 'number', min: '0', step: '1', value: '100' }),
      like: input('like', 'All holes like this one', { type: 'checkbox' }),
      sling: input('sling', 'A sling above its centre of mass', { type: 'checkbox' }),
      screw_type: input('screw-type', 'Screw', { type: 'text', placeholder: 'M12x40' }),
      torque_nm: input('torque', 'Torque (N·m)', { type: 'number', min: '0', step: '1' }),
      dictionary: el('label', {}, 'Dictionary ', el('select', { id: 'planner-declare-dictionary', 'aria-label': 'Marker dictionary', onchange: () => this.propose() },
        ...DICTIONARIES.map((d) => el('option', { value: d }, d)))),
      marker_id: input('marker-id', 'Marker id', { type: 'number', min: '0', step: '1' }),
      marker_size_mm: input('marker-size', 'Marker size (mm)', { type: 'number', min: '10', step: '1', value: '80' }),
    };
    this.status = el('p', { id: 'planner-declare-status', role: 'status', 'aria-live': 'polite', class: 'small' });
    this.undoBox = el('div', { class: 'toolbar' });
    this.root = el('details', { id: 'planner-declare' }, el('summary', {}, 'Declare a feature (a new cell revision)'),
      el('div', { class: 'toolbar' }, this.kind, ...Object.values(this.fields),
        el('button', { id: 'planner-declare-submit', onclick: () => this.declare() }, 'Declare…')),
      this.status, this.undoBox);
    this.doc = null;  // the running cell document, for the proposals
    this.proposed = {};  // what was proposed per field: a field still holding it (or empty) takes the next
    this.render();
  }

  /// Reads the running cell document again (at the start and after each revision) and proposes anew.
  async refresh() {
    try { this.doc = JSON.parse((await api('/api/cell')).cell_json || '{}'); } catch { this.doc = null; }
    this.propose();
  }

  /// Fills the name and the marker id with what the part and the cell leave free (proposals.js), unless
  /// the person typed something else there; `fresh`: a new kind, whose fields start over.
  propose(fresh = false) {
    const wanted = proposals(this.doc, this.state.picks, this.kind.value, this.value('dictionary'));
    for (const key of ['name', 'marker_id']) {
      const box = this.fields[key].querySelector('input');
      if (!fresh && box.value !== '' && box.value !== String(this.proposed[key] ?? '')) continue;
      box.value = String(wanted[key] ?? '');
      this.proposed[key] = box.value;
    }
  }

  value(key) {
    const box = this.fields[key].querySelector('input, select');
    return box.type === 'checkbox' ? box.checked : box.value.trim();
  }

  /// Shows the kind's own fields only; a new kind's name and marker id are the ones proposed for it (a
  /// name typed for another kind, such as a screw holes' prefix, is not this one's).
  render() {
    const k = this.kind.value;
    this.propose(true);
    const framed = k === 'grasp_frame' || k === 'approach_waypoint';
    const shown = { name: framed || k === 'screw_holes', x_reversed: framed, standoff_mm: k === 'approach_waypoint',
      like: k === 'screw_holes', sling: k === 'rope_attachment', screw_type: k === 'screw_holes', torque_nm: k === 'screw_holes',
      dictionary: k === 'marker', marker_id: k === 'marker', marker_size_mm: k === 'marker' };
    for (const [key, on] of Object.entries(shown)) this.fields[key].hidden = !on;
  }

  tell(text, bad = false) {
    this.status.textContent = text;
    this.status.className = `small${bad ? ' error' : ''}`;
    this.say(text, bad);
  }

  async declare() {
    const fields = Object.fromEntries(Object.keys(this.fields).map((k) => [k, this.value(k)]));
    const request = declareFromPicks(this.state.picks, { kind: this.kind.value, ...fields });
    if (request.error) return this.tell(`Nothing declared: ${request.error}.`, true);
    const what = request.target ? `the insertion of ${request.model.slice(7)} into ${request.target.model.slice(7)}`
      : `${this.kind.value.replace('_', ' ')}${request.name ? ` ${request.name}` : ''}${request.marker_id !== undefined ? ` ${request.marker_id}` : ''} on ${request.model.slice(7)}`;
    try {
      const sel = await api('/api/planner/declare', { method: 'POST', body: request });
      this.status.textContent = `${what}: ${sel.features.join(', ')} — ${describeChanges(sel.changes)}`;
      const part = request.model.slice(7);
      const rope = sel.rope_from ? `The crane's rope moves from ${sel.rope_from} to ${part}: it becomes the crane's load, hanging where `
        + `${sel.rope_from} hung, and ${sel.rope_from} is set down where ${part} stood. ` : '';
      const note = sel.note ? `${sel.note} ` : '';
      if (!(await confirmDialog('Declare the feature?', `${what} (${sel.features.join(', ')}): ${describeChanges(sel.changes)}. `
        + rope + note + 'Every service follows the new revision.', 'Declare'))) return this.tell('Feature not declared (not confirmed).');
      const done = await api('/api/confirm', { method: 'POST', body: { confirmation_id: sel.confirmation_id } });
      this.tell(`Declared ${sel.features.join(', ')}: cell revision ${done.cell_revision}.`);
      this.offerUndo(sel.base_revision, sel.features);
    } catch (e) {
      this.tell(`Nothing declared (${what}): ${e.message}${e.where ? ` at ${e.where}` : ''}`, true);
    }
  }

  /// The undo of a declaration: the rollback to the revision it was declared on, in the same two steps.
  offerUndo(revision, features) {
    this.undoBox.replaceChildren(el('button', { id: 'planner-declare-undo', onclick: async () => {
      try {
        const sel = await api('/api/cell/revisions', { method: 'POST', body: { rollback: revision, comment: `undo ${features.join(', ')}` } });
        if (!(await confirmDialog('Undo the declaration?', `roll back to revision ${revision}: ${describeChanges(sel.changes)}.`, 'Roll back'))) return;
        const done = await api('/api/confirm', { method: 'POST', body: { confirmation_id: sel.confirmation_id } });
        this.tell(`Rolled back to revision ${revision} (now revision ${done.cell_revision}).`);
        this.undoBox.replaceChildren();
      } catch (e) { this.tell(`Undo failed: ${e.message}`, true); }
    } }, `Undo (roll back to revision ${revision})…`));
  }
}
