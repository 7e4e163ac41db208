// The planner's recipe as a document, without the page: the tree of a recipe (docs/recipes.md) with the
// selected node's JSON pointer, the edits the Planner makes on them, the readings of the tree the page
// draws from (its nodes, the node owning an error's pointer, the Screw bindings' own errors) and its
// texts (an undo snapshot, the canonical text). No DOM, no HTTP: node --test runs it as it is
// (services/console/web/test). An edit returns {error} when it is refused, saying why, and then
// changes nothing; otherwise {} or {scope}, the subtree the edit stayed inside (the page redraws it alone).

/// The control nodes of the palette.
export const CONTROL = ['Sequence', 'Parallel', 'Fallback'];
/// Decorators hold one child; their own field (docs/recipes.md), with the default a new one gets.
export const DECORATORS = {
  Retry: { field: 'max_attempts', label: 'Attempts, the first run included ', init: 2, min: 1, max: 1000, step: '1' },
  Repeat: { field: 'repetitions', label: 'Successes needed ', init: 2, min: 1, max: 1000000, step: '1' },
  Timeout: { field: 'duration_s', label: 'Deadline ', unit: 's', init: 60, min: 0.001, max: 86400, step: 'any' },
  Inverter: null,
  ForceSuccess: null,
};
/// What Wrap may put around the selected node.
export const WRAPPERS = [...Object.keys(DECORATORS), 'Sequence', 'Fallback', 'OperatorDecision'];
const LEAVES = { skill: 'Skill', monitor: 'Monitor', condition: 'Condition' };
/// The fields of a Screw binding's holes that the page lets the programmer type, each with the Screw's
/// parameter that takes it hole by hole.
const SCREW_FIELDS = { torque_nm: 'torque_per_hole_nm', screw_type: 'screw_type_per_hole' };

/// A recipe with nothing in it yet.
export function emptyRecipe() { return { recipe_version: 1, task_id: 'planned-task', root: null }; }

/// The node's children as [pointer suffix, node] (children, a decorator's child, a decision's options).
export function childrenOf(node) {
  if (Array.isArray(node.children)) return node.children.map((c, i) => [`/children/${i}`, c]);
  if (node.child) return [['/child', node.child]];
  if (Array.isArray(node.options)) return node.options.map((o, i) => [`/options/${i}/child`, o.child]).filter(([, c]) => c);
  return [];
}
/// What `pointer` names in `doc` (undefined when nothing).
export function nodeAt(doc, pointer) {
  let v = doc;
  for (const k of pointer.split('/').slice(1)) v = v?.[k];
  return v;
}
/// Where a node sits: in a list (a control node's children, a decision's options: `list` says which)
/// at `index`, or as a decorator's only child (`list` null). null for the root.
export function parentOf(pointer) {
  let m = pointer.match(/^(.*)\/children\/(\d+)$/);
  if (m) return { parent: m[1], list: 'children', index: Number(m[2]) };
  m = pointer.match(/^(.*)\/options\/(\d+)\/child$/);
  if (m) return { parent: m[1], list: 'options', index: Number(m[2]) };
  m = pointer.match(/^(.*)\/child$/);
  return m ? { parent: m[1], list: null, index: 0 } : null;
}
function pointerIn(parent, list, index) { return list === 'options' ? `${parent}/options/${index}/child` : `${parent}/children/${index}`; }
export function isDecorator(node) { return Boolean(node) && Object.prototype.hasOwnProperty.call(DECORATORS, node.type); }
const isNode = (v) => Boolean(v) && typeof v === 'object' && !Array.isArray(v) && typeof v.type === 'string';
/// The skill, monitor or condition a leaf names ('' for other nodes).
export function leafName(node) { return node.skill || node.monitor || node.condition || ''; }
/// Substitutes a leaf's parameters (or their defaults) into a pre/postcondition: "attached(robot,$object)".
export function bindCondition(text, node, description) {
  return text.replace(/\$([A-Za-z_][A-Za-z0-9_]*)/g, (whole, name) => {
    const v = node.params?.[name] ?? description.params.find((p) => p.name === name)?.default;
    return v === undefined ? whole : String(v);
  });
}

