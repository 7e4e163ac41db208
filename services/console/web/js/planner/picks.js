// What picks on the CAD model make (no DOM): the CAD service's frame rules a pose parameter is bound by.

/// The frame rules of a pose binding (docs/console.md, "Poses from picks").
export const FRAME_RULES = ['edges', 'face', 'hole'];

/// The CAD frame rule the picks make, as the request's fields (POST /api/planner/frame) with a
/// `summary` for the button, or {error} saying what to pick.
export function frameFromPicks(picks) {
  const of = (kind) => picks.filter((p) => p.kind === kind);
  const [edges, faces, holes, vertices] = ['edge', 'face', 'hole', 'vertex'].map(of);
  if (!picks.length) return { error: 'pick a point (a vertex or a face) and two perpendicular edges, or a face, or a hole' };
  const entities = new Set(picks.map((p) => p.entity));
  if (entities.size !== 1) return { error: `the picks are on ${[...entities].join(' and ')}: pick on one part` };
  const model = `object:${picks[0].entity}`;
  if (edges.length === 2 && vertices.length + faces.length === 1 && picks.length === 3) {
    const point = vertices[0] || faces[0];
    return { model, rule: 'edges', point_m: point.point_m, edges: edges.map((e) => e.ref),
      summary: `a point (${point.kind} ${point.kind === 'vertex' ? point.vertex : point.face}) and edges ${edges[0].edge}, ${edges[1].edge}` };
  }
  if (holes.length === 1 && picks.length === 1) return { model, rule: 'hole', hole: holes[0].hole, summary: `hole ${holes[0].hole}` };
  if (faces.length === 1 && picks.length === 1) return { model, rule: 'face', face: faces[0].ref, point_m: faces[0].point_m, summary: `face ${faces[0].face} at the picked point` };
  return { error: `${picks.length} picks (${picks.map((p) => p.kind).join(', ')}): pick a point (a vertex or a face) and two perpendicular edges, or one face, or one hole` };
}

/// The placement two face picks make (POST /api/planner/place): the first pick's part, that face at the
/// picked point, laid on the second pick's face at its point (normals opposite), as the request's fields
/// with a `summary`; or {error} saying what to pick.
export function placeFromPicks(picks) {
  const what = 'pick a face of the part to place, then the face to place it on (of another part); an edge of each to line them up';
  if (picks.some((p) => p.entity === 'imported')) return { error: 'to place: the imported file is not a part of the cell yet' };
  const faces = picks.filter((p) => p.kind === 'face'), edges = picks.filter((p) => p.kind === 'edge');
  if (faces.length !== 2 || faces.length + edges.length !== picks.length) return { error: `to place: ${what}` };
  const [own, onto] = faces;
  if (own.entity === onto.entity) return { error: `to place: both faces are of ${own.entity}; ${what}` };
  const edgeOf = (entity) => edges.filter((e) => e.entity === entity);
  if (edges.length && (edges.length !== 2 || edgeOf(own.entity).length !== 1 || edgeOf(onto.entity).length !== 1))
    return { error: `to place: pick one edge of ${own.entity} and one of ${onto.entity} to line them up, or none` };
  const request = {
    model: `object:${own.entity}`, face: own.ref, point_m: own.point_m,
    onto: { model: `object:${onto.entity}`, face: onto.ref, point_m: onto.point_m },
    summary: `${own.entity} (face ${own.face}) on ${onto.entity} (face ${onto.face})`,
  };
  if (edges.length) {
    request.edge = edgeOf(own.entity)[0].edge;
    request.onto.edge = edgeOf(onto.entity)[0].edge;
    request.summary += `, edge ${request.edge} along edge ${request.onto.edge}`;
  }
  return request;
}

/// The features the Planner declares by picks (POST /api/planner/declare; docs/console.md, "Declare a feature").
export const DECLARE_KINDS = ['grasp_frame', 'approach_waypoint', 'screw_holes', 'insertion', 'rope_attachment', 'marker'];

