// The planner (programmer role): build a task's behaviour tree from the live skill library (control
// nodes, decorators, operator decisions; wrap, copy/cut/paste, undo/redo, keys), fill the parameters
// from forms generated from the skill descriptions (with their pre- and postconditions), bind the Screw
// skill's holes to holes picked on the CAD model (the CAD service derives the screw list; the binding
// is kept in the recipe), choose feature_ref parameters among the world model's features
// (planner_features.js), validate with the task controller's own validator (errors on their node and
// field, by JSON pointer), export canonical JSON, rehearse on the simulated cell of the rehearsal domain
// (one step; the run shown live) and publish (two steps). See docs/console.md, "Planner" and "Rehearsal".
//
// This module lays the page out and wires its parts: the recipe and its edits (tree_document.js), undo
// (undo.js), the tree's drawing (tree_view.js), the node's form (form.js), picks and bindings
// (bindings.js), keys (keys.js) and the console's endpoints (api.js).
import { el, confirmDialog, store } from '../api.js';
import { PartsView } from '../planner_view.js';
import { FeaturePicker } from '../planner_features.js';
import { recipeFields } from '../planner_recipe.js';
import { RehearsalView } from '../rehearsal.js';
import { Effort } from './effort.js';
import { PlacePanel } from './place.js';
import { ImportPanel } from './import.js';
import { confirmCommand, rehearsalCell, rehearseRecipe, skillLibrary, submitRecipe, validateRecipe } from './api.js';
import { Bindings } from './bindings.js';
import { DeclarePanel } from './declare.js';
import { NodeForm } from './form.js';
import { ObjectPicker } from './objects.js';
import { listenKeys } from './keys.js';
import { CONTROL, DECORATORS, TreeDocument, WRAPPERS, changedOwners, emptyRecipe, errorsByNode, leafName, nodeAt } from './tree_document.js';
import { TreeView } from './tree_view.js';
import { History } from './undo.js';