/// A new node from a palette value `kind:name` (`control:Sequence`, `decorator:Retry`,
/// `decision:OperatorDecision`, `skill:Screw`, `monitor:…`, `condition:…`); null for anything else.
export function newNode(value) {
  const [kind, name] = String(value).split(':');
  if (!name) return null;
  if (kind === 'control') {
    if (!CONTROL.includes(name)) return null;
    const n = { type: name, children: [] };
    if (name === 'Parallel') { n.success_threshold = 1; n.failure_threshold = 1; }
    return n;
  }
  if (kind === 'decorator') {
    if (!Object.prototype.hasOwnProperty.call(DECORATORS, name)) return null;
    const d = DECORATORS[name];
    return d ? { type: name, [d.field]: d.init } : { type: name };
  }
  if (kind === 'decision') return name === 'OperatorDecision' ? { type: 'OperatorDecision', prompt: 'How to go on?', options: [] } : null;
  return LEAVES[kind] ? { type: LEAVES[kind], [kind]: name, params: {} } : null;
}

/// Every node of `doc` as [pointer, node], depth first.
export function allNodes(doc) {
  const out = [];
  const walk = (node, ptr) => { out.push([ptr, node]); for (const [s, c] of childrenOf(node)) walk(c, ptr + s); };
  if (doc.root) walk(doc.root, '/root');
  return out;
}
/// The node that owns `pointer`: the longest node pointer of the set `nodes` it starts with (undefined
/// for the recipe's own fields). Walks up the pointer, so it costs its depth, not the tree's size.
export function ownerOf(pointer, nodes) {
  for (let p = pointer; p; p = p.slice(0, Math.max(0, p.lastIndexOf('/')))) if (nodes.has(p)) return p;
  return undefined;
}
/// The errors ({pointer, message}) by the node that owns them (not a descendant's: a field is the rest
/// of the pointer). Recipe-level errors (task_id, assumptions) are left out.
export function errorsByNode(doc, errors) {
  const nodes = new Set(allNodes(doc).map(([p]) => p));
  const out = new Map();
  for (const e of errors) {
    const owner = ownerOf(e.pointer, nodes);
    if (owner === undefined) continue;
    if (!out.has(owner)) out.set(owner, []);
    out.get(owner).push(e);
  }
  return out;
}
/// The nodes whose errors differ between two errorsByNode() maps (those to redraw).
export function changedOwners(before, after) {
  const same = (a = [], b = []) => a.length === b.length && a.every((e, i) => e.pointer === b[i].pointer && e.message === b[i].message);
  return [...new Set([...before.keys(), ...after.keys()])].filter((ptr) => !same(before.get(ptr), after.get(ptr)));
}
/// A Screw's parameters from its holes' binding: the holes' features, and the typed torque and type —
/// none when each hole's comes from the world model, one for every hole when they agree, else one per
/// hole (`torque_per_hole_nm`, `screw_type_per_hole`).
function applyScrews(node) {
  const b = node.bindings.holes;
  node.params = node.params || {};
  node.params.holes = b.screws.map((s) => s.feature);
  for (const [f, perHole] of Object.entries(SCREW_FIELDS)) {
    const vals = b.screws.map((s) => s[f]);
    const fromWorld = b.screws.every((s) => s[f] === s[`world_${f}`]);
    delete node.params[f];
    delete node.params[perHole];
    if (fromWorld) continue;  // the skill takes each hole's value from the world model
    if (new Set(vals).size === 1) node.params[f] = vals[0];
    else node.params[perHole] = vals;
  }
}
/// The recipe to send: `doc` without an empty root.
export function recipeOf(doc) {
  const out = structuredClone(doc);
  if (!out.root) delete out.root;
  return out;
}
const sortedKeys = (v) => (Array.isArray(v) ? v.map(sortedKeys)
  : v && typeof v === 'object' ? Object.fromEntries(Object.keys(v).sort().map((k) => [k, sortedKeys(v[k])])) : v);
/// The recipe as canonical text: keys sorted at every level, two-space indent, a final newline, the
/// layout of the console's canonical text (services/console/src/planner.cpp), which Export downloads
/// (the two may write a number differently: 1e-7 here, 1e-07 there). Equal recipes give equal bytes.
export function canonical(doc) { return `${JSON.stringify(sortedKeys(recipeOf(doc)), null, 2)}\n`; }

