// Import a STEP file (docs/console.md, "Import a STEP file"): the file goes to the console
// (POST /api/planner/import) — or one of the cell's own models is chosen (GET /api/planner/cell_models,
// then POST /api/planner/import?model=<sha256>), e.g. for a second object of a part — whose CAD service reads it with the same bounded reader as the cell's
// models; the page shows what it holds — units, solids, faces, holes and the product tree (assemblies,
// parts and their instances, as the file names them) — and draws it beside the cell, where its faces,
// edges and holes can be picked. A file the CAD service refuses (not STEP, no length unit, no solid,
// too large) is said with its reason; nothing changes in the cell. Each node of the product tree is a
// button: choosing a part or a sub-assembly has the CAD service make it a STEP file of its own (POST
// /api/planner/import/node), drawn highlighted where the file has it, and "Add to the cell…" then adds
// that node alone, named after it. "Add to the cell…" makes it an object
// of the cell: named, of a material (or fixed to the floor), standing on the floor beside the cell; the
// console sends its bytes with the revision, so every service gets them (POST /api/planner/add, then the
// confirmation). Place then puts it where it belongs. Or "Replace its model…" makes it the new version of an
// object's model (POST /api/planner/replace): the features the new model no longer carries are dropped and
// named, and recipes made on the old model see their bindings stale.
import { api, el, confirmDialog } from '../api.js';
import { describeChanges } from '../cell_revisions.js';

/// The 3D view's id of the imported model (not a cell entity): what "Add to the cell…" adds (the file, or
/// the node chosen in its product tree).
export const IMPORTED = 'imported';
/// The whole file while a node of it is chosen: drawn faint around the node, not picked.
const IMPORTED_FILE = 'imported-file';
const CHOSEN = 0x3fbf7f;

/// A name for an object: `name` as an id (letters, digits, '_' and '-'), numbered past the ids `taken`.
export function objectId(name, taken) {
  const id = String(name || '').replace(/\.(step|stp)$/i, '').replace(/[^A-Za-z0-9_-]+/g, '_').slice(0, 60) || 'part';
  let free = id;
  for (let n = 2; taken.has(free); n += 1) free = `${id}_${n}`;
  return free;
}

/// The product tree as nested lists: each node ("name (assembly)" or "name", an instance's own name beside
/// its part's) a button that chooses it (`choose(path)`, "1/0" from the root; "" is the whole file).
function productList(node, choose) {
  if (!node) return el('p', { class: 'muted' }, 'no product structure');
  const label = (n) => `${n.name || '(unnamed)'}${n.assembly ? ' (assembly)' : ''}${n.instance && n.instance !== n.name ? ` — instance ${n.instance}` : ''}`;
  const item = (n, path) => el('li', { 'data-product': n.name || '' },
    el('button', { type: 'button', class: 'product-node', 'data-path': path, 'aria-pressed': path === '' ? 'true' : 'false',
      title: path === '' ? 'the whole file' : `node ${path}`, onclick: () => choose(path) }, label(n)),
    ...(n.children?.length ? [el('ul', {}, ...n.children.map((c, i) => item(c, path === '' ? `${i}` : `${path}/${i}`)))] : []));
  return el('ul', { class: 'product-tree', 'aria-label': 'Product tree of the imported file: choose a part or a sub-assembly to add it alone' }, item(node, ''));
}

export class ImportPanel {
  /// `view`: the PartsView; `say(text, bad)`: the page's notice.
  constructor({ view, say }) {
    Object.assign(this, { view, say });
    this.file = el('input', { type: 'file', id: 'planner-import', accept: '.step,.stp,.STEP,.STP', onchange: () => this.read() });
    this.result = el('div', { id: 'planner-imported', role: 'status', 'aria-live': 'polite' });
    this.name = el('input', { id: 'planner-add-name', type: 'text', maxlength: '64', pattern: '[A-Za-z0-9_-]+', autocomplete: 'off' });
    this.material = el('select', { id: 'planner-add-material' },
      ...[['steel', 'steel (loose)'], ['aluminium', 'aluminium (loose)'], ['plastic', 'plastic (loose)'], ['fixed', 'fixed to the floor']]
        .map(([value, label]) => el('option', { value }, label)));
    this.addButton = el('button', { id: 'planner-add-object', onclick: () => this.add() }, 'Add to the cell…');
    this.replaceObject = el('select', { id: 'planner-replace-object' });
    this.replaceButton = el('button', { id: 'planner-replace-model', onclick: () => this.replace() }, 'Replace its model…');
    this.addForm = el('div', { hidden: true },
      el('div', { class: 'toolbar' }, el('label', {}, 'Name ', this.name), el('label', {}, 'Material ', this.material), this.addButton),
      el('div', { class: 'toolbar' }, el('label', {}, 'or a new version of the model of ', this.replaceObject), this.replaceButton));
    this.cellModel = el('select', { id: 'planner-cell-model' }, el('option', { value: '' }, '(none)'));
    this.cellModelButton = el('button', { id: 'planner-import-cell-model', onclick: () => this.readCellModel() }, 'Import');
    this.root = el('div', { role: 'group', 'aria-labelledby': 'planner-import-title' },
      el('h2', { id: 'planner-import-title' }, 'Import a STEP file'),
      el('label', {}, 'STEP file ', this.file),
      el('div', { class: 'toolbar' }, el('label', {}, 'or a model of the cell ', this.cellModel), this.cellModelButton),
      this.result, this.addForm);
    this.imported = null;  // the CAD service's answer for the last file read
    this.chosen = null;  // the answer for the node of it chosen in its product tree, or null: the whole file
  }

