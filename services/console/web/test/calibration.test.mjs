// The cameras' calibration lines of the Tasks page's cell panel.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { cameraCalibrations } from '../js/calibration.js';

const camera = (attributes) => ({ id: 'camera', kind: 'device', camera: { width: 1280 }, ...(attributes ? { attributes } : {}) });

test('a camera without a record is shown as drawn', () => {
  assert.deepEqual(cameraCalibrations({ entities: [{ id: 'robot', kind: 'device' }, camera()] }),
    [{ id: 'camera', calibrated: false, text: 'Camera camera: as drawn (no calibration recorded)' }]);
});

test('a record says when, for whom, the residuals and the poses', () => {
  const record = { stamp: '2026-11-29T04:44:00Z', requested_by: 'riggerctl:ada', from_revision: 3,
    residual_rms_mm: 0.4123, residual_rms_deg: 0.0312, residual_max_mm: 0.91, residual_max_deg: 0.064,
    poses: [{}, {}, {}, {}, {}, {}, {}, {}, {}], skipped: [{ why: 'unreachable' }] };
  const [line] = cameraCalibrations({ entities: [camera({ calibration: record })] });
  assert.equal(line.calibrated, true);
  assert.equal(line.text, 'Camera camera: calibrated 2026-11-29T04:44:00Z for riggerctl:ada, residual RMS 0.41 mm / 0.031° ' +
    '(largest 0.91 mm / 0.064°), 9 poses, 1 skipped; from cell revision 3');
});

test('a malformed document or record shows nothing false', () => {
  assert.deepEqual(cameraCalibrations(null), []);
  assert.deepEqual(cameraCalibrations({ entities: 'x' }), []);
  const [line] = cameraCalibrations({ entities: [camera({ calibration: { residual_rms_mm: 'a lot' } })] });
  assert.match(line.text, /calibrated \(when unknown\), residual RMS \? mm/);
});
