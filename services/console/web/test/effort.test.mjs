// The Planner's count of a programming session (js/planner/effort.js) without a browser: which typed
// fields are coordinates, the figure the new-product test fails on. Run by ctest (console_web_unit_test).
import assert from 'node:assert/strict';
import { describe, it } from 'node:test';

import { isCoordinateField } from '../js/planner/effort.js';

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
