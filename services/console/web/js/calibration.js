// The cameras' calibration as the cell document records it: the CalibrateCamera skill writes each
// camera's solved pose with a record in its `attributes.calibration` (docs/real-cell.md, "Calibrating the
// camera"). Pure: the Tasks page's cell panel shows these lines.

/// One line per camera of the cell document `doc`: {id, calibrated, text}.
export function cameraCalibrations(doc) {
  const entities = Array.isArray(doc?.entities) ? doc.entities : [];
  const cameras = entities.filter((e) => e && typeof e === 'object' && e.camera);
  return cameras.map((e) => {
    const c = e.attributes?.calibration;
    if (!c || typeof c !== 'object') return { id: e.id, calibrated: false, text: `Camera ${e.id}: as drawn (no calibration recorded)` };
    const n = (x, digits) => (Number.isFinite(x) ? x.toFixed(digits) : '?');
    const used = Array.isArray(c.poses) ? c.poses.length : 0;
    const skipped = Array.isArray(c.skipped) ? c.skipped.length : 0;
    const text = `Camera ${e.id}: calibrated ${c.stamp || '(when unknown)'}` +
      (c.requested_by ? ` for ${c.requested_by}` : '') +
      `, residual RMS ${n(c.residual_rms_mm, 2)} mm / ${n(c.residual_rms_deg, 3)}°` +
      ` (largest ${n(c.residual_max_mm, 2)} mm / ${n(c.residual_max_deg, 3)}°)` +
      `, ${used} pose${used === 1 ? '' : 's'}${skipped ? `, ${skipped} skipped` : ''}` +
      (c.from_revision !== undefined ? `; from cell revision ${c.from_revision}` : '');
    return { id: e.id, calibrated: true, text };
  });
}
