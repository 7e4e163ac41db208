// The selected node's form: its name; a Parallel's thresholds; a decorator's field; a decision's
// question and options' labels; a leaf's description, resources, pre- and postconditions (its parameters
// substituted) and one field per parameter of its description (docs/console.md, "Node form"). The
// validator's errors are marked on the field they name, on the condition or resource a node-level error
// quotes, and under the form. Each edit goes to the document, then `changed(false)` (a typed step).
import { el } from '../api.js';
import { quantityInput } from '../planner_units.js';
import { DECORATORS, bindCondition, errorsByNode, leafName } from './tree_document.js';

/// A labelled field with its unit, help text and the place for its errors.
function field(label, input, unit = '', help = '') {
  return el('div', { class: 'field' }, el('label', {}, label, input, unit ? el('span', { class: 'unit' }, ` ${unit}`) : null),
    help ? el('div', { class: 'muted small' }, help) : null, el('div', { class: 'field-error error' }));
}

export class NodeForm {
  /// Draws the form of `state.selected` into `box`. `tree`: the TreeDocument; `describe(name)`: a
  /// leaf's skill description; `features`: the FeaturePicker; `changed(redrawForm)`: after an edit.
  /// `bindings` (set once made): the Bindings, which add their parts to pose and Screw fields.
  constructor({ box, state, tree, describe, features, objects, changed }) {
    Object.assign(this, { box, state, tree, describe, features, objects, changed, bindings: null });
  }
  /// The selected node's errors (one walk of the tree for all the fields).
  ownErrors() { return errorsByNode(this.state.doc, this.state.errors).get(this.state.selected) || []; }