/// The recipe being edited and the selected node. Both live in `holder` (`holder.doc`,
/// `holder.selected`: a node's JSON pointer, '' for none), the page's state, which the page's test hook
/// shows; an undo step restores both.
export class TreeDocument {
  constructor(holder = { doc: emptyRecipe(), selected: '' }) { this.holder = holder; }
  get doc() { return this.holder.doc; }
  get selected() { return this.holder.selected; }
  /// The selected node, or null.
  selectedNode() { return (this.selected && nodeAt(this.doc, this.selected)) || null; }
  nodes() { return allNodes(this.doc); }
  recipe() { return recipeOf(this.doc); }
  canonical() { return canonical(this.doc); }
  /// The document and its selection as text (an undo step), and back.
  snapshot() { return JSON.stringify({ doc: this.doc, selected: this.selected }); }
  restore(text) {
    const { doc, selected } = JSON.parse(text);
    this.holder.doc = doc;
    this.holder.selected = selected;
  }
  /// Another recipe (a file opened), its root selected.
  open(doc) {
    if (!doc || typeof doc !== 'object' || Array.isArray(doc)) return { error: `the file holds ${Array.isArray(doc) ? 'an array' : JSON.stringify(doc)}, not a recipe object` };
    this.holder.doc = doc;
    this.holder.selected = doc.root ? '/root' : '';
    return {};
  }
  select(pointer) {
    if (pointer && !isNode(nodeAt(this.doc, pointer))) return { error: `no node at ${pointer}` };
    this.holder.selected = pointer;
    return {};
  }
  /// Selects the node `delta` places after the selected one in the drawn order (stops at the ends).
  step(delta) {
    const pointers = this.nodes().map(([p]) => p);
    if (!pointers.length) return { error: 'The tree is empty.' };
    const j = Math.min(pointers.length - 1, Math.max(0, pointers.indexOf(this.selected) + delta));
    this.holder.selected = pointers[j];
    return {};
  }

  /// Adds a new node from a palette value (newNode()) as insert() does.
  add(value) {
    const node = newNode(value);
    return node ? this.insert(node) : { error: `There is no node "${value}" to add.` };
  }
  /// Puts `node` into the selected control node (at its end), as the selected decorator's child, as a
  /// new option of the selected OperatorDecision, or else after the selected node in its list; the
  /// new node is selected.
  insert(node) {
    if (!isNode(node)) return { error: `Not a node: ${JSON.stringify(node)}.` };
    const h = this.holder;
    if (!h.doc.root) {
      h.doc.root = node;
      h.selected = '/root';
      return { scope: '' };
    }
    const at = h.selected || '/root';
    const sel = nodeAt(h.doc, at);
    if (sel && Array.isArray(sel.children)) {
      sel.children.push(node);
      h.selected = `${at}/children/${sel.children.length - 1}`;
      return { scope: at };
    }
    if (isDecorator(sel) && !sel.child) {
      sel.child = node;
      h.selected = `${at}/child`;
      return { scope: at };
    }
    if (sel?.type === 'OperatorDecision') {
      sel.options = sel.options || [];
      sel.options.push({ label: `option ${sel.options.length + 1}`, child: node });
      h.selected = `${at}/options/${sel.options.length - 1}/child`;
      return { scope: at };
    }
    const p = parentOf(at);
    if (!p || !p.list) {
      return { error: isDecorator(sel) ? `The ${sel.type} has its child: select that child to add after it, or Wrap it.`
        : 'Select a Sequence, Parallel, Fallback, decorator or OperatorDecision to add into (the root is a leaf).' };
    }
    const parent = nodeAt(h.doc, p.parent);
    if (p.list === 'options') parent.options.splice(p.index + 1, 0, { label: `option ${parent.options.length + 1}`, child: node });
    else parent.children.splice(p.index + 1, 0, node);
    h.selected = pointerIn(p.parent, p.list, p.index + 1);
    return { scope: p.parent };
  }
  /// Replaces the selected node by a new `type` holding it (a decorator's child, a control node's first
  /// child, a decision's first option); the selection stays on the new node.
  wrap(type) {
    if (!this.selected) return { error: 'Select the node to wrap.' };
    if (!WRAPPERS.includes(type)) return { error: `Wrap in one of ${WRAPPERS.join(', ')}, not "${type}".` };
    const inner = nodeAt(this.doc, this.selected);
    const outer = newNode(DECORATORS[type] !== undefined ? `decorator:${type}` : type === 'OperatorDecision' ? 'decision:OperatorDecision' : `control:${type}`);
    if (isDecorator(outer)) outer.child = inner;
    else if (outer.type === 'OperatorDecision') outer.options.push({ label: 'option 1', child: inner });
    else outer.children.push(inner);
    this.replaceAt(this.selected, outer);
    return {};
  }
  replaceAt(pointer, node) {
    if (pointer === '/root') { this.doc.root = node; return; }
    const p = parentOf(pointer);
    const parent = nodeAt(this.doc, p.parent);
    if (p.list === 'options') parent.options[p.index].child = node;
    else if (p.list === 'children') parent.children[p.index] = node;
    else parent.child = node;
  }
  /// Swaps the selected node with the one `delta` places further in its list (a decision's option moves
  /// with its label); the selection follows it.
  move(delta) {
    const p = parentOf(this.selected);
    if (!p || !p.list) return { error: this.selected ? 'Only a node in a list moves (not the root, not a decorator\'s child).' : 'Select the node to move.' };
    const list = nodeAt(this.doc, p.parent)[p.list];
    const j = p.index + delta;
    if (!Number.isInteger(delta) || j < 0 || j >= list.length) return { error: `The node cannot move by ${delta} in a list of ${list.length}.` };
    [list[p.index], list[j]] = [list[j], list[p.index]];
    this.holder.selected = pointerIn(p.parent, p.list, j);
    return {};
  }
  /// Deletes the selected node (a decision's option goes with its child); its parent is selected.
  remove() {
    if (!this.selected) return { error: 'Select the node to delete.' };
    if (this.selected === '/root') {
      this.doc.root = null;
      this.holder.selected = '';
      return {};
    }
    const p = parentOf(this.selected);
    const parent = nodeAt(this.doc, p.parent);
    if (p.list) parent[p.list].splice(p.index, 1);
    else delete parent.child;
    this.holder.selected = p.parent;
    return {};
  }
  /// A copy of the selected subtree (bindings included), for insert() later.
  copy() {
    const node = this.selectedNode();
    return node ? { node: structuredClone(node) } : { error: 'Select the node to copy.' };
  }

