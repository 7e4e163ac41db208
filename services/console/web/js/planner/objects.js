// The cell's objects in the Planner: every object of the world model (GET /api/world/entities), listed
// with Show and Frame, drawn in the 3D view from its STEP model (or its box), and offered to a
// skill's object_id parameter as a list and by a click on the part in the 3D view — never typed.
import { api, el } from '../api.js';

export class ObjectPicker {
  /// `view`: the PartsView; `say(text, bad)`: the page's notice; `list`: the <ul> of the parts.
  constructor(view, say, list) {
    Object.assign(this, { view, say, list });
    this.objects = [];  // [{id, world}] in the world model's order
    this.problem = '';  // what the world model did not answer, for the feature list
    this.armed = null;  // {ptr, name, set, select}: the object_id field (of node ptr) waiting for a click on a part
  }

  /// Reads the world model's objects (each with its description) and draws each.
  async load() {
    const { entities } = await api('/api/world/entities');
    const described = await Promise.allSettled(entities.map((id) => api(`/api/world/entity/${encodeURIComponent(id)}`)));
    const unanswered = [];
    this.objects = [];
    described.forEach((r, i) => {
      if (r.status === 'rejected') unanswered.push(`${entities[i]}: ${r.reason.message}`);
      else if (r.value.kind === 'object') this.objects.push({ id: entities[i], world: r.value });
    });
    this.problem = unanswered.join('; ');
    const loaded = await Promise.allSettled(this.objects.map((o) => this.view.load(o.id, o.world)));
    const failed = loaded.map((r, i) => (r.status === 'rejected' ? `${this.objects[i].id}: ${r.reason.message}` : null)).filter(Boolean);
    if (failed.length || unanswered.length) this.say(`Parts not shown (${[...unanswered, ...failed].join('; ')})`, true);
    this.renderList();
  }

  renderList() {
    this.list.replaceChildren(...this.objects.map(({ id }) => {
      const part = this.view.parts.get(id);
      const show = el('input', { type: 'checkbox', checked: !!part, disabled: !part, 'data-part': id,
        onchange: () => this.view.setVisible(id, show.checked) });
      return el('li', {},
        el('label', {}, show, ` ${id}`, part?.box ? el('span', { class: 'muted' }, ' (box: no CAD model)') : ''),
        ' ', el('button', { 'data-frame': id, disabled: !part, onclick: () => this.view.frame(id) }, 'Frame'));
    }));
  }

  /// A click in the view while a field is armed fills it; returns whether it did.
  take(pick) {
    if (!this.armed || !pick) return false;
    const { name, set, select } = this.armed;
    this.disarm();
    select.value = pick.entity;  // the form is not drawn again for an edit of one of its fields
    set(pick.entity);
    this.say(`${name} = ${pick.entity} (clicked)`);
    return true;
  }

  disarm() {
    this.armed = null;
    this.view.renderer.domElement.classList.remove('picking-object');
  }

  /// The chooser of parameter `name` of node `ptr` (current value `cur`): the objects as a list, and
  /// "Pick in 3D", after which a click on a part fills it. `set(id | undefined)` edits the recipe.
  field(ptr, name, cur, fallback, set) {
    const select = el('select', { 'data-object-param': name, 'aria-label': `${name}: an object of the cell`,
      onchange: () => set(select.value === '' ? undefined : select.value) },
    el('option', { value: '' }, fallback !== undefined ? `(default ${fallback})` : '(choose a part)'),
    ...this.objects.map(({ id }) => el('option', { value: id, selected: cur === id }, id)));
    if (cur !== undefined && !this.objects.some((o) => o.id === cur)) {
      select.append(el('option', { value: cur, selected: true }, `${cur} (not in the cell)`));
    }
    const pick = el('button', { type: 'button', 'data-pick-object': name,
      onclick: () => {
        this.armed = { ptr, name, set, select };
        this.view.renderer.domElement.classList.add('picking-object');
        this.say(`Click a part in the 3D view for ${name}.`);
      } }, 'Pick in 3D');
    return { select, pick };
  }
}
