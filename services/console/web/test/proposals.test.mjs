// The "Declare a feature" panel's proposals (js/planner/proposals.js): names a part does not use yet and
// marker ids no object carries, from the running cell document. Run by ctest (console_web_unit_test).
import assert from 'node:assert/strict';
import { describe, it } from 'node:test';

import { dictionarySize, featureIds, freeMarkerId, freeName, freePrefix, markerIds, proposals } from '../js/planner/proposals.js';

const doc = {
  entities: [
    { id: 'robot', calibration_board: { markers: { dictionary: 'DICT_4X4_50', items: [{ id: 0 }, { id: 3 }] } } },
    { id: 'load', features: { grasp_frames: [{ id: 'grasp' }], approach_waypoints: [{ id: 'pre_grasp' }],
      markers: { dictionary: 'DICT_4X4_50', items: [{ id: 1 }, { id: 2 }] }, rope_attachment: { position_m: [0, 0, 0] } } },
    { id: 'plate', features: { screw_holes: [{ id: 'a1' }, { id: 'a2' }, { id: 'c10' }, { id: 'bolt' }] } },
    { id: 'bare' },
  ],
};
const pick = (entity) => [{ kind: 'face', entity }];

describe('proposals', () => {
  it('collects a part\'s feature ids from every list, and nothing for an unknown part', () => {
    assert.deepEqual([...featureIds(doc, 'plate')].sort(), ['a1', 'a2', 'bolt', 'c10']);
    assert.deepEqual([...featureIds(doc, 'load')].sort(), ['grasp', 'pre_grasp']);
    assert.equal(featureIds(doc, 'nobody').size, 0);
    assert.equal(featureIds(null, 'load').size, 0);
  });
  it('counts the markers of every object and of a calibration board', () => {
    assert.deepEqual([...markerIds(doc)].sort(), [0, 1, 2, 3]);
    assert.equal(freeMarkerId(doc, 'DICT_4X4_50'), 4);
    assert.equal(freeMarkerId({}, 'DICT_4X4_50'), 0);
    assert.equal(dictionarySize('DICT_6X6_250'), 250);
    assert.equal(freeMarkerId(doc, 'NOT_A_DICTIONARY'), '', 'no size, no proposal');
    const full = { entities: [{ id: 'x', features: { markers: { items: Array.from({ length: 50 }, (_, id) => ({ id })) } } }] };
    assert.equal(freeMarkerId(full, 'DICT_4X4_50'), '', 'every id taken');
    assert.equal(freeMarkerId(full, 'DICT_4X4_100'), 50);
  });
  it('proposes a frame\'s name, numbered when the part has it already', () => {
    assert.equal(freeName('grasp', new Set()), 'grasp');
    assert.equal(freeName('grasp', new Set(['grasp', 'grasp2'])), 'grasp3');
    assert.deepEqual(proposals(doc, pick('load'), 'grasp_frame', ''), { name: 'grasp2' });
    assert.deepEqual(proposals(doc, pick('bare'), 'approach_waypoint', ''), { name: 'pre_grasp' });
    assert.deepEqual(proposals(doc, [], 'grasp_frame', ''), { name: 'grasp' }, 'nothing picked yet');
  });
  it('proposes the first letter no hole pattern of the part uses', () => {
    assert.equal(freePrefix(featureIds(doc, 'plate')), 'b', 'a1 takes a; c10 takes c; bolt is a name, not a pattern');
    assert.deepEqual(proposals(doc, pick('bare'), 'screw_holes', ''), { name: 'a' });
    assert.equal(freePrefix(new Set(Array.from({ length: 26 }, (_, i) => `${String.fromCharCode(97 + i)}1`))), '');
  });
  it('proposes a marker id, and nothing for the kinds without a name', () => {
    assert.deepEqual(proposals(doc, pick('plate'), 'marker', 'DICT_4X4_50'), { marker_id: 4 });
    assert.deepEqual(proposals(doc, pick('plate'), 'insertion', ''), {});
    assert.deepEqual(proposals(doc, pick('plate'), 'rope_attachment', ''), {});
  });
});