  /// What "Add to the cell…" and "Replace its model…" take: the chosen node, or the whole file.
  current() { return this.chosen || this.imported; }

  /// Takes the imported drawings (the file and the chosen node) out of the view.
  undraw() {
    this.view.remove(IMPORTED);
    this.view.remove(IMPORTED_FILE);
  }

  /// Chooses the node at `path` ("1/0"; "" the whole file) of the imported file's product tree: the CAD
  /// service makes it a file of its own (POST /api/planner/import/node), drawn highlighted where the file
  /// has it, the rest of the file faint; Add then adds it alone, its name proposed from the node's.
  async choose(path) {
    const r = this.imported;
    if (!r) return;
    const button = this.result.querySelector(`.product-node[data-path="${path}"]`);
    const label = button?.textContent || path;
    try {
      let chosen = null;
      if (path !== '') chosen = await api('/api/planner/import/node', { method: 'POST', body: { model: r.model, node: path.split('/').map(Number) } });
      await this.drawChosen(chosen);
      this.chosen = chosen;
      for (const b of this.result.querySelectorAll('.product-node')) b.setAttribute('aria-pressed', String(b.dataset.path === path));
      const c = chosen?.counts;
      this.chosenText.replaceChildren(chosen
        ? `Chosen: ${label} (node ${path}): ${c.solids} solid${c.solids === 1 ? '' : 's'}, ${c.faces} faces, ${c.holes} hole${c.holes === 1 ? '' : 's'}, drawn highlighted; "Add to the cell…" adds it alone.`
        : 'Chosen: the whole file.');
      this.name.value = objectId(chosen ? chosen.node.name : r.name, new Set(this.view.parts.keys()));
      this.say(chosen ? `Chose ${label}: drawn highlighted in the file.` : `Chose the whole file ${r.name}.`);
    } catch (e) {
      this.say(`${label}: ${e.message}${e.where ? ` at ${e.where}` : ''}`, true);
    }
  }

  /// Draws the chosen node (null: the whole file again) in place of the one drawn before.
  async drawChosen(chosen) {
    const view = this.view;
    if (!chosen) {
      if (!view.parts.has(IMPORTED_FILE)) return;
      view.remove(IMPORTED);
      view.rename(IMPORTED_FILE, IMPORTED);
      view.setGhost(IMPORTED, false);
      return;
    }
    if (view.parts.has(IMPORTED_FILE)) view.remove(IMPORTED);
    else {
      view.rename(IMPORTED, IMPORTED_FILE);
      view.setGhost(IMPORTED_FILE, true);
    }
    await view.load(IMPORTED, { pose: view.worldPoseOf(IMPORTED_FILE, chosen.node.pose_in_file) }, chosen.model);
    view.setColor(IMPORTED, CHOSEN);
    view.frame(IMPORTED_FILE);
  }

  /// The cell's models, for the "or a model of the cell" list (called when the cell's revision changes).
  async loadCellModels() {
    try {
      const models = await api('/api/planner/cell_models');
      const chosen = this.cellModel.value;
      this.cellModel.replaceChildren(el('option', { value: '' }, models.length ? '(choose)' : '(the cell pins no model)'),
        ...models.map((m) => el('option', { value: m.sha256 }, `${m.name} (${(m.bytes / 1024).toFixed(0)} KiB)`)));
      if (models.some((m) => m.sha256 === chosen)) this.cellModel.value = chosen;
    } catch (e) {
      this.cellModel.replaceChildren(el('option', { value: '' }, `(no list: ${e.message})`));
    }
  }

  async read() {
    const f = this.file.files?.[0];
    if (!f) return;
    this.result.replaceChildren(el('p', {}, `Reading ${f.name} (${(f.size / 1024).toFixed(0)} KiB)…`));
    await this.show(f.name, () => api(`/api/planner/import?name=${encodeURIComponent(f.name)}`, { method: 'POST', bytes: f }));
  }

  async readCellModel() {
    const sha = this.cellModel.value;
    if (!sha) return this.say('Choose a model of the cell first.', true);
    const label = this.cellModel.selectedOptions[0]?.textContent || sha;
    this.result.replaceChildren(el('p', {}, `Reading ${label}…`));
    await this.show(label, () => api(`/api/planner/import?model=${encodeURIComponent(sha)}`, { method: 'POST' }));
  }

