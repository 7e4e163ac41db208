// The planner (programmer role): build a task's behaviour tree from the live skill library (control
// nodes, decorators, operator decisions; wrap, copy/cut/paste, undo/redo, keys), fill the parameters
// from forms generated from the skill descriptions (with their pre- and postconditions), bind the Screw
// skill's holes to holes picked on the CAD model (the CAD service derives the screw list; the binding
// is kept in the recipe), choose feature_ref parameters among the world model's features
// (planner_features.js), validate with the task controller's own validator (errors on their node and
// field, by JSON pointer), export canonical JSON, rehearse on the simulated cell of the rehearsal domain
// (one step; the run shown live) and publish (two steps). See docs/console.md, "Planner" and "Rehearsal".
import { api, el, confirmDialog, store } from './api.js';
import { PartsView, pickKey } from './planner_view.js';
import { FeaturePicker } from './planner_features.js';
import { quantityInput } from './planner_units.js';
import { recipeFields } from './planner_recipe.js';
import { RehearsalView } from './rehearsal.js';

const CONTROL = ['Sequence', 'Parallel', 'Fallback'];
// Decorators hold one child; their own field (docs/recipes.md), with the default a new one gets.
const DECORATORS = {
  Retry: { field: 'max_attempts', label: 'Attempts, the first run included ', init: 2, min: 1, max: 1000, step: '1' },
  Repeat: { field: 'repetitions', label: 'Successes needed ', init: 2, min: 1, max: 1000000, step: '1' },
  Timeout: { field: 'duration_s', label: 'Deadline ', unit: 's', init: 60, min: 0.001, max: 86400, step: 'any' },
  Inverter: null,
  ForceSuccess: null,
};
const HISTORY_LIMIT = 200;
const FRAME_RULES = ['edges', 'face', 'hole'];

/// The CAD frame rule the picks make, as the request's fields, or {error} saying what to pick.
function frameFromPicks(picks) {
  const of = (kind) => picks.filter((p) => p.kind === kind);
  const [edges, faces, holes, vertices] = ['edge', 'face', 'hole', 'vertex'].map(of);
  if (!picks.length) return { error: 'pick a point (a vertex or a face) and two perpendicular edges, or a face, or a hole' };
  const entities = new Set(picks.map((p) => p.entity));
  if (entities.size !== 1) return { error: `the picks are on ${[...entities].join(' and ')}: pick on one part` };
  const model = `object:${picks[0].entity}`;
  if (edges.length === 2 && vertices.length + faces.length === 1 && picks.length === 3) {
    const point = vertices[0] || faces[0];
    return { model, rule: 'edges', point_m: point.point_m, edges: edges.map((e) => e.ref),
      summary: `a point (${point.kind} ${point.kind === 'vertex' ? point.vertex : point.face}) and edges ${edges[0].edge}, ${edges[1].edge}` };
  }
  if (holes.length === 1 && picks.length === 1) return { model, rule: 'hole', hole: holes[0].hole, summary: `hole ${holes[0].hole}` };
  if (faces.length === 1 && picks.length === 1) return { model, rule: 'face', face: faces[0].ref, point_m: faces[0].point_m, summary: `face ${faces[0].face} at the picked point` };
  return { error: `${picks.length} picks (${picks.map((p) => p.kind).join(', ')}): pick a point (a vertex or a face) and two perpendicular edges, or one face, or one hole` };
}
const ENTITIES = ['target', 'load'];

/// The node's children as [pointer suffix, node] (children, a decorator's child, a decision's options).
function childrenOf(node) {
  if (Array.isArray(node.children)) return node.children.map((c, i) => [`/children/${i}`, c]);
  if (node.child) return [['/child', node.child]];
  if (Array.isArray(node.options)) return node.options.map((o, i) => [`/options/${i}/child`, o.child]).filter(([, c]) => c);
  return [];
}
function nodeAt(doc, pointer) {
  let v = doc;
  for (const k of pointer.split('/').slice(1)) v = v?.[k];
  return v;
}
/// Where a node sits: in a list (a control node's children, a decision's options: `list` says which)
/// at `index`, or as a decorator's only child (`list` null). null for the root.
function parentOf(pointer) {
  let m = pointer.match(/^(.*)\/children\/(\d+)$/);
  if (m) return { parent: m[1], list: 'children', index: Number(m[2]) };
  m = pointer.match(/^(.*)\/options\/(\d+)\/child$/);
  if (m) return { parent: m[1], list: 'options', index: Number(m[2]) };
  m = pointer.match(/^(.*)\/child$/);
  return m ? { parent: m[1], list: null, index: 0 } : null;
}
function pointerIn(parent, list, index) { return list === 'options' ? `${parent}/options/${index}/child` : `${parent}/children/${index}`; }
function isDecorator(node) { return node && Object.prototype.hasOwnProperty.call(DECORATORS, node.type); }
/// Substitutes a leaf's parameters (or their defaults) into a pre/postcondition: "attached(robot,$object)".
function bindCondition(text, node, description) {
  return text.replace(/\$([A-Za-z_][A-Za-z0-9_]*)/g, (whole, name) => {
    const v = node.params?.[name] ?? description.params.find((p) => p.name === name)?.default;
    return v === undefined ? whole : String(v);
  });
}
function leafName(node) { return node.skill || node.monitor || node.condition || ''; }

