// The planner's recipe document without a browser (js/planner/tree_document.js): trees built by the
// page's edits, where each edit puts the node and the selection, refused edits that change nothing and
// say why, the bindings' edits, and the readings the page draws from. Run by ctest (console_web_unit_test).
import assert from 'node:assert/strict';
import { describe, it } from 'node:test';

import {
  TreeDocument, allNodes, canonical, changedOwners, errorsByNode, newNode, ownerOf, parentOf,
} from '../js/planner/tree_document.js';

/// A document built by palette values added in turn, each `[select, value]` (select: a pointer to
/// select first, or null to add where the last edit left the selection).
function built(steps) {
  const tree = new TreeDocument();
  for (const [at, value] of steps) {
    if (at !== null) assert.deepEqual(tree.select(at), {});
    const r = tree.add(value);
    assert.equal(r.error, undefined, `add ${value} at ${at ?? tree.selected}`);
  }
  return tree;
}
/// A refused edit: an error that says something, and the document and selection unchanged.
function refused(tree, apply, pattern) {
  const before = tree.snapshot();
  const r = apply();
  assert.match(r.error ?? '', pattern);
  assert.equal(tree.snapshot(), before, 'a refused edit changes nothing');
}
const kinds = (tree) => allNodes(tree.doc).map(([p, n]) => `${p} ${n.type}${n.skill ? ` ${n.skill}` : ''}`);

describe('newNode', () => {
  it('makes the palette\'s nodes with their defaults', () => {
    assert.deepEqual(newNode('control:Parallel'), { type: 'Parallel', children: [], success_threshold: 1, failure_threshold: 1 });
    assert.deepEqual(newNode('decorator:Retry'), { type: 'Retry', max_attempts: 2 });
    assert.deepEqual(newNode('decorator:Timeout'), { type: 'Timeout', duration_s: 60 });
    assert.deepEqual(newNode('decorator:Inverter'), { type: 'Inverter' });
    assert.deepEqual(newNode('decision:OperatorDecision'), { type: 'OperatorDecision', prompt: 'How to go on?', options: [] });
    assert.deepEqual(newNode('skill:Screw'), { type: 'Skill', skill: 'Screw', params: {} });
    assert.deepEqual(newNode('monitor:YankMonitor'), { type: 'Monitor', monitor: 'YankMonitor', params: {} });
  });
  it('makes nothing of what the palette does not offer', () => {
    for (const v of ['control:Loop', 'decorator:Forever', 'decision:Vote', 'robot:Screw', 'skill:', '', 'Sequence']) {
      assert.equal(newNode(v), null, v);
    }
  });
});

