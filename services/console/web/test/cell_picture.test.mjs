// The 3D cell's picture: the live changes merged, and a replay's moment from a run's rows.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { cellAt, mergeCell } from '../js/cell_picture.js';

const rows = [
  { t: 10, objects: { a: { position_m: [1, 0, 0] }, b: { position_m: [2, 0, 0] } }, hook: [0, 0, 4] },
  { t: 11, objects: { a: { position_m: [1.5, 0, 0] } } },
  { t: 12, hook: [0, 0, 3], tool: [1, 1, 1] },
];

test('a change replaces the objects it names and keeps the others', () => {
  const picture = mergeCell({}, rows[0]);
  mergeCell(picture, rows[1]);
  assert.deepEqual(picture.objects.a.position_m, [1.5, 0, 0]);
  assert.deepEqual(picture.objects.b.position_m, [2, 0, 0]);
  assert.deepEqual(picture.hook, [0, 0, 4]);
  assert.equal(picture.t, 11);
});

test('the moment of a replay is every row at or before it', () => {
  assert.deepEqual(cellAt(rows, 9.99), {});
  assert.deepEqual(cellAt(rows, 10.5).objects.a.position_m, [1, 0, 0]);
  const at12 = cellAt(rows, 12);
  assert.deepEqual(at12.hook, [0, 0, 3]);
  assert.deepEqual(at12.tool, [1, 1, 1]);
  assert.deepEqual(at12.objects.a.position_m, [1.5, 0, 0]);
  assert.equal(cellAt(rows, 11.999).tool, undefined);
});
