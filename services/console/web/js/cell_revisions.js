// The cell's revisions on the Tasks page: the running revision and the history (GET /api/cell/history),
// and for a programmer a new revision from a cell file or a rollback to an earlier one, each in two steps
// (the world model's dry run says what would change, the person confirms). A new revision (the store's
// "revision" event) redraws the history; the 3D views follow it by themselves.
import { api, store, el, fmtTime, confirmDialog } from './api.js';
import { cameraCalibrations } from './calibration.js';

/// "added a; removed b; moved part 120 mm, 0.0°; changed load (mass_kg)" from a revision's changes.
export function describeChanges(c = {}) {
  const parts = [];
  if (c.added?.length) parts.push(`added ${c.added.join(', ')}`);
  if (c.removed?.length) parts.push(`removed ${c.removed.join(', ')}`);
  for (const m of c.moved || []) parts.push(`moved ${m.id} ${(1000 * (m.distance_m || 0)).toFixed(0)} mm, ${(m.angle_deg || 0).toFixed(1)}°`);
  for (const x of c.changed || []) parts.push(`changed ${x.id}${x.keys?.length ? ` (${x.keys.join(', ')})` : ''}`);
  return parts.join('; ') || 'no change';
}

export function cellRevisionsPanel(me, say) {
  const canProgram = me.role === 'programmer';
  const current = el('p', { role: 'status' });
  const cameras = el('ul', { class: 'calibrations', 'aria-label': 'Camera calibrations' });
  const rows = el('tbody');
  const file = el('input', { type: 'file', accept: '.json,application/json', 'aria-label': 'Cell file (JSON)' });
  const comment = el('input', { type: 'text', placeholder: 'Comment', 'aria-label': 'Comment on the revision' });
  const panel = el('details', { class: 'panel', ontoggle: () => { if (panel.open) load(); } },
    el('summary', {}, 'Cell revisions'), current, cameras,
    canProgram ? el('div', { class: 'toolbar' }, file, comment, el('button', { class: 'primary', onclick: () => applyFile() }, 'Apply…')) : null,
    el('table', { class: 'revisions', 'aria-label': 'Revisions of the cell' },
      el('thead', {}, el('tr', {}, ...['Revision', 'When', 'Who', 'Comment', 'Changes', 'Roll back'].map((h) => el('th', { scope: 'col' }, h)))), rows));

  async function load() {
    try {
      const h = await api('/api/cell/history');
      current.textContent = `Running revision ${h.cell_revision}.`;
      rows.replaceChildren(...[...(h.revisions || [])].reverse().map((r) => el('tr', { 'data-revision': r.cell_revision },
        el('td', {}, String(r.cell_revision)), el('td', {}, fmtTime(r.stamp)), el('td', {}, r.who || ''), el('td', {}, r.comment || ''),
        el('td', {}, typeof r.summary === 'string' ? r.summary : describeChanges(r.summary)),
        el('td', {}, canProgram && r.cell_revision !== h.cell_revision
          ? el('button', { 'data-rollback': r.cell_revision, onclick: () => submit({ rollback: r.cell_revision }, `roll back to revision ${r.cell_revision}`) }, 'Roll back…')
          : ''))));
    } catch (e) { current.textContent = `Cell revisions: ${e.message}`; }
    try {
      const running = await api('/api/cell');
      cameras.replaceChildren(...cameraCalibrations(JSON.parse(running.cell_json || '{}'))
        .map((c) => el('li', { 'data-camera': c.id, 'data-calibrated': String(c.calibrated) }, c.text)));
    } catch (e) {
      cameras.replaceChildren(el('li', {}, `Camera calibration: ${e.message}`));
    }
  }

  async function applyFile() {
    const f = file.files?.[0];
    if (!f) return say('Choose a cell file first.', true);
    let cell;
    try { cell = JSON.parse(await f.text()); } catch (e) { return say(`${f.name} is not JSON: ${e.message}`, true); }
    await submit({ cell, comment: comment.value }, `apply ${f.name}`);
  }

  async function submit(body, what) {
    try {
      const sel = await api('/api/cell/revisions', { method: 'POST', body });
      if (!(await confirmDialog('Change the cell?', `${what}: ${describeChanges(sel.changes)}. Every service follows the new revision.`, 'Apply'))) return say('Cell revision not confirmed.');
      const done = await api('/api/confirm', { method: 'POST', body: { confirmation_id: sel.confirmation_id } });
      say(`Cell revision ${done.cell_revision} running (${describeChanges(done.changes)}).`);
    } catch (e) { say(`Cell revision (${what}): ${e.message}${e.where ? ` at ${e.where}` : ''}`, true); }
  }

  const off = store.on((type) => { if (type === 'revision' && panel.open) load(); });
  return { panel, off };
}
