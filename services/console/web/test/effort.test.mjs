// The Planner's count of a programming session (js/planner/effort.js) without a browser: which typed
// fields are coordinates, the figure the new-product test fails on. Run by ctest (console_web_unit_test).
import assert from 'node:assert/strict';
import { describe, it } from 'node:test';

import { isCoordinateField, isDrag } from '../js/planner/effort.js';

describe('isCoordinateField', () => {
  it('names a position, a point, a pose or one component of one a coordinate', () => {
    for (const name of ['param-position_m', 'param-pose', 'point_m', 'param-standoff_y_m', 'param-standoff_z_m',
      'offset-x', 'rpy_deg', 'param-x', 'goal_z_mm']) assert.equal(isCoordinateField(name), true, name);
  });
  it('leaves distances, limits, names and ids alone', () => {
    for (const name of ['planner-place-offset', 'planner-declare-standoff', 'planner-declare-marker-size',
      'planner-declare-marker-id', 'planner-declare-torque', 'planner-add-name', 'param-max_force_n',
      'param-tolerance_m', 'param-duration_s', 'planner-task-id', 'max_attempts', 'name', '']) {
      assert.equal(isCoordinateField(name), false, name);
    }
  });
});

describe('isDrag', () => {
  it('tells a drag (the 3D view orbited) from a click', () => {
    assert.equal(isDrag([100, 100], { clientX: 100, clientY: 160 }), true);
    assert.equal(isDrag([100, 100], { clientX: 102, clientY: 101 }), false);
    assert.equal(isDrag(null, { clientX: 5, clientY: 5 }), false);
  });
});