  /// What the CAD service read (`ask()` returns it), shown and drawn; `label`: the file, for messages.
  async show(label, ask) {
    try {
      const r = await ask();
      this.imported = r;
      this.chosen = null;
      this.chosenText = el('p', { id: 'planner-imported-node', role: 'status' }, 'Chosen: the whole file.');
      const c = r.counts || {};
      this.result.replaceChildren(
        el('p', { id: 'planner-imported-summary' },
          `${r.name}: units ${r.units}, ${c.solids} solid${c.solids === 1 ? '' : 's'}, ${c.faces} faces, ${c.holes} hole${c.holes === 1 ? '' : 's'}`,
          c.faces_from_bspline ? ` (${c.faces_from_bspline} faces recognised from B-splines)` : '', '. ',
          el('code', {}, r.model.slice(0, 19) + '…')),
        productList(r.product, (path) => this.choose(path)), this.chosenText);
      await this.draw(r);
      // A name for the object it may become: the file's, as an id.
      this.name.value = objectId(r.name, new Set(this.view.parts.keys()));
      // The objects given by a STEP model (not a box), whose model this file may replace.
      const objects = [...this.view.parts.entries()].filter(([id, p]) => id !== IMPORTED && id !== IMPORTED_FILE && !p.box).map(([id]) => id).sort();
      this.replaceObject.replaceChildren(...objects.map((id) => el('option', { value: id }, id)));
      this.replaceButton.disabled = !objects.length;
      this.addForm.hidden = false;
      this.say(`Imported ${r.name}: drawn beside the cell; its faces and holes can be picked.`);
    } catch (e) {
      this.imported = null;
      this.chosen = null;
      this.addForm.hidden = true;
      this.result.replaceChildren(el('p', { class: 'error', id: 'planner-import-error' }, `${label}: ${e.message}`));
      this.say(`Import of ${label} refused: ${e.message}`, true);
    }
  }

  /// The imported file as a new version of an object's model, after the person confirmed what changes and
  /// which features the new model no longer carries (dropped, to be declared again by picks).
  async replace() {
    const r = this.current(), object = this.replaceObject.value;
    if (!r || !object) return this.say('Import a STEP file and choose the object whose model it replaces.', true);
    try {
      const sel = await api('/api/planner/replace', { method: 'POST', body: { model: r.model, object } });
      const dropped = sel.dropped || [];
      const lost = dropped.length
        ? ` These features are not in the new model and are dropped, to be declared again: ${dropped.map((d) => `${d.feature} (${d.why})`).join('; ')}.`
        : ' Every feature of it is in the new model.';
      const question = `${r.name} becomes the model of ${object}: ${describeChanges(sel.changes)}.${lost} Recipes made on the old model show their bindings stale until they are picked again.`;
      if (!(await confirmDialog(`Replace the model of ${object}?`, question, 'Replace'))) return this.say('Not replaced: the cell is unchanged.');
      const done = await api('/api/confirm', { method: 'POST', body: { confirmation_id: sel.confirmation_id } });
      this.undraw();
      this.addForm.hidden = true;
      this.say(`Replaced the model of ${object}: cell revision ${done.cell_revision}.${dropped.length ? ` Declare again: ${dropped.map((d) => d.feature).join(', ')}.` : ''}`);
    } catch (e) {
      this.say(`Replace the model of ${object}: ${e.message}${e.where ? ` at ${e.where}` : ''}`, true);
    }
  }

  /// The imported part as a new object of the cell, after the person confirmed what the world model said.
  async add() {
    const r = this.current();
    if (!r) return this.say('Import a STEP file first.', true);
    const body = { model: r.model, id: this.name.value.trim(), material: this.material.value };
    try {
      const sel = await api('/api/planner/add', { method: 'POST', body });
      const how = body.material === 'fixed' ? 'fixed to the floor' : `loose, of ${body.material}`;
      const question = `${r.name} becomes the object ${sel.object}, ${how}, standing on the floor beside the cell: ${describeChanges(sel.changes)}. Every service gets its model with the new cell revision.`;
      if (!(await confirmDialog('Add the part to the cell?', question, 'Add'))) return this.say('Not added: the cell is unchanged.');
      const done = await api('/api/confirm', { method: 'POST', body: { confirmation_id: sel.confirmation_id } });
      this.undraw();
      this.addForm.hidden = true;
      this.say(`Added ${sel.object} to the cell: cell revision ${done.cell_revision} (${describeChanges(done.changes)}). Place it by picks.`);
    } catch (e) {
      this.say(`Add to the cell: ${e.message}${e.where ? ` at ${e.where}` : ''}`, true);
    }
  }

  /// Draws the imported model beside the cell's parts (0.5 m past them along x, at their lowest z).
  async draw(r) {
    this.undraw();
    let x = 0, z = 0;
    for (const [, part] of this.view.parts) {
      part.group.updateMatrixWorld(true);
      const p = part.group.position;
      x = Math.max(x, p.x);
      z = Math.min(z, p.z);
    }
    const world = { pose: { position_m: [x + 1.0, 0, z], rpy_deg: [0, 0, 0] } };
    await this.view.load(IMPORTED, world, r.model);
    this.view.frame(IMPORTED);
  }
}