  /// Sets the value at `pointer`: a node's field (`/root/children/0/name`), a parameter
  /// (`/root/params/object`: a leaf without `params` gets them), an option's label, a recipe field
  /// (`/task_id`); undefined deletes it. Refused when the pointer does not lead there.
  set(pointer, value) {
    const keys = pointer.split('/').slice(1);
    if (!pointer.startsWith('/') || !keys.length || keys.includes('')) return { error: `"${pointer}" is not a pointer to a field` };
    let v = this.doc;
    for (const [i, k] of keys.slice(0, -1).entries()) {
      if (v[k] === undefined && k === 'params' && i === keys.length - 2 && isNode(v)) v[k] = {};
      v = v[k];
      if (!v || typeof v !== 'object') return { error: `no ${keys.slice(0, i + 1).join('/')} in the recipe to set ${pointer}` };
    }
    const last = keys[keys.length - 1];
    if (value === undefined) delete v[last]; else v[last] = value;
    return {};
  }
  /// Parameter `name` of the node at `pointer` set to `value`, derived as `binding` says (a world model's
  /// feature, a CAD frame: kept in the node's `bindings`, checked again when the recipe is opened).
  bind(pointer, name, value, binding) {
    const node = nodeAt(this.doc, pointer);
    if (!isNode(node)) return { error: `no node at ${pointer} to bind ${name}` };
    node.params = node.params || {};
    node.params[name] = value;
    node.bindings = node.bindings || {};
    node.bindings[name] = binding;
    return {};
  }
  /// A pose parameter from the console's answer to POST /api/planner/frame ({model, model_sha256, args, pose}).
  bindFrame(pointer, name, answer) {
    const { model, model_sha256: sha, args, pose } = answer;
    return this.bind(pointer, name, pose, { rule: args.rule, model, model_sha256: sha, args, pose });
  }
  /// A Screw's holes from the console's answer to POST /api/planner/screws ({model, model_sha256,
  /// screws}): each screw keeps the world model's type and torque beside the ones the page lets type.
  bindScrews(pointer, answer) {
    const node = nodeAt(this.doc, pointer);
    if (!isNode(node)) return { error: `no node at ${pointer} to bind holes` };
    node.bindings = node.bindings || {};
    node.bindings.holes = {
      rule: 'screw_list', model: answer.model, model_sha256: answer.model_sha256,
      screws: answer.screws.map((s) => ({ ...s, world_screw_type: s.screw_type, world_torque_nm: s.torque_nm })),
    };
    applyScrews(node);
    return {};
  }
  /// A typed screw type or torque of hole `index` of the Screw at `pointer`; its parameters follow.
  setScrew(pointer, index, field, value) {
    const screws = nodeAt(this.doc, pointer)?.bindings?.holes?.screws;
    if (!screws) return { error: `no screw holes bound at ${pointer}` };
    if (!(field in SCREW_FIELDS)) return { error: `a screw's ${field} is not typed: only ${Object.keys(SCREW_FIELDS).join(' and ')}` };
    if (!screws[index]) return { error: `no hole ${index} of ${screws.length} at ${pointer}` };
    screws[index][field] = value;
    applyScrews(nodeAt(this.doc, pointer));
    return {};
  }
}
