// The planner's undo and redo without a browser (js/planner/undo.js on a js/planner/tree_document.js
// document): every step undone restores the recipe byte for byte, redo brings every edit back, typing is
// one step once quiet, the history keeps its last 200 steps. Run by ctest (console_web_unit_test).
import assert from 'node:assert/strict';
import { describe, it } from 'node:test';

import { TreeDocument } from '../js/planner/tree_document.js';
import { History } from '../js/planner/undo.js';

/// A document with its history, as the page keeps them: each structural edit recorded at once.
function editor(options = {}) {
  const tree = new TreeDocument();
  const history = new History(() => tree.snapshot(), options);
  history.present();
  const edit = (apply) => {
    history.settle();
    const r = apply();
    assert.equal(r.error, undefined);
    history.record();
  };
  const travel = (snapshot) => {
    if (snapshot === null) return false;
    tree.restore(snapshot);
    history.present();
    return true;
  };
  return { tree, history, edit, undo: () => travel(history.undo()), redo: () => travel(history.redo()) };
}

describe('History', () => {
  it('undoes every edit back to the empty recipe and redoes them to the same bytes', () => {
    const { tree, history, edit, undo, redo } = editor();
    const texts = [tree.canonical()];
    const selections = [tree.selected];
    const edits = [
      () => tree.add('control:Sequence'),
      () => tree.add('control:Parallel'),
      () => tree.add('skill:Localize'),
      () => tree.set('/root/children/0/children/0/params/object', 'target'),
      () => tree.add('monitor:YankMonitor'),
      () => tree.select('/root'),
      () => tree.add('skill:Screw'),
      () => tree.move(-1),
      () => tree.wrap('Retry'),
      () => tree.set('/root/children/0/max_attempts', 3),
      () => tree.bindScrews('/root/children/0/child', { model: 'object:target', model_sha256: '0'.repeat(64),
        screws: [{ feature: 'target/h1', screw_type: 'M6', torque_nm: 8 }] }),
      () => tree.remove(),
    ];
    for (const apply of edits) {
      edit(apply);
      texts.push(tree.canonical());
      selections.push(tree.selected);
    }
    // select() alone changes the snapshot (the selection is restored with the tree), so it is a step too.
    assert.equal(history.past.length, edits.length);
    for (let i = edits.length - 1; i >= 0; --i) {
      assert.ok(undo());
      assert.equal(tree.canonical(), texts[i], `undo to step ${i}`);
      assert.equal(tree.selected, selections[i]);
    }
    assert.equal(undo(), false, 'nothing before the empty recipe');
    assert.equal(history.canUndo, false);
    for (let i = 1; i <= edits.length; ++i) {
      assert.ok(redo());
      assert.equal(tree.canonical(), texts[i], `redo to step ${i}`);
    }
    assert.equal(redo(), false);
    assert.equal(history.canRedo, false);
  });

  it('restores the document itself, not only an equal one: the page\'s text compares equal too', () => {
    const { tree, edit, undo, redo } = editor();
    edit(() => tree.add('control:Sequence'));
    edit(() => tree.set('/description', 'what the task does'));
    const before = JSON.stringify(tree.doc);
    edit(() => tree.add('skill:Screw'));
    const after = JSON.stringify(tree.doc);
    undo();
    assert.equal(JSON.stringify(tree.doc), before);
    redo();
    assert.equal(JSON.stringify(tree.doc), after);
  });

  it('drops the redo steps with a new edit', () => {
    const { tree, history, edit, undo } = editor();
    edit(() => tree.add('control:Sequence'));
    edit(() => tree.add('skill:Screw'));
    undo();
    assert.equal(history.canRedo, true);
    edit(() => tree.add('skill:Release'));
    assert.equal(history.canRedo, false);
    assert.deepEqual(tree.doc.root.children.map((c) => c.skill), ['Release']);
  });

  it('makes no step of an edit that changed nothing', () => {
    const { tree, history, edit } = editor();
    edit(() => tree.add('control:Sequence'));
    edit(() => tree.set('/task_id', tree.doc.task_id));
    assert.equal(history.past.length, 1);
    assert.equal(history.record(), false);
  });

  it('keeps the last `limit` steps', () => {
    const { tree, history, edit, undo } = editor({ limit: 3 });
    edit(() => tree.add('control:Sequence'));
    for (let i = 0; i < 5; ++i) edit(() => tree.set('/root/name', `name ${i}`));
    assert.equal(history.past.length, 3);
    while (undo());
    assert.equal(tree.doc.root.name, 'name 1', 'the oldest steps are gone');
  });

  it('makes typing one step once quiet, and a structural edit settles the typing first', async () => {
    let told = 0;
    const { tree, history, edit, undo } = editor({ quietMs: 20, onChange: () => { told += 1; } });
    edit(() => tree.add('control:Sequence'));
    for (const name of ['l', 'lo', 'loc']) {
      tree.set('/root/name', name);
      history.recordLater();
    }
    assert.equal(history.past.length, 1, 'not a step while typing');
    await new Promise((ok) => setTimeout(ok, 60));
    assert.equal(history.past.length, 2, 'one step for the whole word');
    tree.set('/root/name', 'local');
    history.recordLater();
    edit(() => tree.add('skill:Localize'));  // settles 'local' as its own step, then the Add
    assert.equal(history.past.length, 4);
    undo();
    assert.equal(tree.doc.root.name, 'local');
    assert.equal(tree.doc.root.children.length, 0);
    undo();
    assert.equal(tree.doc.root.name, 'loc');
    assert.equal(told, 7, 'told at the start, after each of the 4 steps and each of the 2 undos');
    history.close();
  });

  it('undoes typing still waiting for its quiet time as a step of its own', () => {
    const { tree, history, edit, undo, redo } = editor({ quietMs: 60000 });
    edit(() => tree.add('control:Sequence'));
    tree.set('/root/name', 'typed');
    history.recordLater();
    assert.ok(undo());
    assert.equal(tree.doc.root.name, undefined, 'the typing was the step undone');
    assert.equal(history.future.length, 1);
    assert.ok(redo(), 'the typing can be redone');
    assert.equal(tree.doc.root.name, 'typed');
    history.close();
  });
});