export function plannerPage(main, me) {
  if (me.role !== 'programmer') {
    main.replaceChildren(el('h1', {}, 'Planner'), el('p', { class: 'error' }, `The planner is for programmers; you are a ${me.role}.`));
    return () => {};
  }
  const state = {
    doc: emptyRecipe(),
    selected: '',
    picks: [],
    library: [],
    errors: [],
    validation: null,
    validations: 0,
    exported: '',
    staleBindings: [],  // bindings of an opened recipe that no longer match the CAD model
  };
  const tree = new TreeDocument(state);
  const treeBox = el('div', { class: 'ptree', role: 'tree', 'aria-label': 'Behaviour tree' });
  const formBox = el('div', { class: 'pform' });
  const declarePanel = new DeclarePanel(state, (text, bad) => say(text, bad));
  const picksList = el('ol', { class: 'picks', 'aria-label': 'Picked faces and holes' });
  const holesList = el('ul', { class: 'picks', 'aria-label': 'Holes of the models' });
  const errorsBox = el('div', { class: 'perrors', role: 'status', 'aria-live': 'polite' });
  const resourcesBox = el('div', { id: 'planner-resources' });
  const notice = el('p', { id: 'planner-notice', role: 'status', 'aria-live': 'polite' });
  const say = (text, bad = false) => { notice.textContent = text; notice.className = bad ? 'error' : ''; };
  const effortLine = el('p', { id: 'planner-effort', class: 'muted small' });
  // The confirmation dialog is outside the page's main: its Yes and No are the session's clicks too.
  const effort = new Effort([main, document.getElementById('confirm')].filter(Boolean), (e) => { effortLine.textContent = e.text(); });
  effortLine.textContent = effort.text();
  // The node the person chose to add: kept through a rebuild of the palette (an executor that missed its
  // liveliness lease takes its skills out of the live library until it is back).
  let wantedKind = '';
  const addSelect = el('select', { id: 'planner-add-kind', 'aria-label': 'Node to add', onchange: () => { wantedKind = addSelect.value; } });
  const addNode = () => {
    const option = addSelect.selectedOptions[0];
    if (option?.disabled) return say(`${option.value.split(':')[1]} is not offered now: no executor announces it (it may be restarting); wait for it or choose another.`, true);
    if (addSelect.value) edit(() => tree.add(addSelect.value));
  };
  const taskId = el('input', { type: 'text', id: 'planner-task-id', 'aria-label': 'Task id', value: state.doc.task_id,
    oninput: () => { tree.set('/task_id', taskId.value); changed(false); } });
  const assumptions = el('input', { type: 'text', id: 'planner-assumptions', 'aria-label': 'Assumptions', placeholder: 'facts that hold at the start, e.g. hooked(crane,load)',
    oninput: () => {
      const list = assumptions.value.split(/[\s;]+/).filter(Boolean);
      tree.set('/assumptions', list.length ? list : undefined);
      changed(false);
    } });
  const wrapSelect = el('select', { id: 'planner-wrap-kind', 'aria-label': 'Wrap the selected node in' },
    ...WRAPPERS.map((t) => el('option', { value: t }, t)));
  const openFile = el('input', { type: 'file', id: 'planner-open', accept: '.json,application/json', 'aria-label': 'Open a recipe',
    onchange: async () => { if (openFile.files[0]) open(await openFile.files[0].text()); } });
  const viewBox = el('div', { class: 'pview' });
  const placeBox = el('div', { id: 'planner-place-box' });
  const importBox = el('div', { id: 'planner-import-box' });
  const partsList = el('ul', { class: 'picks', id: 'planner-parts', 'aria-label': 'Parts of the cell' });
  const recipeRow = recipeFields(state, changed);
  const undoButton = el('button', { id: 'planner-undo', title: 'Ctrl+Z', onclick: () => undo() }, 'Undo');
  const redoButton = el('button', { id: 'planner-redo', title: 'Ctrl+Shift+Z or Ctrl+Y', onclick: () => redo() }, 'Redo');

  const editor = el('div', { id: 'planner-editor' },
    el('div', { class: 'toolbar' },
      el('label', {}, 'Task id ', taskId), el('label', {}, 'Assumptions ', assumptions),
      el('button', { id: 'planner-validate', onclick: () => validate() }, 'Validate'),
      el('button', { id: 'planner-export', onclick: () => exportRecipe() }, 'Export JSON'),
      el('button', { id: 'planner-rehearse', onclick: () => rehearse(), title: 'Run it on the simulated cell of the rehearsal domain first' }, 'Rehearse'),
      el('button', { id: 'planner-publish', class: 'primary', onclick: () => publish() }, 'Publish…'),
      el('label', {}, 'Open ', openFile)),
    recipeRow.row,
    effortLine,
    notice,
    el('div', { class: 'planner' },
      el('section', { class: 'panel', 'aria-labelledby': 'pv' }, el('h2', { id: 'pv' }, 'Parts'),
        el('div', { class: 'toolbar' }, el('button', { id: 'planner-clear-picks', onclick: () => bindings.clearPicks() }, 'Clear picks')),
        viewBox,
        el('details', { open: true }, el('summary', {}, 'Parts of the cell (show, frame)'), partsList),
        importBox,
        el('h2', {}, 'Picked'), picksList, placeBox,
        el('details', {}, el('summary', {}, 'Holes of the models (click to pick)'), holesList),
        declarePanel.root),
      el('section', { class: 'panel', 'aria-labelledby': 'pt' }, el('h2', { id: 'pt' }, 'Tree'),
        el('div', { class: 'toolbar' }, addSelect,
          el('button', { id: 'planner-add', onclick: addNode }, 'Add'),
          el('button', { id: 'planner-up', title: 'Alt+↑', onclick: () => move(-1) }, 'Up'),
          el('button', { id: 'planner-down', title: 'Alt+↓', onclick: () => move(1) }, 'Down'),
          el('button', { id: 'planner-delete', class: 'danger', title: 'Delete', onclick: () => remove() }, 'Delete')),
        el('div', { class: 'toolbar' }, wrapSelect,
          el('button', { id: 'planner-wrap', onclick: () => edit(() => tree.wrap(wrapSelect.value)) }, 'Wrap'),
          undoButton, redoButton,
          el('button', { id: 'planner-copy', title: 'Ctrl+C', onclick: () => copy() }, 'Copy'),
          el('button', { id: 'planner-cut', title: 'Ctrl+X', onclick: () => cut() }, 'Cut'),
          el('button', { id: 'planner-paste', title: 'Ctrl+V', onclick: () => paste() }, 'Paste')),
        el('p', { class: 'muted small' }, 'Keys on the tree: ↑/↓ select, Alt+↑/↓ move, Delete, Ctrl+Z/Ctrl+Y, Ctrl+C/X/V.'),
        treeBox, el('h2', {}, 'Validation'), errorsBox, el('h2', {}, 'Resources'), resourcesBox),
      el('section', { class: 'panel', 'aria-labelledby': 'pf' }, el('h2', { id: 'pf' }, 'Node'), formBox)));
  // The rehearsal's live view takes the editor's place; "Back to the plan" brings the plan back as it was.
  // Closing its stream tells the console nobody watches the rehearsal any more (its cell may stop when idle).
  const rehearsal = new RehearsalView(() => { rehearsal.close(); rehearsal.hide(); editor.hidden = false; });
  main.replaceChildren(el('h1', {}, 'Planner'), editor, rehearsal.root);

  const describe = (name) => state.library.find((s) => s.name === name);
  const history = new History(() => tree.snapshot(), { onChange: () => {
    undoButton.disabled = !history.canUndo;
    redoButton.disabled = !history.canRedo;
  } });
  const select = (pointer) => { tree.select(pointer); treeView.render(); form.render(); };
  const view = new PartsView(viewBox, (pick) => {
    if (objects.take(pick)) return;
    if (pick.kind === 'object') return say(`${pick.entity} has no CAD model: its faces and holes cannot be picked`, true);
    bindings.toggle(pick);
  });
  const objects = new ObjectPicker(view, say, partsList);
  const features = new FeaturePicker(view, (node, name, f) => bindings.featureChosen(name, f));
  const treeView = new TreeView({ box: treeBox, resources: resourcesBox, errors: errorsBox, state, describe, select });
  const form = new NodeForm({ box: formBox, state, tree, describe, features, objects, changed });
  const bindings = new Bindings({ state, tree, view, form, picksList, holesList, say, changed,
    settle: () => history.settle(), validate });
  form.bindings = bindings;
  const place = new PlacePanel({ state, say, clearPicks: () => bindings.clearPicks() });
  bindings.onPicks = () => { place.refresh(); declarePanel.propose(); };
  placeBox.replaceChildren(place.root);
  const importer = new ImportPanel({ view, say });
  importBox.replaceChildren(importer.root);
  importer.loadCellModels();

  // --- the library ---
  async function loadLibrary() {
    const lib = await skillLibrary();
    state.library = lib.skills;
    const chosen = wantedKind || addSelect.value;
    addSelect.replaceChildren(
      el('optgroup', { label: 'Control' }, ...CONTROL.map((c) => el('option', { value: `control:${c}` }, c))),
      el('optgroup', { label: 'Decorators' }, ...Object.keys(DECORATORS).map((c) => el('option', { value: `decorator:${c}` }, c))),
      el('optgroup', { label: 'Operator' }, el('option', { value: 'decision:OperatorDecision' }, 'OperatorDecision')),
      ...['skill', 'monitor', 'condition'].map((kind) => el('optgroup', { label: `${kind[0].toUpperCase()}${kind.slice(1)}s` },
        ...lib.skills.filter((s) => s.kind === kind).map((s) => el('option', { value: `${kind}:${s.name}`, title: s.description || '' }, s.name)))));
    if (chosen && ![...addSelect.options].some((o) => o.value === chosen)) {
      // Chosen, then gone from the library: kept in view, not offered, until its executor is back.
      addSelect.append(el('option', { value: chosen, disabled: true }, `${chosen.split(':')[1]} (no executor now)`));
    }
    if (chosen) addSelect.value = chosen;
    if (lib.problems?.length) say(`Skill library: ${lib.problems.join('; ')}`, true);
  }
  // An executor that comes, goes or comes back (a missed liveliness lease on a loaded machine) changes
  // the live library: the palette, the resources and the validation follow it a moment later, instead of
  // keeping what the library was when the page opened.
  let libraryTimer = null;
  const offLibrary = store.on((type) => {
    if (type !== 'executor' && type !== 'load') return;
    clearTimeout(libraryTimer);
    libraryTimer = setTimeout(() => loadLibrary().then(() => { treeView.renderResources(); validate(); }, (e) => say(`No skill library: ${e.message}`, true)), 300);
  });

  // --- structural edits: the typing before one is its own undo step; a refusal is said unless `quiet` ---
  function edit(apply, quiet = false) {
    history.settle();
    const r = apply();
    if (r.error) {
      if (!quiet) say(r.error, true);
      return false;
    }
    changed(true, true, r.scope || '');
    return true;
  }
  const move = (delta) => edit(() => tree.move(delta), true);
  const remove = () => edit(() => tree.remove(), true);
  // Copy, cut, paste: a subtree, kept in the page and offered to the system clipboard as text.
  let clipboard = null;
  function copy() {
    const { node, error } = tree.copy();
    if (error) return say(error, true);
    clipboard = node;
    navigator.clipboard?.writeText(JSON.stringify(node, null, 2)).catch(() => { /* the page's copy is enough */ });
    say(`Copied ${node.type}${leafName(node) ? ` ${leafName(node)}` : ''}.`);
    return true;
  }
  function cut() { if (copy()) remove(); }
  function paste() {
    if (!clipboard) return say('Nothing copied yet.', true);
    edit(() => tree.insert(structuredClone(clipboard)));
  }
  /// The recipe's own fields as the document has them (after Open, Undo, Redo).
  function showRecipeFields() {
    taskId.value = state.doc.task_id || '';
    assumptions.value = (state.doc.assumptions || []).join(' ');
    recipeRow.refresh();
  }
  function travel(snapshot) {
    if (snapshot === null) return;
    tree.restore(snapshot);
    showRecipeFields();
    changed(true, false);
  }
  const undo = () => travel(history.undo());
  const redo = () => travel(history.redo());
  const offKeys = listenKeys({
    undo, redo, copy, cut, paste, delete: remove, moveUp: () => move(-1), moveDown: () => move(1),
    previous: () => selectStep(-1), next: () => selectStep(1), focus: () => treeView.focusSelected(),
  }, { active: () => !document.querySelector('dialog[open]') && !editor.hidden, selected: () => state.selected });
  function selectStep(delta) {
    if (tree.step(delta).error) return;
    treeView.render();
    form.render();
    treeView.focusSelected();
  }

  // --- after every edit, and the validation by the controller's validator through the console ---
  let timer = null;
  /// After every edit: redraw, validate (after 250 ms), and make it an undo step — at once for a
  /// structural edit (redrawForm), after 600 ms of quiet for typing in a field.
  /// `scope`: the subtree a structural edit stayed inside (and the selection with it), redrawn alone.
  function changed(redrawForm = true, remember = true, scope = '') {
    // Typing in a field changes the selected node only (an option's label shows on its child's row).
    const own = !redrawForm && state.selected && nodeAt(state.doc, state.selected)?.type !== 'OperatorDecision';
    if ((own && treeView.renderNode(state.selected)) || (scope && treeView.renderSubtree(scope))) treeView.renderResources();
    else treeView.render();
    if (redrawForm) form.render();
    else form.refreshConditions();
    clearTimeout(timer);
    timer = setTimeout(() => validate(), 250);
    if (!remember) history.present();
    else if (redrawForm) history.record();
    else history.recordLater();
  }
  async function validate() {
    clearTimeout(timer);
    const seq = ++state.validations;
    let r;
    try {
      r = await validateRecipe(tree.recipe());
    } catch (e) {
      return say(`Validation failed: ${e.message}`, true);
    }
    if (seq !== state.validations) return state.validation;  // a newer edit is being validated
    r.errors = [...r.errors, ...state.staleBindings];
    r.ok = r.ok && r.errors.length === 0;
    state.validation = r;
    state.validated = seq;
    // Only the nodes whose errors came or went are redrawn.
    const before = errorsByNode(state.doc, state.errors);
    state.errors = r.errors;
    const after = errorsByNode(state.doc, state.errors);
    for (const ptr of changedOwners(before, after)) treeView.renderNode(ptr, after);
    treeView.renderErrors();
    form.markFields();
    return r;
  }

  // --- export, open, rehearse, publish ---
  async function exportRecipe() {
    const v = await validate();
    if (!v?.canonical) return say('Nothing to export.', true);
    state.exported = v.canonical;
    const a = el('a', { href: URL.createObjectURL(new Blob([v.canonical], { type: 'application/json' })), download: `${state.doc.task_id || 'recipe'}.json` });
    document.body.append(a);
    a.click();
    a.remove();
    say(v.ok ? 'Exported (valid).' : `Exported with ${v.errors.length} error(s): the controller would refuse it.`, !v.ok);
  }
  function open(text) {
    try {
      const doc = JSON.parse(text);
      history.settle();
      const r = tree.open(doc);
      if (r.error) return say(`Not a recipe: ${r.error}`, true);
      showRecipeFields();
      state.staleBindings = [];
      changed();  // opening is one undo step: Undo brings the tree before it back
      say(`Opened ${doc.task_id}.`);
      bindings.check();
    } catch (e) {
      say(`Not a recipe: ${e.message}`, true);
    }
  }
  /// Runs the recipe on the rehearsal cell (one step: nothing real moves) and shows the run live.
  async function rehearse() {
    const v = await validate();
    if (!v?.canonical) return say('Nothing to rehearse: the recipe does not parse.', true);
    const local = state.staleBindings;
    if (local.length) return say(`Not rehearsed: ${local[0].message}`, true);
    try {
      const recipe = JSON.parse(v.canonical);
      let r = await rehearseRecipe(recipe);
      if (r.starting) r = await rehearseOnceStarted(recipe, r);
      say(`Rehearsing ${r.task_id} on the simulated cell of domain ${r.domain}.`);
      editor.hidden = true;
      await rehearsal.show(r.task_id, r.domain);
    } catch (e) {
      say(`Not rehearsed: ${e.message}`, true);
    }
  }
  /// The console is starting the rehearsal cell (`r` its 202 answer), or stopping it to start it again on
  /// the cell's revision (`r.restarting`): follows it until a controller is there, then sends the recipe; rejects with the console's reason (and its log) when the start fails.
  async function rehearseOnceStarted(recipe, r) {
    const deadline = Date.now() + ((r.cell?.start_timeout_s || 120) + 30) * 1000;
    for (;;) {
      const what = r.restarting ? 'Restarting the rehearsal cell of domain ' + r.domain + ' on the cell\'s revision'
        : 'Starting the rehearsal cell of domain ' + r.domain;
      say(`${what}… (its log: ${r.cell?.log || '?'})`);
      await new Promise((done) => setTimeout(done, 500));
      const cell = await rehearsalCell();
      if (cell.error) throw new Error(`the rehearsal cell of domain ${cell.domain} did not start: ${cell.error}`);
      if (cell.phase === 'ready') {
        r = await rehearseRecipe(recipe);
        if (!r.starting) return r;
      } else if (cell.phase !== 'starting' && !(cell.phase === 'stopping' && cell.restart)) {
        throw new Error(`the rehearsal cell of domain ${cell.domain} is ${cell.phase}; see ${cell.log}`);
      }
      if (Date.now() > deadline) throw new Error(`the rehearsal cell did not come up; see ${cell.log}`);
    }
  }
  async function publish() {
    const v = await validate();
    if (!v?.ok) return say(`Not published: ${v ? v.errors.length : 'no'} validation error(s); fix them first.`, true);
    try {
      const sel = await submitRecipe(JSON.parse(v.canonical));
      if (!(await confirmDialog('Publish the recipe?', `Publish ${state.doc.task_id}: the task starts and the robot and the crane move.`, 'Publish'))) return say('Publish not confirmed.');
      await confirmCommand(sel.confirmation_id);
      say(`Published ${state.doc.task_id}; follow it on the Tasks page.`);
      state.published = state.doc.task_id;
    } catch (e) {
      say(`Publishing failed: ${e.message}`, true);
    }
  }

  // Test hook: state, and screen positions of model points (to click holes like a person would).
  window.rigger.planner = {
    state, view, history, validate, features, rehearsal, effort, importer,
    screenOf: (entity, point) => view.screenOf(entity, point),
    holes: (entity) => view.parts.get(entity)?.features.holes || [],
  };

  history.present();
  treeView.render();
  form.render();
  (async () => {
    try {
      await loadLibrary();
      treeView.renderResources();  // the descriptions say what each leaf claims
    } catch (e) {
      say(`No skill library: ${e.message}`, true);
    }
    try {
      await objects.load();
    } catch (e) {
      say(`No parts: the world model did not answer (${e.message})`, true);
    }
    view.frameAll();
    bindings.renderHoles();
    form.render();  // the object lists of the fields
    features.load(objects.objects, objects.problem);
    await declarePanel.refresh();
    window.rigger.planner.ready = true;
  })();
  // A new revision of the cell: its parts drawn afresh, the object lists with them.
  const offRevision = store.on(async (type, d) => {
    if (type !== 'revision') return;
    view.clear();
    try { await objects.load(); } catch (e) { say(`No parts: the world model did not answer (${e.message})`, true); }
    form.render();
    features.load(objects.objects, objects.problem);
    await importer.loadCellModels();
    await declarePanel.refresh();
    window.rigger.planner.drawnRevision = Math.max(window.rigger.planner.drawnRevision || 0, d?.cell_revision || 0);
  });
  return () => {
    clearTimeout(timer); history.close(); clearTimeout(libraryTimer); offLibrary(); offKeys();
    rehearsal.close(); offRevision(); effort.close(); delete window.rigger.planner;
  };
}
