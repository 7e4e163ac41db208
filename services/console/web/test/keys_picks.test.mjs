// The planner's pure helpers besides the document (js/planner/keys.js's key map, js/planner/picks.js's
// frame rules), without a browser. Run by ctest (console_web_unit_test).
import assert from 'node:assert/strict';
import { describe, it } from 'node:test';

import { keyCommand } from '../js/planner/keys.js';
import { declareFromPicks, frameFromPicks, placeFromPicks } from '../js/planner/picks.js';

describe('keyCommand', () => {
  const press = (key, mods = {}, { selected = true, textSelected = false } = {}) =>
    keyCommand({ key, ctrlKey: false, metaKey: false, shiftKey: false, altKey: false, ...mods }, { selected, textSelected: () => textSelected });

  it('maps the documented keys', () => {
    assert.equal(press('z', { ctrlKey: true }), 'undo');
    assert.equal(press('Z', { ctrlKey: true, shiftKey: true }), 'redo');
    assert.equal(press('y', { metaKey: true }), 'redo');
    assert.equal(press('c', { ctrlKey: true }), 'copy');
    assert.equal(press('x', { metaKey: true }), 'cut');
    assert.equal(press('v', { ctrlKey: true }), 'paste');
    assert.equal(press('Delete'), 'delete');
    assert.equal(press('ArrowUp', { altKey: true }), 'moveUp');
    assert.equal(press('ArrowDown', { altKey: true }), 'moveDown');
    assert.equal(press('ArrowUp'), 'previous');
    assert.equal(press('ArrowDown'), 'next');
  });
  it('leaves other keys, Delete without a selection and a copy of selected text to the browser', () => {
    assert.equal(press('a'), '');
    assert.equal(press('z'), '', 'z without Ctrl types');
    assert.equal(press('ArrowUp', { ctrlKey: true }), '');
    assert.equal(press('Delete', {}, { selected: false }), '');
    assert.equal(press('Delete', { ctrlKey: true }), '');
    assert.equal(press('c', { ctrlKey: true }, { textSelected: true }), '');
    assert.equal(press('x', { ctrlKey: true }, { textSelected: true }), '');
    assert.equal(press('v', { ctrlKey: true }, { textSelected: true }), 'paste');
  });
});

describe('frameFromPicks', () => {
  const ref = (kind, index) => ({ kind, index, model_sha256: 'ab'.repeat(32), signature: {} });
  const vertex = { kind: 'vertex', entity: 'target', vertex: 3, point_m: [0.1, 0, 0.05], ref: ref('vertex', 3) };
  const edge = (i) => ({ kind: 'edge', entity: 'target', edge: i, ref: ref('edge', i) });
  const face = { kind: 'face', entity: 'target', face: 7, point_m: [0, 0, 0.05], ref: ref('face', 7) };
  const hole = { kind: 'hole', entity: 'target', hole: 2, ref: ref('face', 12) };

  it('makes the paper\'s rule of a point and two edges, in the order picked', () => {
    assert.deepEqual(frameFromPicks([edge(4), vertex, edge(9)]), { model: 'object:target', rule: 'edges', point_m: [0.1, 0, 0.05],
      edges: [ref('edge', 4), ref('edge', 9)], summary: 'a point (vertex 3) and edges 4, 9' });
    assert.equal(frameFromPicks([face, edge(1), edge(2)]).summary, 'a point (face 7) and edges 1, 2');
  });
  it('makes the face and hole rules of one pick', () => {
    assert.deepEqual(frameFromPicks([face]), { model: 'object:target', rule: 'face', face: ref('face', 7), point_m: [0, 0, 0.05], summary: 'face 7 at the picked point' });
    assert.deepEqual(frameFromPicks([hole]), { model: 'object:target', rule: 'hole', hole: 2, summary: 'hole 2' });
  });
  it('says what to pick instead', () => {
    assert.match(frameFromPicks([]).error, /^pick a point \(a vertex or a face\) and two perpendicular edges/);
    assert.equal(frameFromPicks([vertex, { ...edge(1), entity: 'load' }]).error, 'the picks are on target and load: pick on one part');
    assert.match(frameFromPicks([vertex, edge(1)]).error, /^2 picks \(vertex, edge\): pick a point/);
    assert.match(frameFromPicks([hole, face]).error, /^2 picks \(hole, face\)/);
  });
});

