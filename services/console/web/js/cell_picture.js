// Where things are in the cell, as the console sends it (services/console/src/cell_feed.hpp): a picture
// {t, objects: {id: {position_m, quaternion_xyzw}}, tool: [x, y, z], hook: [x, y, z]} (world frame, m)
// and the changes to it. No DOM and no three.js: node's test runner checks these.

/// Applies `change` to `picture` (objects by id; tool, hook and t replaced); returns `picture`.
export function mergeCell(picture, change) {
  for (const [key, value] of Object.entries(change || {})) {
    if (key === 'objects') picture.objects = { ...(picture.objects || {}), ...value };
    else picture[key] = value;
  }
  return picture;
}

/// The picture at time `t` (s since the epoch) from a run's rows (time order, the first the whole
/// picture when the run began): every row at or before `t` merged; empty before the first.
export function cellAt(rows, t) {
  const picture = {};
  for (const row of rows) {
    if (row.t > t) break;
    mergeCell(picture, row);
  }
  return picture;
}
