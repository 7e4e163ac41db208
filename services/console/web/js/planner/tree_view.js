// The planner's tree as the page draws it: a button per node (type, leaf, fields, name, its own errors),
// the devices the leaves claim, and the validation's error list. A click on a node, a claim or an error
// selects its node. Redraws are as small as the edit: one node's button for a typed field or a
// validation, one subtree for a structural edit inside it.
import { el } from '../api.js';
import { DECORATORS, allNodes, bindCondition, childrenOf, errorsByNode, isDecorator, leafName, nodeAt, ownerOf } from './tree_document.js';

export class TreeView {
  /// Draws `state.doc` (its `selected`, `errors`, `validation`) into `box`, the resources into
  /// `resources` and the error list into `errors`; `describe(name)`: a leaf's skill description;
  /// `select(pointer)`: a node was clicked.
  constructor({ box, resources, errors, state, describe, select }) {
    Object.assign(this, { box, resourcesBox: resources, errorsBox: errors, state, describe, select });
  }
  byNode() { return errorsByNode(this.state.doc, this.state.errors); }

  /// A node's button in the tree: its type, leaf and fields, name, and the count of its own errors.
  nodeButton(node, ptr, errs) {
    const d = DECORATORS[node.type];
    const extra = node.type === 'Parallel' ? ` (M=${node.success_threshold}, K=${node.failure_threshold})`
      : d ? ` (${d.field}=${node[d.field]})` : '';
    const label = `${node.type}${leafName(node) ? ` ${leafName(node)}` : ''}${extra}`;
    return el('button', { class: `pnode${ptr === this.state.selected ? ' selected' : ''}${errs.length ? ' invalid' : ''}`, 'data-pointer': ptr,
      onclick: () => this.select(ptr) },
    el('span', { class: 'ptype' }, label), node.name ? el('span', { class: 'pname' }, ` “${node.name}”`) : null,
    errs.length ? el('span', { class: 'perr-count', title: errs.map((e) => e.message).join('\n') }, ` ⚠ ${errs.length}`) : null);
  }
  /// Redraws one node's button, not its subtree (an edit of its fields, its errors after a validation):
  /// a 1,000-node tree is not rebuilt for a keystroke. False when the node is not drawn.
  renderNode(ptr, byNode = this.byNode()) {
    const old = this.box.querySelector(`button.pnode[data-pointer="${CSS.escape(ptr)}"]`);
    const node = nodeAt(this.state.doc, ptr);
    if (!old || !node) return false;
    old.replaceWith(this.nodeButton(node, ptr, byNode.get(ptr) || []));
    return true;
  }
  /// A node's row with its subtree.
  treeRow(node, ptr, byNode) {
    const li = el('li', { role: 'treeitem', 'data-pointer': ptr, 'aria-selected': String(ptr === this.state.selected) },
      this.nodeButton(node, ptr, byNode.get(ptr) || []));
    const kids = childrenOf(node);
    if (kids.length) {
      li.append(el('ul', { role: 'group' }, ...kids.map(([s, c]) => {
        const item = this.treeRow(c, ptr + s, byNode);
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
  renderSubtree(ptr) {
    const li = this.box.querySelector(`li[data-pointer="${CSS.escape(ptr)}"]`);
    const node = nodeAt(this.state.doc, ptr);
    if (!li || !node || /\/options\/\d+\/child$/.test(ptr)) return false;
    li.replaceWith(this.treeRow(node, ptr, this.byNode()));
    return true;
  }
  /// The whole tree, and the resources.
  render() {
    const { doc } = this.state;
    this.box.replaceChildren(doc.root ? el('ul', { role: 'none' }, this.treeRow(doc.root, '/root', this.byNode()))
      : el('p', { class: 'muted' }, 'Empty: choose a node and press Add.'));
    this.renderResources();
  }
  focusSelected() { this.box.querySelector(`button.pnode[data-pointer="${this.state.selected}"]`)?.focus(); }

  /// The tree's devices: each resource and the leaves that claim it (their descriptions' resources,
  /// parameters substituted, as the controller's validator reads them); a click selects the leaf.
  /// Whether two claims may overlap is the validator's to say (a conflict is an error on its node).
  renderResources() {
    const held = new Map();
    for (const [ptr, node] of allNodes(this.state.doc)) {
      const d = (node.type === 'Skill' || node.type === 'Monitor') && this.describe(leafName(node));
      for (const r of (d && d.resources) || []) {
        const name = bindCondition(r, node, d);
        if (!held.has(name)) held.set(name, []);
        held.get(name).push([ptr, node]);
      }
    }
    if (!held.size) return this.resourcesBox.replaceChildren(el('p', { class: 'muted small' }, 'No leaf claims a device yet.'));
    this.resourcesBox.replaceChildren(el('table', { class: 'small', 'aria-label': 'Resources the tree claims' },
      el('thead', {}, el('tr', {}, el('th', { scope: 'col' }, 'Resource'), el('th', { scope: 'col' }, 'Claimed by'))),
      el('tbody', {}, ...[...held].sort(([a], [b]) => a.localeCompare(b)).map(([name, nodes]) =>
        el('tr', { 'data-resource': name }, el('th', { scope: 'row' }, name),
          el('td', {}, ...nodes.map(([ptr, node]) => el('button', { class: 'link-button', 'data-pointer': ptr,
            onclick: () => this.selectOwner(ptr) }, `${leafName(node)}${node.name ? ` “${node.name}”` : ''}`))))))));
  }
  /// The validation's verdict: valid, or each error with its pointer (a click selects its node).
  renderErrors() {
    const v = this.state.validation;
    if (!v) return this.errorsBox.replaceChildren();
    this.errorsBox.replaceChildren(v.ok ? el('p', { class: 'ok', id: 'planner-valid' }, '✔ valid: the controller would accept this recipe')
      : el('ul', { id: 'planner-errors' }, ...v.errors.map((e) => el('li', { class: 'error' },
        el('button', { class: 'link-button', onclick: () => this.selectOwner(e.pointer) }, e.pointer || '(recipe)'), ` ${e.message}`))));
  }
  /// Selects the node that owns `pointer` (none for the recipe's own fields).
  selectOwner(pointer) {
    const owner = ownerOf(pointer, new Set(allNodes(this.state.doc).map(([p]) => p)));
    if (owner) this.select(owner);
  }
}