  render() {
    const ptr = this.state.selected;
    const node = this.tree.selectedNode();
    this.features.formFor(ptr);
    if (this.objects.armed && this.objects.armed.ptr !== ptr) this.objects.disarm();  // another node selected
    if (!node) return this.box.replaceChildren(el('p', { class: 'muted' }, 'Select a node.'));
    const edit = (key, value) => { this.tree.set(`${ptr}/${key}`, value); this.changed(false); };
    const parts = [el('p', {}, el('strong', {}, node.type), leafName(node) ? ` ${leafName(node)}` : '', el('code', { class: 'muted' }, ` ${ptr}`))];
    const name = el('input', { type: 'text', 'data-field': 'name', value: node.name || '',
      oninput: () => edit('name', name.value || undefined) });
    parts.push(field('Name ', name));
    if (node.type === 'Parallel') {
      for (const [key, label] of [['success_threshold', 'Successes needed (M) '], ['failure_threshold', 'Failures that fail it (K) ']]) {
        const input = el('input', { type: 'number', min: '1', step: '1', 'data-field': key, value: node[key],
          oninput: () => edit(key, Number(input.value)) });
        parts.push(field(label, input));
      }
    }
    const dec = DECORATORS[node.type];
    if (dec) {
      const input = el('input', { type: 'number', min: String(dec.min), max: String(dec.max), step: dec.step, 'data-field': dec.field, value: node[dec.field],
        oninput: () => edit(dec.field, Number(input.value)) });
      parts.push(field(dec.label, input, dec.unit || '', `${dec.field} in [${dec.min}, ${dec.max}]`));
    }
    if (node.type === 'OperatorDecision') {
      const prompt = el('input', { type: 'text', 'data-field': 'prompt', value: node.prompt || '',
        oninput: () => edit('prompt', prompt.value) });
      parts.push(field('Question to the operator ', prompt));
      (node.options || []).forEach((o, i) => {
        const label = el('input', { type: 'text', 'data-field': `options/${i}/label`, value: o.label || '',
          oninput: () => edit(`options/${i}/label`, label.value) });
        parts.push(field(`Option ${i + 1} `, label, '', 'the answer the operator picks; select the option\'s node to edit it'));
      });
    }
    const d = this.describe(leafName(node));
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
      if (!node.params) this.tree.set(`${ptr}/params`, {});
      for (const p of d.params) parts.push(this.paramField(node, ptr, p, edit));
    }
    parts.push(el('pre', { class: 'node-errors error' }));
    this.box.replaceChildren(...parts);
    this.markFields();
  }
  /// Parameter `p` (a description's) of `node` at `ptr`: an input by its type, its feature picker, a
  /// Screw's holes from picks, a pose from picks.
  paramField(node, ptr, p, edit) {
    const set = (v) => edit(`params/${p.name}`, v);
    const cur = node.params[p.name];
    const range = p.min !== undefined || p.max !== undefined ? `[${p.min ?? '−∞'}, ${p.max ?? '∞'}]` : '';
    const req = p.default === undefined;
    const help = `${p.type}${range ? ` in ${range}` : ''}${req ? ', required' : `, default ${JSON.stringify(p.default)}`}. ${p.description || ''}`;
    const label = `${p.name}${req ? ' *' : ''} `;
    let input;
    let pickObject = null;  // an object_id's "Pick in 3D"
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
    } else if (p.type === 'number_list') {
      // Numbers in the declared unit; what is not a number is kept as typed, for the validator to name.
      input = el('input', { type: 'text', value: Array.isArray(cur) ? cur.join(', ') : '',
        placeholder: `comma-separated${p.unit ? ` ${p.unit}` : ''}, e.g. one per hole`,
        oninput: () => set(input.value.trim() === '' ? undefined : input.value.split(',').map((s) => s.trim())
          .filter((s) => s !== '').map((s) => (Number.isFinite(Number(s)) ? Number(s) : s))) });
    } else if (p.type === 'object_id') {
      const chooser = this.objects.field(ptr, p.name, cur, p.default, set);
      input = chooser.select;
      pickObject = chooser.pick;
    } else if (p.type === 'pose') {
      input = el('textarea', { rows: '2', placeholder: '{"position_m": [x, y, z], "rpy_deg": [r, p, y], "frame": "world"}',
        oninput: () => { try { set(input.value.trim() === '' ? undefined : JSON.parse(input.value)); } catch { /* the validator says why */ } } });
      input.value = cur ? JSON.stringify(cur) : '';
    } else {
      input = el('input', { type: 'text', value: typeof cur === 'string' ? cur : '', placeholder: p.default !== undefined ? String(p.default) : '',
        oninput: () => set(input.value === '' ? undefined : input.value) });
    }
    input.dataset.field = `params/${p.name}`;
    input.id = `param-${p.name}`;
    const f = field(label, input, input.unitSelect ? '' : p.unit || '', help);
    if (input.unitSelect) input.after(input.unitSelect);
    if (pickObject) f.append(pickObject);
    if (p.type === 'feature_ref') f.append(this.features.field(node, ptr, p.name, input));
    if (node.skill === 'Screw' && p.name === 'holes') f.append(this.bindings.screwField(node, ptr));
    if (p.type === 'pose') f.append(this.bindings.frameField(node, ptr, p.name));
    return f;
  }
  /// Shows `value` in the form's field `key` (`params/holes`) when it is drawn, the focus left where it is.
  show(key, value) {
    const input = this.box.querySelector(`[data-field="${key}"]`);
    if (input) input.value = value;
  }
  /// The selected node's pre/postconditions again with its parameters as typed (the form keeps focus).
  refreshConditions() {
    const node = this.tree.selectedNode();
    const d = node && this.describe(leafName(node));
    if (!d) return;
    for (const c of this.box.querySelectorAll('code[data-condition]')) c.textContent = `${bindCondition(c.dataset.condition, node, d)} `;
    for (const c of this.box.querySelectorAll('code[data-claim]')) c.textContent = `${bindCondition(c.dataset.claim, node, d)} `;
  }
  /// Marks the validator's errors on the form: fields (aria-invalid, the message beside), the
  /// conditions and resources a node-level error names, the rest under the form.
  markFields() {
    const sel = this.state.selected;
    const own = this.ownErrors();
    for (const f of this.box.querySelectorAll('[data-field]')) {
      const msg = f.closest('.field')?.querySelector('.field-error');
      const errs = own.filter((e) => e.pointer === `${sel}/${f.dataset.field}` || e.pointer.startsWith(`${sel}/${f.dataset.field}/`));
      f.setAttribute('aria-invalid', String(errs.length > 0));
      if (msg) msg.textContent = errs.map((e) => e.message).join('; ');
    }
    // The node's own errors about a precondition it needs or a resource it claims (the validator names
    // them in quotes) mark that condition or resource in the form, with the message as its title.
    const nodeLevel = own.filter((e) => e.pointer === sel);
    const claimed = (m) => [...(m.match(/^resources? ((?:"[^"]*"(?:, )?)+) (?:is|are) claimed/)?.[1].matchAll(/"([^"]*)"/g) || [])].map((x) => x[1]);
    const mark = (c, errs, raw) => {
      c.classList.toggle('unmet', errs.length > 0);
      c.title = errs.length ? errs.map((e) => e.message).join('\n') : raw;
    };
    for (const c of this.box.querySelectorAll('[data-conditions="preconditions"] code[data-condition]')) {
      mark(c, nodeLevel.filter((e) => e.message.startsWith(`precondition "${c.textContent.trim()}" `)), c.dataset.condition);
    }
    for (const c of this.box.querySelectorAll('code[data-claim]')) {
      mark(c, nodeLevel.filter((e) => claimed(e.message).includes(c.textContent.trim())), c.dataset.claim);
    }
    const nodeErrs = this.box.querySelector('.node-errors');
    if (nodeErrs) {
      const fields = [...this.box.querySelectorAll('[data-field]')].map((f) => `${sel}/${f.dataset.field}`);
      nodeErrs.textContent = own.filter((e) => !fields.some((p) => e.pointer === p || e.pointer.startsWith(`${p}/`)))
        .map((e) => `${e.pointer}: ${e.message}`).join('\n');
    }
  }
}
