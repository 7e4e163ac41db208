// What the "Declare a feature" panel proposes, from the running cell document and the picks: a name
// the picked part does not use yet, and a marker id no object carries. The console refuses a taken name
// or id (POST /api/planner/declare); a proposal saves typing one that it would accept.

/// The ids of `entity`'s features in `doc` (every list under its "features"), as the console counts them
/// when it refuses a taken name.
export function featureIds(doc, entity) {
  const e = (doc?.entities || []).find((x) => x?.id === entity);
  const ids = new Set();
  for (const list of Object.values(e?.features || {}))
    if (Array.isArray(list)) for (const f of list) if (typeof f?.id === 'string') ids.add(f.id);
  return ids;
}

/// The marker ids of every object in `doc`, and of a robot's calibration board (whatever their
/// dictionary: the console refuses an id that is on an object already, since the tracker tells objects
/// apart by their ids).
export function markerIds(doc) {
  const ids = new Set();
  for (const e of doc?.entities || [])
    for (const m of [...(e?.features?.markers?.items || []), ...(e?.calibration_board?.markers?.items || [])])
      if (Number.isInteger(m?.id)) ids.add(m.id);
  return ids;
}

/// How many markers `dictionary` has ("DICT_4X4_50" → 50), or 0 when the name does not say.
export function dictionarySize(dictionary) {
  const m = /_(\d+)$/.exec(dictionary || '');
  return m ? Number(m[1]) : 0;
}

/// The lowest id of `dictionary` no object of `doc` carries, or '' when every id is taken.
export function freeMarkerId(doc, dictionary) {
  const used = markerIds(doc);
  for (let id = 0; id < dictionarySize(dictionary); ++id) if (!used.has(id)) return id;
  return '';
}

/// `base` when `taken` lacks it, else base2, base3, …
export function freeName(base, taken) {
  if (!taken.has(base)) return base;
  for (let i = 2; ; ++i) if (!taken.has(`${base}${i}`)) return `${base}${i}`;
}

/// The first of a, b, …, z (a hole pattern's prefix, as drawings letter their hole groups) that names
/// none of `taken` followed by digits; '' when all are used.
export function freePrefix(taken) {
  for (let c = 97; c <= 122; ++c) {
    const p = String.fromCharCode(c);
    if (![...taken].some((id) => new RegExp(`^${p}\\d+$`).test(id))) return p;
  }
  return '';
}

// The names a frame is proposed by (the shipped cell's).
const FRAME_NAMES = { grasp_frame: 'grasp', approach_waypoint: 'pre_grasp' };

/// The panel's proposals for declaring `kind` on the part of the first pick (the cell's names when
/// nothing is picked yet): { name, marker_id } where they apply.
export function proposals(doc, picks, kind, dictionary) {
  const taken = featureIds(doc, picks[0]?.entity);
  if (FRAME_NAMES[kind]) return { name: freeName(FRAME_NAMES[kind], taken) };
  if (kind === 'screw_holes') return { name: freePrefix(taken) };
  if (kind === 'marker') return { marker_id: freeMarkerId(doc, dictionary) };
  return {};
}