describe('TreeDocument edits', () => {
  it('puts each added node where the Planner\'s Add does and selects it', () => {
    const tree = built([
      [null, 'control:Sequence'],          // the root
      [null, 'control:Parallel'],          // into the selected Sequence
      [null, 'skill:Localize'],            // into the selected Parallel
      [null, 'monitor:YankMonitor'],       // after the selected leaf
      ['/root', 'decorator:Retry'],        // at the Sequence's end
      [null, 'skill:Screw'],               // the Retry's child
      ['/root', 'decision:OperatorDecision'],
      [null, 'skill:Release'],             // the decision's first option
      [null, 'skill:Release'],             // a second option, after the selected option's child
    ]);
    assert.deepEqual(kinds(tree), [
      '/root Sequence',
      '/root/children/0 Parallel',
      '/root/children/0/children/0 Skill Localize',
      '/root/children/0/children/1 Monitor',
      '/root/children/1 Retry',
      '/root/children/1/child Skill Screw',
      '/root/children/2 OperatorDecision',
      '/root/children/2/options/0/child Skill Release',
      '/root/children/2/options/1/child Skill Release',
    ]);
    assert.equal(tree.selected, '/root/children/2/options/1/child');
    assert.deepEqual(tree.doc.root.children[2].options.map((o) => o.label), ['option 1', 'option 2']);
  });

  it('says which subtree an insertion stayed inside', () => {
    const tree = built([[null, 'control:Sequence'], [null, 'skill:Localize']]);
    assert.deepEqual(tree.add('skill:Release'), { scope: '/root' });  // after the selected leaf
    assert.deepEqual(tree.select('/root'), {});
    assert.deepEqual(tree.add('decorator:Retry'), { scope: '/root' });
    assert.deepEqual(tree.add('skill:Screw'), { scope: '/root/children/2' });
    assert.deepEqual(new TreeDocument().add('skill:Screw'), { scope: '' });  // a new root: all of it
  });

  it('refuses an insertion with nowhere to go, saying where to add', () => {
    const leaf = built([[null, 'skill:Localize']]);
    refused(leaf, () => leaf.add('skill:Release'), /Select a Sequence, Parallel, Fallback, decorator or OperatorDecision/);
    const full = built([[null, 'decorator:Retry'], [null, 'skill:Screw']]);
    assert.deepEqual(full.select('/root'), {});
    refused(full, () => full.add('skill:Release'), /^The Retry has its child: select that child to add after it, or Wrap it\.$/);
    refused(full, () => full.add('robot:Screw'), /no node "robot:Screw"/);
    refused(full, () => full.insert({ skill: 'Screw' }), /Not a node/);
  });

  it('wraps the selected node, which stays selected inside its new parent', () => {
    const tree = built([[null, 'control:Sequence'], [null, 'skill:Screw']]);
    assert.deepEqual(tree.wrap('Retry'), {});
    assert.deepEqual(tree.doc.root.children[0], { type: 'Retry', max_attempts: 2, child: { type: 'Skill', skill: 'Screw', params: {} } });
    assert.equal(tree.selected, '/root/children/0');
    assert.deepEqual(tree.wrap('OperatorDecision'), {});
    assert.deepEqual(tree.doc.root.children[0].options.map((o) => [o.label, o.child.type]), [['option 1', 'Retry']]);
    assert.deepEqual(tree.select('/root'), {});
    assert.deepEqual(tree.wrap('Fallback'), {});
    assert.deepEqual(kinds(tree).slice(0, 3), ['/root Fallback', '/root/children/0 Sequence', '/root/children/0/children/0 OperatorDecision']);
  });

  it('refuses to wrap nothing, or in what cannot hold a node', () => {
    const tree = built([[null, 'control:Sequence'], [null, 'skill:Screw']]);
    refused(tree, () => tree.wrap('Loop'), /Wrap in one of Retry, Repeat, Timeout, Inverter, ForceSuccess, Sequence, Fallback, OperatorDecision, not "Loop"/);
    assert.deepEqual(tree.select(''), {});
    refused(tree, () => tree.wrap('Retry'), /^Select the node to wrap\.$/);
  });

  it('moves the selected node within its list and refuses to move past its ends', () => {
    const tree = built([[null, 'control:Sequence'], [null, 'skill:Localize'], [null, 'skill:Screw'], [null, 'skill:Release']]);
    assert.deepEqual(tree.move(-1), {});
    assert.equal(tree.selected, '/root/children/1');
    assert.deepEqual(tree.doc.root.children.map((c) => c.skill), ['Localize', 'Release', 'Screw']);
    assert.deepEqual(tree.move(-1), {});
    refused(tree, () => tree.move(-1), /cannot move by -1 in a list of 3/);
    assert.deepEqual(tree.select('/root/children/2'), {});
    refused(tree, () => tree.move(1), /cannot move by 1 in a list of 3/);
    assert.deepEqual(tree.select('/root'), {});
    refused(tree, () => tree.move(1), /Only a node in a list moves/);
  });

  it('removes the selected node (an option with its child) and selects its parent', () => {
    const tree = built([[null, 'decision:OperatorDecision'], [null, 'skill:Screw'], ['/root', 'skill:Release']]);
    assert.deepEqual(tree.remove(), {});
    assert.equal(tree.selected, '/root');
    assert.equal(tree.doc.root.options.length, 1);
    assert.deepEqual(tree.remove(), {});
    assert.equal(tree.doc.root, null);
    assert.equal(tree.selected, '');
    refused(tree, () => tree.remove(), /^Select the node to delete\.$/);
  });

  it('copies a subtree apart from the document: pasting it twice makes two', () => {
    const tree = built([[null, 'control:Sequence'], [null, 'skill:Screw']]);
    tree.set('/root/children/0/params/holes', ['target/h1']);
    const { node } = tree.copy();
    node.params.holes.push('changed after the copy');
    assert.deepEqual(tree.doc.root.children[0].params.holes, ['target/h1'], 'the copy is not the node');
    assert.deepEqual(tree.insert(structuredClone(tree.copy().node)), { scope: '/root' });
    assert.deepEqual(tree.insert(structuredClone(tree.copy().node)), { scope: '/root' });
    assert.equal(tree.doc.root.children.length, 3);
    tree.doc.root.children[2].params.holes.push('target/h2');
    assert.deepEqual(tree.doc.root.children[1].params.holes, ['target/h1']);
    assert.deepEqual(tree.select(''), {});
    assert.match(tree.copy().error, /^Select the node to copy\.$/);
  });

  it('sets fields, parameters and recipe fields; undefined deletes; a bad pointer is refused', () => {
    const tree = built([[null, 'control:Sequence'], [null, 'decision:OperatorDecision'], [null, 'skill:Localize']]);
    delete tree.doc.root.children[0].options[0].child.params;  // a leaf of an opened recipe, without params
    assert.deepEqual(tree.set('/root/children/0/options/0/child/params/object', 'target'), {});
    assert.deepEqual(tree.doc.root.children[0].options[0].child.params, { object: 'target' });
    assert.deepEqual(tree.set('/root/children/0/options/0/label', 'retry'), {});
    assert.deepEqual(tree.set('/root/name', 'main'), {});
    assert.deepEqual(tree.set('/task_id', 'crane-insert'), {});
    assert.deepEqual(tree.set('/root/name', undefined), {});
    assert.equal('name' in tree.doc.root, false);
    assert.equal(tree.doc.task_id, 'crane-insert');
    assert.equal(tree.doc.root.children[0].options[0].label, 'retry');
    refused(tree, () => tree.set('/root/children/5/name', 'x'), /no root\/children\/5 in the recipe/);
    refused(tree, () => tree.set('/root/bindings/pose/rule', 'edges'), /no root\/bindings in the recipe/);
    refused(tree, () => tree.set('task_id', 'x'), /not a pointer to a field/);
    refused(tree, () => tree.set('/root//name', 'x'), /not a pointer to a field/);
  });

  it('selects only nodes, and steps through them in the drawn order', () => {
    const tree = built([[null, 'control:Sequence'], [null, 'skill:Localize'], ['/root', 'skill:Screw']]);
    refused(tree, () => tree.select('/root/children/7'), /no node at \/root\/children\/7/);
    refused(tree, () => tree.select('/root/children/0/params'), /no node at/);
    assert.deepEqual(tree.select('/root'), {});
    tree.step(1);
    assert.equal(tree.selected, '/root/children/0');
    tree.step(5);
    assert.equal(tree.selected, '/root/children/1');
    tree.step(-9);
    assert.equal(tree.selected, '/root');
    assert.match(new TreeDocument().step(1).error, /empty/);
  });

  it('opens a recipe object with its root selected, and refuses anything else', () => {
    const tree = new TreeDocument();
    refused(tree, () => tree.open([1, 2]), /an array, not a recipe object/);
    refused(tree, () => tree.open(null), /null, not a recipe object/);
    refused(tree, () => tree.open('crane-insert'), /"crane-insert", not a recipe object/);
    assert.deepEqual(tree.open({ recipe_version: 1, task_id: 't', root: { type: 'Skill', skill: 'Screw' } }), {});
    assert.equal(tree.selected, '/root');
    assert.deepEqual(tree.open({ recipe_version: 1, task_id: 'empty' }), {});
    assert.equal(tree.selected, '');
  });
});