/// The declare request the picks and the panel's fields make ({kind, name, standoff_m, like, screw_type,
/// torque_nm}), or {error} saying what to pick or fill in. The console builds the rule from the CAD
/// service's references of the picked indices; nothing here is a coordinate.
export function declareFromPicks(picks, fields) {
  const { kind, name } = fields;
  if (!DECLARE_KINDS.includes(kind)) return { error: `choose what to declare: ${DECLARE_KINDS.join(', ')}` };
  if (kind === 'insertion') {
    // The part's face first, then the face of the part it goes into; then, to pin them, a hole of each
    // (one or two pairs, paired in the order picked).
    const faces = picks.filter((p) => p.kind === 'face'), holes = picks.filter((p) => p.kind === 'hole');
    if (faces.length !== 2 || faces.length + holes.length !== picks.length || faces[0].entity === faces[1].entity)
      return { error: 'pick the face of the part that mates, then the face of the part it goes into (and a hole of each to pin them)' };
    const [own, onto] = faces;
    const ownHoles = holes.filter((h) => h.entity === own.entity), ontoHoles = holes.filter((h) => h.entity === onto.entity);
    if (ownHoles.length + ontoHoles.length !== holes.length || ownHoles.length !== ontoHoles.length || holes.length > 4)
      return { error: `to pin the insertion: pick one or two holes of ${own.entity} and as many of ${onto.entity}, in pairs` };
    const request = { model: `object:${own.entity}`, kind, face: own.face, target: { model: `object:${onto.entity}`, face: onto.face } };
    if (holes.length) request.pins = ownHoles.map((h, i) => ({ hole: h.hole, target_hole: ontoHoles[i].hole }));
    return request;
  }
  if (kind === 'rope_attachment' || kind === 'marker') {
    const [p] = picks;
    const model = p ? `object:${p.entity}` : '';
    // A sling above the part's centre of mass: any pick says which part.
    if (kind === 'rope_attachment' && fields.sling) {
      if (picks.length !== 1) return { error: 'pick the part the sling goes round (any face of it)' };
      return { model, kind, above_centre_of_mass: true };
    }
    if (kind === 'rope_attachment' && picks.length === 1 && p.kind === 'hole') return { model, kind, hole: p.hole };
    if (picks.length !== 1 || p.kind !== 'face')
      return { error: kind === 'marker' ? 'pick the point on a face where the marker goes' : 'pick a hole, or the point on a face where the rope hooks' };
    if (kind === 'rope_attachment') return { model, kind, face: p.face, point_m: p.point_m };
    const id = Number(fields.marker_id), size = Number(fields.marker_size_mm) / 1000;
    if (!fields.dictionary || !Number.isInteger(id) || fields.marker_id === '' || !(size > 0))
      return { error: 'give the marker\'s dictionary, id and size (mm)' };
    return { model, kind, face: p.face, point_m: p.point_m, dictionary: fields.dictionary, marker_id: id, size_m: size };
  }
  if (!/^[A-Za-z0-9_-]{1,64}$/.test(name || '')) return { error: 'give it a name of letters, digits, _ or -' };
  const entities = new Set(picks.map((p) => p.entity));
  if (entities.size > 1) return { error: `the picks are on ${[...entities].join(' and ')}: pick on one part` };
  const of = (k) => picks.filter((p) => p.kind === k);
  const model = picks.length ? `object:${picks[0].entity}` : '';
  if (kind === 'screw_holes') {
    const holes = of('hole');
    if (holes.length !== 1 || picks.length !== 1) return { error: 'pick one hole (and tick "all like this one" for its pattern)' };
    const torque = Number(fields.torque_nm);
    if (!fields.screw_type || !(torque > 0)) return { error: 'give the screw type and its torque (N·m, > 0)' };
    return { model, kind, name, hole: holes[0].hole, like: Boolean(fields.like),
      screw: { screw_type: fields.screw_type, torque_nm: torque } };
  }
  const faces = of('face'), edges = of('edge');
  if (faces.length !== 1 || edges.length > 1 || picks.length !== faces.length + edges.length)
    return { error: 'pick one face, and a straight edge of it for x if you like' };
  const request = { model, kind, name, face: faces[0].face };
  if (edges.length) Object.assign(request, { x_edge: edges[0].edge, x_reversed: Boolean(fields.x_reversed) });
  if (kind === 'approach_waypoint') {
    const standoff = Number(fields.standoff_mm) / 1000;
    if (!(standoff > 0)) return { error: 'give the stand-off out of the face (mm, > 0)' };
    request.standoff_m = standoff;
  }
  return request;
}