describe('declareFromPicks', () => {
  const face = { kind: 'face', entity: 'target', face: 2 };
  const edge = { kind: 'edge', entity: 'target', edge: 7 };
  const hole = { kind: 'hole', entity: 'target', hole: 1 };

  it('makes a grasp frame of a face and an edge of it, by indices only', () => {
    assert.deepEqual(declareFromPicks([face, edge], { kind: 'grasp_frame', name: 'g', x_reversed: true }),
      { model: 'object:target', kind: 'grasp_frame', name: 'g', face: 2, x_edge: 7, x_reversed: true });
  });
  it('takes the stand-off in millimetres', () => {
    assert.equal(declareFromPicks([face], { kind: 'approach_waypoint', name: 'a', standoff_mm: '100' }).standoff_m, 0.1);
    assert.match(declareFromPicks([face], { kind: 'approach_waypoint', name: 'a', standoff_mm: '' }).error, /stand-off/);
  });
  it('makes the insertion of the first picked face onto the second part\'s face', () => {
    const onto = { kind: 'face', entity: 'plate', face: 5 };
    assert.deepEqual(declareFromPicks([face, onto], { kind: 'insertion' }),
      { model: 'object:target', kind: 'insertion', face: 2, target: { model: 'object:plate', face: 5 } });
    assert.match(declareFromPicks([face, { ...face, face: 3 }], { kind: 'insertion' }).error, /face of the part it goes into/);
    assert.match(declareFromPicks([face, hole], { kind: 'insertion' }).error, /face of the part it goes into/);
  });
  it('pins the insertion by a hole of each part, paired in the order picked', () => {
    const onto = { ...face, entity: 'plate', face: 5 };
    const own = (n) => ({ ...hole, entity: 'target', hole: n }), theirs = (n) => ({ ...hole, entity: 'plate', hole: n });
    assert.deepEqual(declareFromPicks([face, onto, own(1), theirs(4), own(2), theirs(3)], { kind: 'insertion' }).pins,
      [{ hole: 1, target_hole: 4 }, { hole: 2, target_hole: 3 }]);
    assert.match(declareFromPicks([face, onto, own(1)], { kind: 'insertion' }).error, /in pairs/);
    assert.match(declareFromPicks([face, onto, own(1), own(2)], { kind: 'insertion' }).error, /in pairs/);
    assert.equal(declareFromPicks([face, onto], { kind: 'insertion' }).pins, undefined);
  });
  it('places a marker or the rope attachment at the picked point of a face, or the rope at a hole', () => {
    const at = { ...face, point_m: [0.2, 0, 0.05] };
    assert.deepEqual(declareFromPicks([at], { kind: 'marker', dictionary: 'DICT_4X4_50', marker_id: '12', marker_size_mm: '80' }),
      { model: 'object:target', kind: 'marker', face: 2, point_m: [0.2, 0, 0.05], dictionary: 'DICT_4X4_50', marker_id: 12, size_m: 0.08 });
    assert.match(declareFromPicks([at], { kind: 'marker', dictionary: 'DICT_4X4_50', marker_id: '', marker_size_mm: '80' }).error, /id and size/);
    assert.match(declareFromPicks([hole], { kind: 'marker' }).error, /point on a face/);
    assert.deepEqual(declareFromPicks([hole], { kind: 'rope_attachment' }), { model: 'object:target', kind: 'rope_attachment', hole: 1 });
    assert.deepEqual(declareFromPicks([at], { kind: 'rope_attachment' }), { model: 'object:target', kind: 'rope_attachment', face: 2, point_m: [0.2, 0, 0.05] });
    // A sling: any one pick names the part; the CAD service finds its centre of mass.
    assert.deepEqual(declareFromPicks([hole], { kind: 'rope_attachment', sling: true }), { model: 'object:target', kind: 'rope_attachment', above_centre_of_mass: true });
    assert.match(declareFromPicks([], { kind: 'rope_attachment', sling: true }).error, /sling/);
  });
  it('makes screw holes of one picked hole and the screw', () => {
    assert.deepEqual(declareFromPicks([hole], { kind: 'screw_holes', name: 'm', like: true, screw_type: 'M10x30', torque_nm: '45' }),
      { model: 'object:target', kind: 'screw_holes', name: 'm', hole: 1, like: true, screw: { screw_type: 'M10x30', torque_nm: 45 } });
  });
  it('says what to pick', () => {
    assert.match(declareFromPicks([hole, face], { kind: 'screw_holes', name: 'm', screw_type: 'M', torque_nm: 1 }).error, /one hole/);
    assert.match(declareFromPicks([edge], { kind: 'grasp_frame', name: 'g' }).error, /one face/);
    assert.match(declareFromPicks([face, { ...edge, entity: 'load' }], { kind: 'grasp_frame', name: 'g' }).error, /target and load/);
    assert.match(declareFromPicks([face], { kind: 'grasp_frame', name: 'a b' }).error, /name/);
  });
});

describe('placeFromPicks', () => {
  const face = (entity, f) => ({ kind: 'face', entity, face: f, ref: { index: f }, point_m: [0, 0, 0] });
  const edge = (entity, e) => ({ kind: 'edge', entity, edge: e });
  it('places the first picked part on the second, lined up by an edge of each when picked', () => {
    const plain = placeFromPicks([face('load', 4), face('target', 2)]);
    assert.equal(plain.model, 'object:load');
    assert.equal(plain.onto.model, 'object:target');
    assert.equal(plain.edge, undefined);
    const lined = placeFromPicks([face('load', 4), edge('load', 3), face('target', 2), edge('target', 7)]);
    assert.equal(lined.edge, 3);
    assert.equal(lined.onto.edge, 7);
    assert.match(lined.summary, /edge 3 along edge 7/);
  });
  it('says what to pick otherwise', () => {
    assert.match(placeFromPicks([face('load', 4), edge('load', 3), face('target', 2)]).error, /one edge of load and one of target/);
    assert.match(placeFromPicks([face('load', 4), face('load', 5)]).error, /both faces are of load/);
    assert.match(placeFromPicks([face('load', 4)]).error, /pick a face/);
  });
});