describe('bindings', () => {
  const answer = {
    model: 'object:target', model_sha256: 'ab'.repeat(32),
    screws: [1, 2].map((i) => ({ feature: `target/h${i}`, hole: i, screw_type: 'M6', torque_nm: 8, pose: { position_m: [i, 0, 0] } })),
  };
  const screwTree = () => built([[null, 'control:Sequence'], [null, 'skill:Screw']]);

  it('binds a Screw\'s holes: the features become its holes, each hole\'s values the world model\'s', () => {
    const tree = screwTree();
    assert.deepEqual(tree.bindScrews('/root/children/0', answer), {});
    const node = tree.doc.root.children[0];
    assert.deepEqual(node.params, { holes: ['target/h1', 'target/h2'] });
    assert.equal(node.bindings.holes.rule, 'screw_list');
    assert.deepEqual(node.bindings.holes.screws.map((s) => [s.world_screw_type, s.world_torque_nm]), [['M6', 8], ['M6', 8]]);
  });

  it('takes one typed torque for every hole, or one per hole when they differ', () => {
    const tree = screwTree();
    tree.bindScrews('/root/children/0', answer);
    const params = () => tree.doc.root.children[0].params;
    assert.deepEqual(tree.setScrew('/root/children/0', 0, 'torque_nm', 10), {});
    assert.equal(params().torque_nm, undefined);
    assert.deepEqual(params().torque_per_hole_nm, [10, 8], 'differing torques go hole by hole');
    assert.deepEqual(tree.setScrew('/root/children/0', 1, 'screw_type', 'M8'), {});
    assert.deepEqual(params().screw_type_per_hole, ['M6', 'M8']);
    assert.deepEqual(tree.setScrew('/root/children/0', 1, 'torque_nm', 10), {});
    assert.equal(params().torque_nm, 10);
    assert.equal(params().torque_per_hole_nm, undefined);
    assert.deepEqual(tree.setScrew('/root/children/0', 1, 'screw_type', 'M6'), {});
    assert.equal(params().screw_type_per_hole, undefined, 'the world model\'s again for every hole');
    assert.equal(params().screw_type, undefined);
    refused(tree, () => tree.setScrew('/root/children/0', 2, 'torque_nm', 10), /no hole 2 of 2/);
    refused(tree, () => tree.setScrew('/root/children/0', 0, 'feature', 'target/h9'), /feature is not typed/);
    refused(tree, () => tree.setScrew('/root', 0, 'torque_nm', 1), /no screw holes bound at \/root/);
  });

  it('binds a pose parameter to a CAD frame, and refuses a pointer to no node', () => {
    const tree = built([[null, 'skill:Place']]);
    const pose = { position_m: [0.1, 0.2, 0.3], rpy_deg: [0, 0, 90], frame: 'target' };
    const frame = { model: 'object:target', model_sha256: 'cd'.repeat(32), args: { rule: 'edges', edges: [] }, pose };
    assert.deepEqual(tree.bindFrame('/root', 'pose', frame), {});
    assert.deepEqual(tree.doc.root.params.pose, pose);
    assert.deepEqual(tree.doc.root.bindings.pose, { rule: 'edges', model: 'object:target', model_sha256: 'cd'.repeat(32), args: frame.args, pose });
    refused(tree, () => tree.bindFrame('/root/child', 'pose', frame), /no node at \/root\/child to bind pose/);
    refused(tree, () => tree.bindScrews('/root/children/0', answer), /no node at/);
  });
});

