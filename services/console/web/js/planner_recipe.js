// The recipe's own fields besides the task id and the assumptions (docs/recipes.md): its description
// and the default stop timeout of every leaf. Empty fields leave them out of the recipe.
import { el } from './api.js';

/// The fields of `state.doc` as a row of the planner's page; `changed()` after each edit (a typed step).
/// `refresh()` shows the document's values again (after Open, Undo, Redo).
export function recipeFields(state, changed) {
  const description = el('textarea', { id: 'planner-description', rows: '2', 'aria-label': 'Description of the task',
    placeholder: 'what the task does, for the journal and the next programmer',
    oninput: () => { if (description.value) state.doc.description = description.value; else delete state.doc.description; changed(false); } });
  const stop = el('input', { type: 'number', id: 'planner-stop-timeout', min: '0', max: '3600', step: 'any', 'aria-label': 'Stop timeout of every leaf',
    placeholder: 'default', oninput: () => {
      if (stop.value === '') delete state.doc.stop_timeout_s; else state.doc.stop_timeout_s = Number(stop.value);
      changed(false);
    } });
  const row = el('div', { class: 'toolbar recipe-fields' },
    el('label', { class: 'grow' }, 'Description ', description),
    el('label', {}, 'Stop timeout ', stop, el('span', { class: 'unit' }, ' s')));
  const refresh = () => {
    description.value = state.doc.description || '';
    stop.value = state.doc.stop_timeout_s ?? '';
  };
  return { row, refresh };
}