export function plannerPage(main, me) {
  if (me.role !== 'programmer') {
    main.replaceChildren(el('h1', {}, 'Planner'), el('p', { class: 'error' }, `The planner is for programmers; you are a ${me.role}.`));
    return () => {};
  }
  const state = {
    doc: { recipe_version: 1, task_id: 'planned-task', root: null },
    selected: '',
    picks: [],
    library: [],
    errors: [],
    validation: null,
    validations: 0,
    exported: '',
    staleBindings: [],  // bindings of an opened recipe that no longer match the CAD model
  };
  const treeBox = el('div', { class: 'ptree', role: 'tree', 'aria-label': 'Behaviour tree' });
  const formBox = el('div', { class: 'pform' });
  const picksList = el('ol', { class: 'picks', 'aria-label': 'Picked faces and holes' });
  const holesList = el('ul', { class: 'picks', 'aria-label': 'Holes of the models' });
  const errorsBox = el('div', { class: 'perrors', role: 'status', 'aria-live': 'polite' });
  const resourcesBox = el('div', { id: 'planner-resources' });
  const notice = el('p', { id: 'planner-notice', role: 'status', 'aria-live': 'polite' });
  const say = (text, bad = false) => { notice.textContent = text; notice.className = bad ? 'error' : ''; };
  const addSelect = el('select', { id: 'planner-add-kind', 'aria-label': 'Node to add' });
  const taskId = el('input', { type: 'text', id: 'planner-task-id', 'aria-label': 'Task id', value: state.doc.task_id,
    oninput: () => { state.doc.task_id = taskId.value; changed(false); } });
  const assumptions = el('input', { type: 'text', id: 'planner-assumptions', 'aria-label': 'Assumptions', placeholder: 'facts that hold at the start, e.g. hooked(crane,load)',
    oninput: () => {
      const list = assumptions.value.split(/[\s;]+/).filter(Boolean);
      if (list.length) state.doc.assumptions = list; else delete state.doc.assumptions;
      changed(false);
    } });
  const wrapSelect = el('select', { id: 'planner-wrap-kind', 'aria-label': 'Wrap the selected node in' },
    ...[...Object.keys(DECORATORS), 'Sequence', 'Fallback', 'OperatorDecision'].map((t) => el('option', { value: t }, t)));
  const openFile = el('input', { type: 'file', id: 'planner-open', accept: '.json,application/json', 'aria-label': 'Open a recipe',
    onchange: async () => { if (openFile.files[0]) open(await openFile.files[0].text()); } });
  const viewBox = el('div', { class: 'pview' });
  const recipeRow = recipeFields(state, changed);

  const editor = el('div', { id: 'planner-editor' },
    el('div', { class: 'toolbar' },
      el('label', {}, 'Task id ', taskId), el('label', {}, 'Assumptions ', assumptions),
      el('button', { id: 'planner-validate', onclick: () => validate() }, 'Validate'),
      el('button', { id: 'planner-export', onclick: () => exportRecipe() }, 'Export JSON'),
      el('button', { id: 'planner-rehearse', onclick: () => rehearse(), title: 'Run it on the simulated cell of the rehearsal domain first' }, 'Rehearse'),
      el('button', { id: 'planner-publish', class: 'primary', onclick: () => publish() }, 'Publish…'),
      el('label', {}, 'Open ', openFile)),
    recipeRow.row,
    notice,
    el('div', { class: 'planner' },
      el('section', { class: 'panel', 'aria-labelledby': 'pv' }, el('h2', { id: 'pv' }, 'Parts'),
        el('div', { class: 'toolbar' }, ...ENTITIES.map((e) => el('button', { onclick: () => view.frame(e) }, `View ${e}`)),
          el('button', { id: 'planner-clear-picks', onclick: () => { state.picks = []; renderPicks(); } }, 'Clear picks')),
        viewBox,
        el('h2', {}, 'Picked'), picksList,
        el('details', {}, el('summary', {}, 'Holes of the models (click to pick)'), holesList)),
      el('section', { class: 'panel', 'aria-labelledby': 'pt' }, el('h2', { id: 'pt' }, 'Tree'),
        el('div', { class: 'toolbar' }, addSelect,
          el('button', { id: 'planner-add', onclick: () => add(addSelect.value) }, 'Add'),
          el('button', { id: 'planner-up', title: 'Alt+↑', onclick: () => move(-1) }, 'Up'),
          el('button', { id: 'planner-down', title: 'Alt+↓', onclick: () => move(1) }, 'Down'),
          el('button', { id: 'planner-delete', class: 'danger', title: 'Delete', onclick: () => remove() }, 'Delete')),
        el('div', { class: 'toolbar' }, wrapSelect,
          el('button', { id: 'planner-wrap', onclick: () => wrap(wrapSelect.value) }, 'Wrap'),
          el('button', { id: 'planner-undo', title: 'Ctrl+Z', onclick: () => undo() }, 'Undo'),
          el('button', { id: 'planner-redo', title: 'Ctrl+Shift+Z or Ctrl+Y', onclick: () => redo() }, 'Redo'),
          el('button', { id: 'planner-copy', title: 'Ctrl+C', onclick: () => copy() }, 'Copy'),
          el('button', { id: 'planner-cut', title: 'Ctrl+X', onclick: () => cut() }, 'Cut'),
          el('button', { id: 'planner-paste', title: 'Ctrl+V', onclick: () => paste() }, 'Paste')),
        el('p', { class: 'muted small' }, 'Keys on the tree: ↑/↓ select, Alt+↑/↓ move, Delete, Ctrl+Z/Ctrl+Y, Ctrl+C/X/V.'),
        treeBox, el('h2', {}, 'Validation'), errorsBox, el('h2', {}, 'Resources'), resourcesBox),
      el('section', { class: 'panel', 'aria-labelledby': 'pf' }, el('h2', { id: 'pf' }, 'Node'), formBox)));
  // The rehearsal's live view takes the editor's place; "Back to the plan" brings the plan back as it was.
  const rehearsal = new RehearsalView(() => { rehearsal.hide(); editor.hidden = false; });
  main.replaceChildren(el('h1', {}, 'Planner'), editor, rehearsal.root);

  const view = new PartsView(viewBox, (pick) => {
    const i = state.picks.findIndex((p) => pickKey(p) === pickKey(pick));
    if (i >= 0) state.picks.splice(i, 1); else state.picks.push(pick);
    renderPicks();
  });
  const features = new FeaturePicker(view, (node, name, f) => {
    settle();
    node.params = node.params || {};
    node.params[name] = f.ref;
    node.bindings = node.bindings || {};
    node.bindings[name] = FeaturePicker.binding(f);
    state.staleBindings = state.staleBindings.filter((e) => e.pointer !== `${state.selected}/bindings/${name}`);
    changed();
    say(`${name} is the world model's ${f.ref} (${f.label}).`);
  });

  // --- the library ---
  const describe = (name) => state.library.find((s) => s.name === name);
  async function loadLibrary() {
    const lib = await api('/api/skills');
    state.library = lib.skills;
    const chosen = addSelect.value;
    addSelect.replaceChildren(
      el('optgroup', { label: 'Control' }, ...CONTROL.map((c) => el('option', { value: `control:${c}` }, c))),
      el('optgroup', { label: 'Decorators' }, ...Object.keys(DECORATORS).map((c) => el('option', { value: `decorator:${c}` }, c))),
      el('optgroup', { label: 'Operator' }, el('option', { value: 'decision:OperatorDecision' }, 'OperatorDecision')),
      ...['skill', 'monitor', 'condition'].map((kind) => el('optgroup', { label: `${kind[0].toUpperCase()}${kind.slice(1)}s` },
        ...lib.skills.filter((s) => s.kind === kind).map((s) => el('option', { value: `${kind}:${s.name}`, title: s.description || '' }, s.name)))));
    if ([...addSelect.options].some((o) => o.value === chosen)) addSelect.value = chosen;
    if (lib.problems?.length) say(`Skill library: ${lib.problems.join('; ')}`, true);
  }
  // An executor that comes, goes or comes back (a missed liveliness lease on a loaded machine) changes
  // the live library: the palette, the resources and the validation follow it a moment later, instead of
  // keeping what the library was when the page opened.
  let libraryTimer = null;
  const offLibrary = store.on((type) => {
    if (type !== 'executor' && type !== 'load') return;
    clearTimeout(libraryTimer);
    libraryTimer = setTimeout(() => loadLibrary().then(() => { renderResources(); validate(); }, (e) => say(`No skill library: ${e.message}`, true)), 300);
  });

  // --- editing ---
  function newNode(value) {
    const [kind, name] = value.split(':');
    if (kind === 'control') {
      const n = { type: name, children: [] };
      if (name === 'Parallel') { n.success_threshold = 1; n.failure_threshold = 1; }
      return n;
    }
    if (kind === 'decorator') {
      const d = DECORATORS[name];
      return d ? { type: name, [d.field]: d.init } : { type: name };
    }
    if (kind === 'decision') return { type: 'OperatorDecision', prompt: 'How to go on?', options: [] };
    const type = kind === 'skill' ? 'Skill' : kind === 'monitor' ? 'Monitor' : 'Condition';
    return { type, [kind]: name, params: {} };
  }
  function add(value) {
    if (!value) return;
    insert(newNode(value));
  }
  /// Puts `node` into the selected control node (at its end), as the selected decorator's child, as a
  /// new option of the selected OperatorDecision, or else after the selected node in its list.
  function insert(node) {
    settle();
    if (!state.doc.root) {
      state.doc.root = node;
      state.selected = '/root';
      return changed();
    }
    const at = state.selected || '/root';
    const sel = nodeAt(state.doc, at);
    let scope = at;  // the old and the new selection are both in it
    if (sel && Array.isArray(sel.children)) {
      sel.children.push(node);
      state.selected = `${at}/children/${sel.children.length - 1}`;
    } else if (isDecorator(sel) && !sel.child) {
      sel.child = node;
      state.selected = `${at}/child`;
    } else if (sel?.type === 'OperatorDecision') {
      sel.options = sel.options || [];
      sel.options.push({ label: `option ${sel.options.length + 1}`, child: node });
      state.selected = `${at}/options/${sel.options.length - 1}/child`;
    } else {
      const p = parentOf(at);
      if (!p || !p.list) {
        return say(isDecorator(sel) ? `The ${sel.type} has its child: select that child to add after it, or Wrap it.`
          : 'Select a Sequence, Parallel, Fallback, decorator or OperatorDecision to add into (the root is a leaf).', true);
      }
      const parent = nodeAt(state.doc, p.parent);
      if (p.list === 'options') parent.options.splice(p.index + 1, 0, { label: `option ${parent.options.length + 1}`, child: node });
      else parent.children.splice(p.index + 1, 0, node);
      state.selected = pointerIn(p.parent, p.list, p.index + 1);
      scope = p.parent;
    }
    changed(true, true, scope);
  }
  /// Replaces the selected node by `type` holding it (a decorator's child, a control node's first
  /// child, a decision's first option).
  function wrap(type) {
    if (!state.selected) return say('Select the node to wrap.', true);
    settle();
    const inner = nodeAt(state.doc, state.selected);
    const outer = DECORATORS[type] !== undefined ? newNode(`decorator:${type}`)
      : type === 'OperatorDecision' ? newNode('decision:OperatorDecision') : newNode(`control:${type}`);
    if (isDecorator(outer)) outer.child = inner;
    else if (outer.type === 'OperatorDecision') outer.options.push({ label: 'option 1', child: inner });
    else outer.children.push(inner);
    replaceAt(state.selected, outer);
    changed();
  }
  function replaceAt(pointer, node) {
    if (pointer === '/root') { state.doc.root = node; return; }
    const p = parentOf(pointer);
    const parent = nodeAt(state.doc, p.parent);
    if (p.list === 'options') parent.options[p.index].child = node;
    else if (p.list === 'children') parent.children[p.index] = node;
    else parent.child = node;
  }
  function move(delta) {
    const p = parentOf(state.selected);
    if (!p || !p.list) return;
    settle();
    const list = nodeAt(state.doc, p.parent)[p.list];
    const j = p.index + delta;
    if (j < 0 || j >= list.length) return;
    [list[p.index], list[j]] = [list[j], list[p.index]];
    state.selected = pointerIn(p.parent, p.list, j);
    changed();
  }
  function remove() {
    if (!state.selected) return;
    settle();
    if (state.selected === '/root') {
      state.doc.root = null;
      state.selected = '';
    } else {
      const p = parentOf(state.selected);
      const parent = nodeAt(state.doc, p.parent);
      if (p.list) parent[p.list].splice(p.index, 1);  // a decision's option goes with its child
      else delete parent.child;
      state.selected = p.parent;
    }
    changed();
  }

  // --- copy, cut, paste (a subtree, kept in the page and offered to the system clipboard as text) ---
  let clipboard = null;
  function copy() {
    const node = state.selected && nodeAt(state.doc, state.selected);
    if (!node) return say('Select the node to copy.', true);
    clipboard = structuredClone(node);
    navigator.clipboard?.writeText(JSON.stringify(node, null, 2)).catch(() => { /* the page's copy is enough */ });
    say(`Copied ${node.type}${leafName(node) ? ` ${leafName(node)}` : ''}.`);
    return true;
  }
  function cut() { if (copy()) remove(); }
  function paste() {
    if (!clipboard) return say('Nothing copied yet.', true);
    insert(structuredClone(clipboard));
  }

  // --- undo, redo: whole-document snapshots; typing in one field is one step ---
  const history = { past: [], future: [], current: '' };
  const snapshot = () => JSON.stringify({ doc: state.doc, selected: state.selected });
  let recordTimer = null;
  function record() {
    clearTimeout(recordTimer);
    recordTimer = null;
    const now = snapshot();
    if (now === history.current) return;
    history.past.push(history.current);
    if (history.past.length > HISTORY_LIMIT) history.past.shift();
    history.current = now;
    history.future = [];
    renderHistory();
  }
  /// A field edit still waiting for its quiet time becomes its own step before a structural edit.
  function settle() { if (recordTimer) record(); }
  function travel(from, to) {
    settle();
    if (!from.length) return;
    to.push(history.current);
    history.current = from.pop();
    const { doc, selected } = JSON.parse(history.current);
    state.doc = doc;
    state.selected = selected;
    taskId.value = doc.task_id || '';
    assumptions.value = (doc.assumptions || []).join(' ');
    recipeRow.refresh();
    changed(true, false);
  }
  function undo() { travel(history.past, history.future); }
  function redo() { travel(history.future, history.past); }
  function renderHistory() {
    document.getElementById('planner-undo').disabled = history.past.length === 0;
    document.getElementById('planner-redo').disabled = history.future.length === 0;
  }

  // --- keys, when the focus is not in a text field ---
  function selectSibling(delta) {
    const pointers = allNodes().map(([p]) => p);
    const i = pointers.indexOf(state.selected);
    const j = Math.min(pointers.length - 1, Math.max(0, i + delta));
    if (pointers[j]) { state.selected = pointers[j]; renderTree(); renderForm(); focusSelected(); }
  }
  function focusSelected() { treeBox.querySelector(`button.pnode[data-pointer="${state.selected}"]`)?.focus(); }
  function onKey(e) {
    const t = e.target;
    if (t instanceof HTMLInputElement || t instanceof HTMLTextAreaElement || t instanceof HTMLSelectElement || t?.isContentEditable) return;
    if (document.querySelector('dialog[open]') || editor.hidden) return;  // not while a rehearsal is shown
    const mod = e.ctrlKey || e.metaKey;
    const k = e.key.toLowerCase();
    if (mod && (k === 'c' || k === 'x') && window.getSelection()?.toString()) return;  // copying the page's text
    let done = true;
    if (mod && k === 'z' && !e.shiftKey) undo();
    else if (mod && (k === 'y' || (k === 'z' && e.shiftKey))) redo();
    else if (mod && k === 'c') copy();
    else if (mod && k === 'x') cut();
    else if (mod && k === 'v') paste();
    else if (!mod && e.key === 'Delete' && state.selected) remove();
    else if (e.altKey && e.key === 'ArrowUp') move(-1);
    else if (e.altKey && e.key === 'ArrowDown') move(1);
    else if (!mod && !e.altKey && e.key === 'ArrowUp') selectSibling(-1);
    else if (!mod && !e.altKey && e.key === 'ArrowDown') selectSibling(1);
    else done = false;
    if (done) { e.preventDefault(); focusSelected(); }
  }
  document.addEventListener('keydown', onKey);

  // --- validation, by the controller's validator through the console ---
  let timer = null;
  /// After every edit: redraw, validate (after 250 ms), and make it an undo step — at once for a
  /// structural edit (redrawForm), after 600 ms of quiet for typing in a field.
  /// `scope`: the subtree a structural edit stayed inside (and the selection with it), redrawn alone.
  function changed(redrawForm = true, remember = true, scope = '') {
    // Typing in a field changes the selected node only (an option's label shows on its child's row).
    const own = !redrawForm && state.selected && nodeAt(state.doc, state.selected)?.type !== 'OperatorDecision';
    if ((own && renderNode(state.selected)) || (scope && renderSubtree(scope))) renderResources();
    else renderTree();
    if (redrawForm) renderForm();
    else refreshConditions();
    clearTimeout(timer);
    timer = setTimeout(() => validate(), 250);
    if (!remember) {
      history.current = snapshot();
      renderHistory();
    } else if (redrawForm) {
      record();
    } else {
      clearTimeout(recordTimer);
      recordTimer = setTimeout(record, 600);
    }
  }
  function recipe() {
    const doc = structuredClone(state.doc);
    if (!doc.root) delete doc.root;
    return doc;
  }
  function bindingErrors() {
    // The Screw skill takes one torque (and type) for every hole, or each hole's from the world model.
    const out = [];
    const walk = (node, ptr) => {
      const b = node.bindings?.holes;
      if (b) {
        for (const f of ['torque_nm', 'screw_type']) {
          const vals = b.screws.map((s) => s[f]);
          const fromWorld = b.screws.every((s) => s[f] === s[`world_${f}`]);
          if (!fromWorld && new Set(vals).size > 1) {
            out.push({ pointer: `${ptr}/bindings/holes`, message: `the Screw skill takes one ${f} for every hole, or each hole's from the world model; these differ: ${vals.join(', ')}` });
          }
        }
      }
      for (const [suffix, c] of childrenOf(node)) walk(c, ptr + suffix);
    };
    if (state.doc.root) walk(state.doc.root, '/root');
    return out;
  }
  async function validate() {
    clearTimeout(timer);
    const seq = ++state.validations;
    let r;
    try {
      r = await api('/api/planner/validate', { method: 'POST', body: recipe() });
    } catch (e) {
      return say(`Validation failed: ${e.message}`, true);
    }
    if (seq !== state.validations) return state.validation;  // a newer edit is being validated
    r.errors = [...r.errors, ...bindingErrors(), ...state.staleBindings];
    r.ok = r.ok && r.errors.length === 0;
    state.validation = r;
    state.validated = seq;
    // Only the nodes whose errors came or went are redrawn.
    const before = errorsByNode();
    state.errors = r.errors;
    const after = errorsByNode();
    const same = (a = [], b = []) => a.length === b.length && a.every((e, i) => e.pointer === b[i].pointer && e.message === b[i].message);
    for (const ptr of new Set([...before.keys(), ...after.keys()])) {
      if (!same(before.get(ptr), after.get(ptr))) renderNode(ptr, after);
    }
    renderErrors();
    markFields();
    return r;
  }
  /// The node that owns `pointer`: the longest node pointer it starts with (undefined for the recipe's
  /// own fields). Walks up the pointer, so it costs its depth, not the tree's size.
  function ownerOf(pointer, nodes) {
    for (let p = pointer; p; p = p.slice(0, Math.max(0, p.lastIndexOf('/')))) if (nodes.has(p)) return p;
    return undefined;
  }
  /// The errors by the node that owns them (not a descendant's: a field is the rest of the pointer).
  /// Recipe-level errors (task_id, assumptions) are in the list only.
  function errorsByNode() {
    const nodes = new Set(allNodes().map(([p]) => p));
    const out = new Map();
    for (const e of state.errors) {
      const owner = ownerOf(e.pointer, nodes);
      if (owner === undefined) continue;
      if (!out.has(owner)) out.set(owner, []);
      out.get(owner).push(e);
    }
    return out;
  }
  function errorsAt(nodePtr) { return errorsByNode().get(nodePtr) || []; }
  function allNodes() {
    const out = [];
    const walk = (node, ptr) => { out.push([ptr, node]); for (const [s, c] of childrenOf(node)) walk(c, ptr + s); };
    if (state.doc.root) walk(state.doc.root, '/root');
    return out;
  }

  // --- rendering ---
  /// A node's button in the tree: its type, leaf and fields, name, and the count of its own errors.
  function nodeButton(node, ptr, errs) {
    const d = DECORATORS[node.type];
    const extra = node.type === 'Parallel' ? ` (M=${node.success_threshold}, K=${node.failure_threshold})`
      : d ? ` (${d.field}=${node[d.field]})` : '';
    const label = `${node.type}${leafName(node) ? ` ${leafName(node)}` : ''}${extra}`;
    return el('button', { class: `pnode${ptr === state.selected ? ' selected' : ''}${errs.length ? ' invalid' : ''}`, 'data-pointer': ptr,
      onclick: () => { state.selected = ptr; renderTree(); renderForm(); } },
    el('span', { class: 'ptype' }, label), node.name ? el('span', { class: 'pname' }, ` “${node.name}”`) : null,
    errs.length ? el('span', { class: 'perr-count', title: errs.map((e) => e.message).join('\n') }, ` ⚠ ${errs.length}`) : null);
  }
  /// Redraws one node's button, not its subtree (an edit of its fields, its errors after a validation):
  /// a 1,000-node tree is not rebuilt for a keystroke. False when the node is not drawn.
  function renderNode(ptr, byNode = errorsByNode()) {
    const old = treeBox.querySelector(`button.pnode[data-pointer="${CSS.escape(ptr)}"]`);
    const node = nodeAt(state.doc, ptr);
    if (!old || !node) return false;
    old.replaceWith(nodeButton(node, ptr, byNode.get(ptr) || []));
    return true;
  }
  /// A node's row with its subtree.
  function treeRow(node, ptr, byNode) {
    const li = el('li', { role: 'treeitem', 'data-pointer': ptr, 'aria-selected': String(ptr === state.selected) },
      nodeButton(node, ptr, byNode.get(ptr) || []));
    const kids = childrenOf(node);
    if (kids.length) {
      li.append(el('ul', { role: 'group' }, ...kids.map(([s, c]) => {
        const item = treeRow(c, ptr + s, byNode);
        const opt = s.match(/^\/options\/(\d+)\/child$/);
        if (opt) item.prepend(el('span', { class: 'muted small' }, `“${node.options[Number(opt[1])].label}” → `));
        return item;
      })));
    }
    if ((isDecorator(node) && !node.child) || (node.type === 'OperatorDecision' && !node.options?.length)) {
      li.append(el('ul', { role: 'group' }, el('li', { class: 'muted small', role: 'none' }, '(empty: select it and Add its child)')));
    }
    return li;
  }
  /// Redraws the subtree at `ptr` only (a structural edit inside it): false when it is not drawn, or is
  /// an option's child (whose row carries the option's label, drawn by the decision).
  function renderSubtree(ptr) {
    const li = treeBox.querySelector(`li[data-pointer="${CSS.escape(ptr)}"]`);
    const node = nodeAt(state.doc, ptr);
    if (!li || !node || /\/options\/\d+\/child$/.test(ptr)) return false;
    li.replaceWith(treeRow(node, ptr, errorsByNode()));
    return true;
  }
  function renderTree() {
    const byNode = errorsByNode();
    treeBox.replaceChildren(state.doc.root ? el('ul', { role: 'none' }, treeRow(state.doc.root, '/root', byNode))
      : el('p', { class: 'muted' }, 'Empty: choose a node and press Add.'));
    renderResources();
  }
  /// The tree's devices: each resource and the leaves that claim it (their descriptions' resources,
  /// parameters substituted, as the controller's validator reads them); a click selects the leaf.
  /// Whether two claims may overlap is the validator's to say (a conflict is an error on its node).
  function renderResources() {
    const held = new Map();
    for (const [ptr, node] of allNodes()) {
      const d = (node.type === 'Skill' || node.type === 'Monitor') && describe(leafName(node));
      for (const r of (d && d.resources) || []) {
        const name = bindCondition(r, node, d);
        if (!held.has(name)) held.set(name, []);
        held.get(name).push([ptr, node]);
      }
    }
    if (!held.size) return resourcesBox.replaceChildren(el('p', { class: 'muted small' }, 'No leaf claims a device yet.'));
    resourcesBox.replaceChildren(el('table', { class: 'small', 'aria-label': 'Resources the tree claims' },
      el('thead', {}, el('tr', {}, el('th', { scope: 'col' }, 'Resource'), el('th', { scope: 'col' }, 'Claimed by'))),
      el('tbody', {}, ...[...held].sort(([a], [b]) => a.localeCompare(b)).map(([name, nodes]) =>
        el('tr', { 'data-resource': name }, el('th', { scope: 'row' }, name),
          el('td', {}, ...nodes.map(([ptr, node]) => el('button', { class: 'link-button', 'data-pointer': ptr,
            onclick: () => selectPointer(ptr) }, `${leafName(node)}${node.name ? ` “${node.name}”` : ''}`))))))));
  }
  function renderErrors() {
    const v = state.validation;
    if (!v) return errorsBox.replaceChildren();
    errorsBox.replaceChildren(v.ok ? el('p', { class: 'ok', id: 'planner-valid' }, '✔ valid: the controller would accept this recipe')
      : el('ul', { id: 'planner-errors' }, ...v.errors.map((e) => el('li', { class: 'error' },
        el('button', { class: 'link-button', onclick: () => selectPointer(e.pointer) }, e.pointer || '(recipe)'), ` ${e.message}`))));
  }
  function selectPointer(pointer) {
    const owner = ownerOf(pointer, new Set(allNodes().map(([p]) => p)));
    if (owner) { state.selected = owner; renderTree(); renderForm(); }
  }
  function markFields() {
    const own = errorsAt(state.selected);  // one walk of the tree for all the fields
    for (const f of formBox.querySelectorAll('[data-field]')) {
      const msg = f.closest('.field')?.querySelector('.field-error');
      const errs = own.filter((e) => e.pointer === `${state.selected}/${f.dataset.field}`
        || e.pointer.startsWith(`${state.selected}/${f.dataset.field}/`));
      f.setAttribute('aria-invalid', String(errs.length > 0));
      if (msg) msg.textContent = errs.map((e) => e.message).join('; ');
    }
    // The node's own errors about a precondition it needs or a resource it claims (the validator names
    // them in quotes) mark that condition or resource in the form, with the message as its title.
    const nodeLevel = own.filter((e) => e.pointer === state.selected);
    const claimed = (m) => [...(m.match(/^resources? ((?:"[^"]*"(?:, )?)+) (?:is|are) claimed/)?.[1].matchAll(/"([^"]*)"/g) || [])].map((x) => x[1]);
    const mark = (c, errs, raw) => {
      c.classList.toggle('unmet', errs.length > 0);
      c.title = errs.length ? errs.map((e) => e.message).join('\n') : raw;
    };
    for (const c of formBox.querySelectorAll('[data-conditions="preconditions"] code[data-condition]')) {
      mark(c, nodeLevel.filter((e) => e.message.startsWith(`precondition "${c.textContent.trim()}" `)), c.dataset.condition);
    }
    for (const c of formBox.querySelectorAll('code[data-claim]')) {
      mark(c, nodeLevel.filter((e) => claimed(e.message).includes(c.textContent.trim())), c.dataset.claim);
    }
    const nodeErrs = formBox.querySelector('.node-errors');
    if (nodeErrs) {
      const fields = [...formBox.querySelectorAll('[data-field]')].map((f) => `${state.selected}/${f.dataset.field}`);
      nodeErrs.textContent = own.filter((e) => !fields.some((p) => e.pointer === p || e.pointer.startsWith(`${p}/`)))
        .map((e) => `${e.pointer}: ${e.message}`).join('\n');
    }
  }
  function field(label, input, unit = '', help = '') {
    return el('div', { class: 'field' }, el('label', {}, label, input, unit ? el('span', { class: 'unit' }, ` ${unit}`) : null),
      help ? el('div', { class: 'muted small' }, help) : null, el('div', { class: 'field-error error' }));
  }
  /// The selected node's pre/postconditions again with its parameters as typed (the form keeps focus).
  function refreshConditions() {
    const node = state.selected ? nodeAt(state.doc, state.selected) : null;
    const d = node && describe(leafName(node));
    if (!d) return;
    for (const c of formBox.querySelectorAll('code[data-condition]')) c.textContent = `${bindCondition(c.dataset.condition, node, d)} `;
    for (const c of formBox.querySelectorAll('code[data-claim]')) c.textContent = `${bindCondition(c.dataset.claim, node, d)} `;
  }
  function renderForm() {
    const node = state.selected ? nodeAt(state.doc, state.selected) : null;
    features.formFor(state.selected);
    if (!node) return formBox.replaceChildren(el('p', { class: 'muted' }, 'Select a node.'));
    const parts = [el('p', {}, el('strong', {}, node.type), leafName(node) ? ` ${leafName(node)}` : '', el('code', { class: 'muted' }, ` ${state.selected}`))];
    const name = el('input', { type: 'text', 'data-field': 'name', value: node.name || '',
      oninput: () => { if (name.value) node.name = name.value; else delete node.name; changed(false); } });
    parts.push(field('Name ', name));
    if (node.type === 'Parallel') {
      for (const [key, label] of [['success_threshold', 'Successes needed (M) '], ['failure_threshold', 'Failures that fail it (K) ']]) {
        const input = el('input', { type: 'number', min: '1', step: '1', 'data-field': key, value: node[key],
          oninput: () => { node[key] = Number(input.value); changed(false); } });
        parts.push(field(label, input));
      }
    }
    const dec = DECORATORS[node.type];
    if (dec) {
      const input = el('input', { type: 'number', min: String(dec.min), max: String(dec.max), step: dec.step, 'data-field': dec.field, value: node[dec.field],
        oninput: () => { node[dec.field] = Number(input.value); changed(false); } });
      parts.push(field(dec.label, input, dec.unit || '', `${dec.field} in [${dec.min}, ${dec.max}]`));
    }
    if (node.type === 'OperatorDecision') {
      const prompt = el('input', { type: 'text', 'data-field': 'prompt', value: node.prompt || '',
        oninput: () => { node.prompt = prompt.value; changed(false); } });
      parts.push(field('Question to the operator ', prompt));
      (node.options || []).forEach((o, i) => {
        const label = el('input', { type: 'text', 'data-field': `options/${i}/label`, value: o.label || '',
          oninput: () => { o.label = label.value; changed(false); } });
        parts.push(field(`Option ${i + 1} `, label, '', 'the answer the operator picks; select the option\'s node to edit it'));
      });
    }
    const d = describe(leafName(node));
    if (leafName(node) && !d) parts.push(el('p', { class: 'error' }, `${leafName(node)} is not in the live skill library (no executor announces it).`));
    if (d) {
      parts.push(el('p', { class: 'muted' }, d.description || ''));
      if (d.resources?.length) {
        parts.push(el('p', { class: 'small conditions', 'data-claims': '' }, el('span', { class: 'muted' }, 'resources: '),
          ...d.resources.map((r) => el('code', { title: r, 'data-claim': r }, `${bindCondition(r, node, d)} `))));
      }
      for (const [key, title] of [['preconditions', 'needs'], ['postconditions', 'then holds']]) {
        if (d[key]?.length) {
          parts.push(el('p', { class: 'small conditions', 'data-conditions': key }, el('span', { class: 'muted' }, `${title}: `),
            ...d[key].map((c) => el('code', { title: c, 'data-condition': c }, `${bindCondition(c, node, d)} `))));
        }
      }
      node.params = node.params || {};
      for (const p of d.params) parts.push(paramField(node, p));
    }
    parts.push(el('pre', { class: 'node-errors error' }));
    formBox.replaceChildren(...parts);
    markFields();
  }
  function paramField(node, p) {
    const key = `params/${p.name}`;
    const set = (v) => { if (v === undefined) delete node.params[p.name]; else node.params[p.name] = v; changed(false); };
    const cur = node.params[p.name];
    const range = p.min !== undefined || p.max !== undefined ? `[${p.min ?? '−∞'}, ${p.max ?? '∞'}]` : '';
    const req = p.default === undefined;
    const help = `${p.type}${range ? ` in ${range}` : ''}${req ? ', required' : `, default ${JSON.stringify(p.default)}`}. ${p.description || ''}`;
    const label = `${p.name}${req ? ' *' : ''} `;
    let input;
    if (p.type === 'number' || p.type === 'integer') {
      input = quantityInput(p, cur, set);
    } else if (p.type === 'boolean' || p.type === 'enum') {
      const values = p.type === 'boolean' ? [true, false] : p.values;
      input = el('select', { onchange: () => set(input.value === '' ? undefined : JSON.parse(input.value)) },
        el('option', { value: '' }, p.default !== undefined ? `(default ${JSON.stringify(p.default)})` : '(choose)'),
        ...values.map((v) => el('option', { value: JSON.stringify(v), selected: cur === v }, String(v))));
    } else if (p.type === 'string_list') {
      input = el('input', { type: 'text', value: Array.isArray(cur) ? cur.join(', ') : '', placeholder: 'comma-separated',
        oninput: () => set(input.value.trim() === '' ? undefined : input.value.split(',').map((s) => s.trim()).filter(Boolean)) });
    } else if (p.type === 'pose') {
      input = el('textarea', { rows: '2', placeholder: '{"position_m": [x, y, z], "rpy_deg": [r, p, y], "frame": "world"}',
        oninput: () => { try { set(input.value.trim() === '' ? undefined : JSON.parse(input.value)); } catch { /* the validator says why */ } } });
      input.value = cur ? JSON.stringify(cur) : '';
    } else {
      input = el('input', { type: 'text', value: typeof cur === 'string' ? cur : '', placeholder: p.default !== undefined ? String(p.default) : '',
        oninput: () => set(input.value === '' ? undefined : input.value) });
    }
    input.dataset.field = key;
    input.id = `param-${p.name}`;
    const f = field(label, input, input.unitSelect ? '' : p.unit || '', help);
    if (input.unitSelect) input.after(input.unitSelect);
    if (p.type === 'feature_ref') f.append(features.field(node, state.selected, p.name, input));
    if (node.skill === 'Screw' && p.name === 'holes') f.append(screwBinding(node));
    if (p.type === 'pose') f.append(frameBinding(node, p.name));
    return f;
  }

  // --- a pose parameter from picks: the CAD service's frame rules (the paper's point and two edges) ---
  function frameBinding(node, name) {
    const want = frameFromPicks(state.picks);
    const box = el('div', { class: 'binding' });
    box.append(el('button', { id: `planner-frame-${name}`, disabled: Boolean(want.error), title: want.error || '',
      onclick: () => bindFrame(node, name) }, want.error ? 'Frame from picks' : `Frame from ${want.summary}`));
    if (want.error) box.append(el('span', { class: 'muted small' }, ` ${want.error}`));
    const b = node.bindings?.[name];
    if (b && FRAME_RULES.includes(b.rule)) {
      box.append(el('p', { class: 'muted small', 'data-frame-binding': name },
        `Bound by the ${b.rule} rule to ${b.model} (sha256 ${b.model_sha256.slice(0, 12)}…): origin ${b.pose.position_m.map((v) => v.toFixed(4)).join(', ')} m, `
        + `rpy ${b.pose.rpy_deg.map((v) => v.toFixed(2)).join(', ')}° in frame ${b.pose.frame}`));
    }
    return box;
  }
  async function bindFrame(node, name) {
    const { error, summary, ...request } = frameFromPicks(state.picks);
    if (error) return say(error, true);
    try {
      const r = await api('/api/planner/frame', { method: 'POST', body: request });
      settle();
      node.params = node.params || {};
      node.params[name] = r.pose;
      node.bindings = node.bindings || {};
      node.bindings[name] = { rule: r.args.rule, model: r.model, model_sha256: r.model_sha256, args: r.args, pose: r.pose };
      state.staleBindings = state.staleBindings.filter((e) => e.pointer !== `${state.selected}/bindings/${name}`);
      changed();
      say(`${name} is the frame of ${summary} on ${r.model}.`);
    } catch (e) {
      say(`No frame from these picks: ${e.message}`, true);
    }
  }

  // --- the Screw skill's holes from picked holes ---
  function screwBinding(node) {
    const b = node.bindings?.holes;
    const box = el('div', { class: 'binding' });
    const holes = state.picks.filter((p) => p.kind === 'hole');
    box.append(el('button', { id: 'planner-bind-holes', disabled: holes.length === 0, onclick: () => bindHoles(node) },
      `Use the ${holes.length} picked hole${holes.length === 1 ? '' : 's'}`));
    if (!b) return box;
    box.append(el('p', { class: 'muted small' }, `Bound to ${b.model} (sha256 ${b.model_sha256.slice(0, 12)}…), derived by the CAD service:`));
    const table = el('table', { id: 'planner-screws' }, el('tr', {}, el('th', {}, '#'), el('th', {}, 'feature'), el('th', {}, 'CAD hole (face, signature)'),
      el('th', {}, 'entry (m)'), el('th', {}, 'screw type'), el('th', {}, 'torque (Nm)')));
    b.screws.forEach((s, i) => {
      const type = el('input', { type: 'text', value: s.screw_type, 'aria-label': `screw type of hole ${i + 1}`, 'data-screw': i,
        oninput: () => { s.screw_type = type.value; applyScrews(node); } });
      const torque = el('input', { type: 'number', min: '0', step: 'any', value: s.torque_nm, 'aria-label': `torque of hole ${i + 1}`,
        oninput: () => { s.torque_nm = Number(torque.value); applyScrews(node); } });
      table.append(el('tr', {}, el('td', {}, String(i + 1)), el('td', {}, s.feature),
        el('td', { title: JSON.stringify(s.ref.signature) }, `${s.hole} (face ${s.ref.index}, ${s.ref.signature.type} r ${(s.ref.signature.radius_m * 1000).toFixed(2)} mm)`),
        el('td', {}, s.pose.position_m.map((v) => v.toFixed(4)).join(', ')), el('td', {}, type), el('td', {}, torque)));
    });
    box.append(table);
    return box;
  }
  async function bindHoles(node) {
    const holes = state.picks.filter((p) => p.kind === 'hole');
    const entities = new Set(holes.map((p) => p.entity));
    if (entities.size !== 1) return say('Pick the holes on one part.', true);
    const entity = [...entities][0];
    try {
      const r = await api('/api/planner/screws', { method: 'POST', body: { model: `object:${entity}`, holes: holes.map((p) => p.ref) } });
      node.bindings = node.bindings || {};
      state.staleBindings = state.staleBindings.filter((e) => !e.pointer.startsWith(`${state.selected}/bindings/`));
      node.bindings.holes = {
        rule: 'screw_list', model: r.model, model_sha256: r.model_sha256,
        screws: r.screws.map((s) => ({ ...s, world_screw_type: s.screw_type, world_torque_nm: s.torque_nm })),
      };
      applyScrews(node);
      renderForm();
      say(`Screw list derived from ${r.screws.length} picked holes.`);
    } catch (e) {
      say(`The screw list could not be derived: ${e.message}`, true);
    }
  }
  function applyScrews(node) {
    const b = node.bindings.holes;
    node.params = node.params || {};
    node.params.holes = b.screws.map((s) => s.feature);
    for (const f of ['torque_nm', 'screw_type']) {
      const vals = new Set(b.screws.map((s) => s[f]));
      const fromWorld = b.screws.every((s) => s[f] === s[`world_${f}`]);
      if (fromWorld) delete node.params[f];  // the skill takes each hole's value from the world model
      else if (vals.size === 1) node.params[f] = [...vals][0];
      else delete node.params[f];  // flagged by bindingErrors()
    }
    changed(false);
    const holesInput = formBox.querySelector('[data-field="params/holes"]');
    if (holesInput) holesInput.value = node.params.holes.join(', ');
  }

  // --- picks ---
  function renderPicks() {
    view.setPicked(state.picks);
    const what = (p) => ({
      hole: () => `hole ${p.hole} (Ø ${(p.diameter_m * 1000).toFixed(1)} mm)`,
      edge: () => `edge ${p.edge} (${(Math.hypot(...p.end_m.map((v, k) => v - p.start_m[k])) * 1000).toFixed(1)} mm)`,
      vertex: () => `vertex ${p.vertex} (${p.point_m.map((v) => (v * 1000).toFixed(1)).join(', ')} mm)`,
    }[p.kind] || (() => `face ${p.face}`))();
    picksList.replaceChildren(...state.picks.map((p, i) => el('li', { 'data-kind': p.kind },
      `${p.entity} · ${what(p)} · `,
      el('code', {}, `ref ${p.ref.kind} ${p.ref.index} of ${p.ref.model_sha256.slice(0, 8)}…`), ' ',
      el('code', { class: 'sig' }, JSON.stringify(p.ref.signature)), ' ',
      el('button', { 'aria-label': `unpick ${i + 1}`, onclick: () => { state.picks.splice(i, 1); renderPicks(); } }, '✕'))));
    if (state.selected) renderForm();
  }
  function renderHoles() {
    holesList.replaceChildren(...[...view.parts].flatMap(([entity, part]) => part.features.holes.map((h) =>
      el('li', {}, el('button', { 'data-hole': `${entity}:${h.index}`, onclick: () => view.onPick(view.describe(entity, h.faces[0], h)) },
        `${entity} hole ${h.index}: Ø ${(h.diameter_m * 1000).toFixed(1)} mm, ${(h.depth_m * 1000).toFixed(1)} mm${h.through ? ' through' : ''}`)))));
  }

  // --- export, open, publish ---
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
      settle();
      state.doc = doc;
      taskId.value = doc.task_id || '';
      assumptions.value = (doc.assumptions || []).join(' ');
      recipeRow.refresh();
      state.selected = doc.root ? '/root' : '';
      state.staleBindings = [];
      changed();  // opening is one undo step: Undo brings the tree before it back
      say(`Opened ${doc.task_id}.`);
      checkBindings();
    } catch (e) {
      say(`Not a recipe: ${e.message}`, true);
    }
  }
  /// Asks the CAD service again for every binding of an opened recipe: a reference that no longer
  /// resolves (CAD_STALE_REFERENCE), another model or a screw that moved flags the binding, never used.
  /// A check still in flight when another recipe is opened is superseded: only the newest one reports.
  let bindingsGeneration = 0;
  async function checkBindings() {
    const generation = ++bindingsGeneration;
    const stale = [];
    for (const [ptr, node] of allNodes()) {
      for (const [name, fb] of Object.entries(node.bindings || {})) {
        const where = `${ptr}/bindings/${name}`;
        if (fb.rule === 'feature') {
          const why = await FeaturePicker.check(fb);
          if (why) stale.push({ pointer: where, message: why });
        }
        if (!FRAME_RULES.includes(fb.rule)) continue;
        try {
          const r = await api('/api/planner/frame', { method: 'POST', body: { model: fb.model, ...fb.args } });
          if (r.model_sha256 !== fb.model_sha256) stale.push({ pointer: where, message: `stale binding: ${fb.model} is now model ${r.model_sha256.slice(0, 12)}…, the recipe was made on ${fb.model_sha256.slice(0, 12)}…; pick again` });
          else if (JSON.stringify(r.pose) !== JSON.stringify(fb.pose)) stale.push({ pointer: where, message: `stale binding: the ${fb.rule} frame is now ${JSON.stringify(r.pose)}; pick again` });
        } catch (e) {
          stale.push({ pointer: where, message: `stale binding: ${e.message}; pick again` });
        }
      }
      const b = node.bindings?.holes;
      if (!b || b.rule !== 'screw_list') continue;
      const where = `${ptr}/bindings/holes`;
      try {
        const r = await api('/api/planner/screws', { method: 'POST', body: { model: b.model, holes: b.screws.map((x) => x.ref) } });
        const moved = r.screws.filter((x, i) => x.feature !== b.screws[i]?.feature
          || JSON.stringify(x.pose.position_m) !== JSON.stringify(b.screws[i]?.pose.position_m)).map((x) => x.feature);
        if (r.model_sha256 !== b.model_sha256) stale.push({ pointer: where, message: `stale binding: ${b.model} is now model ${r.model_sha256.slice(0, 12)}…, the recipe was made on ${b.model_sha256.slice(0, 12)}…; pick the holes again` });
        else if (moved.length) stale.push({ pointer: where, message: `stale binding: ${moved.join(', ')} moved; pick the holes again` });
      } catch (e) {
        stale.push({ pointer: where, message: `stale binding: ${e.message}; pick the holes again` });
      }
    }
    if (generation !== bindingsGeneration) return;
    state.staleBindings = stale;
    await validate();
    if (generation !== bindingsGeneration) return;
    state.bindingsChecked = (state.bindingsChecked || 0) + 1;
  }
  /// Runs the recipe on the rehearsal cell (one step: nothing real moves) and shows the run live.
  async function rehearse() {
    const v = await validate();
    if (!v?.canonical) return say('Nothing to rehearse: the recipe does not parse.', true);
    const local = [...bindingErrors(), ...state.staleBindings];
    if (local.length) return say(`Not rehearsed: ${local[0].message}`, true);
    try {
      const r = await api('/api/planner/rehearse', { method: 'POST', body: JSON.parse(v.canonical) });
      say(`Rehearsing ${r.task_id} on the simulated cell of domain ${r.domain}.`);
      editor.hidden = true;
      await rehearsal.show(r.task_id, r.domain);
    } catch (e) {
      say(`Not rehearsed: ${e.message}`, true);
    }
  }
  async function publish() {
    const v = await validate();
    if (!v?.ok) return say(`Not published: ${v ? v.errors.length : 'no'} validation error(s); fix them first.`, true);
    try {
      const sel = await api('/api/recipes', { method: 'POST', body: JSON.parse(v.canonical) });
      if (!(await confirmDialog('Publish the recipe?', `Publish ${state.doc.task_id}: the task starts and the robot and the crane move.`, 'Publish'))) return say('Publish not confirmed.');
      await api('/api/confirm', { method: 'POST', body: { confirmation_id: sel.confirmation_id } });
      say(`Published ${state.doc.task_id}; follow it on the Tasks page.`);
      state.published = state.doc.task_id;
    } catch (e) {
      say(`Publishing failed: ${e.message}`, true);
    }
  }

  // Test hook: state, and screen positions of model points (to click holes like a person would).
  window.rigger.planner = {
    state, view, history, validate, features, rehearsal,
    screenOf: (entity, point) => view.screenOf(entity, point),
    holes: (entity) => view.parts.get(entity)?.features.holes || [],
  };

  history.current = snapshot();
  renderTree();
  renderForm();
  renderHistory();
  (async () => {
    try {
      await loadLibrary();
      renderResources();  // the descriptions say what each leaf claims
    } catch (e) {
      say(`No skill library: ${e.message}`, true);
    }
    const loaded = await Promise.allSettled(ENTITIES.map((e) => view.load(e)));
    const failed = loaded.map((r, i) => r.status === 'rejected' ? `${ENTITIES[i]}: ${r.reason.message}` : null).filter(Boolean);
    if (failed.length) say(`Parts not shown (${failed.join('; ')})`, true);
    view.frame('target');
    renderHoles();
    await features.load(ENTITIES);
    window.rigger.planner.ready = true;
  })();
  return () => {
    clearTimeout(timer); clearTimeout(recordTimer); clearTimeout(libraryTimer); offLibrary();
    document.removeEventListener('keydown', onKey); rehearsal.close(); delete window.rigger.planner;
  };
}