describe('readings', () => {
  it('finds where a node sits and which node owns an error', () => {
    assert.deepEqual(parentOf('/root/children/2'), { parent: '/root', list: 'children', index: 2 });
    assert.deepEqual(parentOf('/root/options/1/child'), { parent: '/root', list: 'options', index: 1 });
    assert.deepEqual(parentOf('/root/child'), { parent: '/root', list: null, index: 0 });
    assert.equal(parentOf('/root'), null);
    const nodes = new Set(['/root', '/root/children/1']);
    assert.equal(ownerOf('/root/children/1/params/holes/0', nodes), '/root/children/1');
    assert.equal(ownerOf('/root/children/10/name', nodes), '/root', 'children/10 is not children/1');
    assert.equal(ownerOf('/task_id', nodes), undefined);
  });

  it('groups errors by their node and names the nodes whose errors changed', () => {
    const tree = built([[null, 'control:Parallel'], [null, 'skill:Release'], ['/root', 'skill:Release']]);
    const first = [{ pointer: '/root/success_threshold', message: 'too many' }, { pointer: '/task_id', message: 'empty' }];
    const second = [{ pointer: '/root/children/1', message: 'resources "robot" are claimed both' }];
    const before = errorsByNode(tree.doc, first);
    const after = errorsByNode(tree.doc, second);
    assert.deepEqual([...before.keys()], ['/root'], 'a recipe-level error has no node');
    assert.deepEqual(changedOwners(before, after).sort(), ['/root', '/root/children/1']);
    assert.deepEqual(changedOwners(after, errorsByNode(tree.doc, structuredClone(second))), []);
  });

  it('exports the recipe canonically: keys sorted, two-space indent, no empty root', () => {
    const tree = built([[null, 'control:Sequence']]);
    tree.set('/assumptions', ['hooked(crane,load)']);
    assert.equal(tree.canonical(), '{\n  "assumptions": [\n    "hooked(crane,load)"\n  ],\n  "recipe_version": 1,\n'
      + '  "root": {\n    "children": [],\n    "type": "Sequence"\n  },\n  "task_id": "planned-task"\n}\n');
    const reordered = JSON.parse(JSON.stringify({ task_id: 'planned-task', root: { type: 'Sequence', children: [] }, assumptions: ['hooked(crane,load)'], recipe_version: 1 }));
    assert.equal(canonical(reordered), tree.canonical(), 'the same recipe gives the same bytes');
    assert.equal(canonical(new TreeDocument().doc), '{\n  "recipe_version": 1,\n  "task_id": "planned-task"\n}\n');
    assert.equal('root' in tree.recipe(), true);
    const empty = new TreeDocument();
    assert.equal('root' in empty.recipe(), false);
    assert.equal(empty.doc.root, null, 'the recipe sent is a copy: the document keeps its empty root');
  });
});
