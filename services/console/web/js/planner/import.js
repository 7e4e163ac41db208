// Import a STEP file (docs/console.md, "Import a STEP file"): the file goes to the console
// (POST /api/planner/import), whose CAD service reads it with the same bounded reader as the cell's
// models; the page shows what it holds — units, solids, faces, holes and the product tree (assemblies,
// parts and their instances, as the file names them) — and draws it beside the cell, where its faces,
// edges and holes can be picked. A file the CAD service refuses (not STEP, no length unit, no solid,
// too large) is said with its reason; nothing changes in the cell.
import { api, el } from '../api.js';

/// The 3D view's id of the imported model (not a cell entity).
export const IMPORTED = 'imported';

/// The product tree as nested lists: "name (assembly)" or "name", an instance's own name beside its part's.
function productList(node) {
  if (!node) return el('p', { class: 'muted' }, 'no product structure');
  const label = (n) => `${n.name || '(unnamed)'}${n.assembly ? ' (assembly)' : ''}${n.instance && n.instance !== n.name ? ` — instance ${n.instance}` : ''}`;
  const item = (n) => el('li', { 'data-product': n.name || '' }, label(n),
    ...(n.children?.length ? [el('ul', {}, ...n.children.map(item))] : []));
  return el('ul', { class: 'product-tree', 'aria-label': 'Product tree of the imported file' }, item(node));
}

export class ImportPanel {
  /// `view`: the PartsView; `say(text, bad)`: the page's notice.
  constructor({ view, say }) {
    Object.assign(this, { view, say });
    this.file = el('input', { type: 'file', id: 'planner-import', accept: '.step,.stp,.STEP,.STP', onchange: () => this.read() });
    this.result = el('div', { id: 'planner-imported', role: 'status', 'aria-live': 'polite' });
    this.root = el('div', { role: 'group', 'aria-labelledby': 'planner-import-title' },
      el('h2', { id: 'planner-import-title' }, 'Import a STEP file'),
      el('label', {}, 'STEP file ', this.file), this.result);
    this.imported = null;  // the CAD service's answer for the last file read
  }

  async read() {
    const f = this.file.files?.[0];
    if (!f) return;
    this.result.replaceChildren(el('p', {}, `Reading ${f.name} (${(f.size / 1024).toFixed(0)} KiB)…`));
    try {
      const r = await api(`/api/planner/import?name=${encodeURIComponent(f.name)}`, { method: 'POST', bytes: f });
      this.imported = r;
      const c = r.counts || {};
      this.result.replaceChildren(
        el('p', { id: 'planner-imported-summary' },
          `${r.name}: units ${r.units}, ${c.solids} solid${c.solids === 1 ? '' : 's'}, ${c.faces} faces, ${c.holes} hole${c.holes === 1 ? '' : 's'}`,
          c.faces_from_bspline ? ` (${c.faces_from_bspline} faces recognised from B-splines)` : '', '. ',
          el('code', {}, r.model.slice(0, 19) + '…')),
        productList(r.product));
      await this.draw(r);
      this.say(`Imported ${r.name}: drawn beside the cell; its faces and holes can be picked.`);
    } catch (e) {
      this.imported = null;
      this.result.replaceChildren(el('p', { class: 'error', id: 'planner-import-error' }, `${f.name}: ${e.message}`));
      this.say(`Import of ${f.name} refused: ${e.message}`, true);
    }
  }

  /// Draws the imported model beside the cell's parts (0.5 m past them along x, at their lowest z).
  async draw(r) {
    const old = this.view.parts.get(IMPORTED);
    if (old) { this.view.scene.remove(old.group); this.view.parts.delete(IMPORTED); }
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
