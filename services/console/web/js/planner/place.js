// Place a part by picks (docs/console.md, "Place a part"): a face of the part, at the picked point, laid
// on a face of another part at its picked point, turned about that face's normal by a chosen angle. The
// console asks the CAD service for both face frames, writes the part's new pose into the running cell
// document and has the world model check it (POST /api/planner/place); the person confirms the changes
// (POST /api/confirm) and every service follows the new cell revision. No coordinate is typed.
import { api, el, confirmDialog } from '../api.js';
import { describeChanges } from '../cell_revisions.js';
import { placeFromPicks } from './picks.js';

const TURNS_DEG = [0, 90, 180, 270];

export class PlacePanel {
  /// `state`: the page's (`picks`); `say(text, bad)`: the page's notice; `clearPicks()`: after a placement.
  constructor({ state, say, clearPicks }) {
    Object.assign(this, { state, say, clearPicks });
    this.turn = el('select', { id: 'planner-place-turn' }, ...TURNS_DEG.map((d) => el('option', { value: String(d) }, `${d}°`)));
    this.button = el('button', { id: 'planner-place', onclick: () => this.place() }, 'Place…');
    // Known where it is placed, or found by a Localize skill at run time (the simulator starts it here).
    this.known = el('input', { type: 'checkbox', id: 'planner-place-known' });
    // A distance along the support's face (along its picked edge, else its x): one number, not a coordinate.
    this.offset = el('input', { type: 'number', id: 'planner-place-offset', step: '1', value: '0', 'aria-label': 'Offset along the face (mm)',
      oninput: () => { this.slider.value = this.offset.value; } });
    // The same distance dragged: a slider of ±500 mm, kept equal to the field.
    this.slider = el('input', { type: 'range', id: 'planner-place-offset-drag', min: '-500', max: '500', step: '1', value: '0',
      'aria-label': 'Offset along the face, dragged (mm)', oninput: () => { this.offset.value = this.slider.value; } });
    this.hint = el('p', { id: 'planner-place-hint', class: 'muted small' });
    this.root = el('div', { role: 'group', 'aria-labelledby': 'planner-place-title' },
      el('h2', { id: 'planner-place-title' }, 'Place a part'),
      el('div', { class: 'toolbar' }, el('label', {}, 'Turn about the face ', this.turn),
        el('label', {}, 'Offset (mm) ', this.offset, this.slider),
        el('label', { title: 'Unchecked: a Localize skill finds it at run time; the simulator starts it here' }, this.known, ' known here'),
        this.button), this.hint);
    this.refresh();
  }

  /// The picks changed: what Place would do, or what to pick.
  refresh() {
    const p = placeFromPicks(this.state.picks);
    this.button.disabled = Boolean(p.error);
    this.hint.textContent = p.error || `Place… lays ${p.summary}.`;
  }

  async place() {
    const { error, summary, ...body } = placeFromPicks(this.state.picks);
    if (error) return this.say(error, true);
    body.turn_deg = Number(this.turn.value);
    const offset = Number(this.offset.value || 0) / 1000;
    if (!Number.isFinite(offset)) return this.say('Place: the offset is a number of millimetres', true);
    if (offset) body.offset_m = offset;
    body.localized = this.known.checked;
    try {
      const sel = await api('/api/planner/place', { method: 'POST', body });
      const where = body.localized ? 'known there' : 'found by Localize at run time (the simulator starts it there)';
      const shifted = body.offset_m ? `, ${Math.round(body.offset_m * 1000)} mm along the face` : '';
      const question = `${summary}, turned ${body.turn_deg}°${shifted}, ${where}: ${describeChanges(sel.changes)}. Every service follows the new cell revision.`;
      if (!(await confirmDialog('Place the part?', question, 'Place'))) return this.say('Placement not confirmed: the cell is unchanged.');
      const done = await api('/api/confirm', { method: 'POST', body: { confirmation_id: sel.confirmation_id } });
      this.clearPicks();
      this.say(`Placed ${sel.object} on ${sel.support}: cell revision ${done.cell_revision} (${describeChanges(done.changes)}).`);
    } catch (e) {
      this.say(`Place: ${e.message}${e.where ? ` at ${e.where}` : ''}`, true);
    }
  }
}
