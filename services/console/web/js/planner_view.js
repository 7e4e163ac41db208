// The planner's 3D view: the cell's objects placed where the world model has them, each
// drawn from its STEP model's tessellation (a box of the world model's size when it has none) (one mesh part per B-rep face, so a picked triangle is a
// face with its stable reference). Faces, holes, straight edges and vertices are picked by clicking;
// hovering highlights what a click would pick. A vertex or an edge is picked within a few pixels of it
// (when no face is in front of it), a hole by clicking one of its faces or its opening (the ray through
// the entry disk). No geometry is derived here: positions come from the CAD service (features, derived
// parameters); this only draws and maps a click to a reference.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { api } from './api.js';

const PART = 0x7d8fa8, HOVER = 0x4fa3ff, PICKED = 0xff9f1c, EDGE = 0x1b2530;
const EDGE_PX = 6, VERTEX_PX = 8;  // how near (screen pixels) a click must be to pick an edge or a vertex
const OCCLUSION_M = 0.002;  // an edge or vertex this far behind the face hit is still on that face

/// One key per pickable thing: "target:hole:2", "target:edge:7", "load:face:5", "target:vertex:0".
export function pickKey(p) {
  const index = { hole: p.hole, edge: p.edge, vertex: p.vertex }[p.kind] ?? p.face;
  return `${p.entity}:${p.kind}:${index}`;
}

/// A cylinder's seam: a straight edge along a hole's or full cylinder's axis at its radius. It bounds
/// no face (the cylinder meets itself there), and seen along the axis it sits at the hole's opening.
function isSeam(edge, features) {
  const axes = [
    ...(features.holes || []).map((h) => ({ point: h.entry_m, dir: h.axis, r: h.diameter_m / 2 })),
    ...(features.faces || []).filter((f) => f.signature?.type === 'cylinder')
      .map((f) => ({ point: f.signature.centroid_m, dir: f.signature.direction, r: f.signature.radius_m })),
  ];
  const d = new THREE.Vector3(...edge.end_m).sub(new THREE.Vector3(...edge.start_m)).normalize();
  return axes.some(({ point, dir, r }) => {
    if (!point || !dir) return false;
    const axis = new THREE.Vector3(...dir).normalize();
    if (d.clone().cross(axis).length() > 1e-6) return false;
    const off = new THREE.Vector3(...edge.start_m).sub(new THREE.Vector3(...point));
    return Math.abs(off.sub(axis.multiplyScalar(off.dot(axis))).length() - r) < 1e-5;
  });
}

/// Sets `object`'s pose from {position_m, quaternion_xyzw} (the world model's) or {position_m, rpy_deg}
/// (the cell file's: R = Rz(yaw) Ry(pitch) Rx(roll)).
export function setPose(object, pose) {
  const p = pose.position_m || [0, 0, 0];
  object.position.set(p[0], p[1], p[2]);
  if (pose.quaternion_xyzw) {
    object.quaternion.set(...pose.quaternion_xyzw);
  } else {
    const rpy = (pose.rpy_deg || [0, 0, 0]).map((d) => THREE.MathUtils.degToRad(d));
    object.rotation.set(rpy[0], rpy[1], rpy[2], 'ZYX');
  }
}

export class PartsView {
  constructor(container, onPick) {
    this.container = container;
    this.onPick = onPick;
    this.parts = new Map();  // entity -> { group, meshes: [{mesh, face}], features, parts, sha256 }
    this.picked = new Set();  // "entity:face" keys drawn as picked
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(1);
    container.append(this.renderer.domElement);
    this.renderer.domElement.setAttribute('aria-label', '3D view of the cell\'s parts: click a face or a hole to pick it');
    this.renderer.domElement.setAttribute('role', 'img');
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x0f1720);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 50);
    this.camera.up.set(0, 0, 1);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x334455, 2.0));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(1, -1.5, 2);
    this.scene.add(sun);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    this.raycaster = new THREE.Raycaster();
    this.hovered = null;
    // While set and active, hover and click go to it instead ({active, hover(x, y), click(x, y)}: the
    // feature picker's markers).
    this.overlay = null;
    const canvas = this.renderer.domElement;
    let down = null;
    canvas.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
    canvas.addEventListener('pointermove', (e) => this.hover(e));
    canvas.addEventListener('pointerleave', () => this.hover(null));
    canvas.addEventListener('click', (e) => {
      // A drag orbits; only a click that did not move picks.
      if (down && Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
      if (this.overlay?.active) return this.overlay.click(e.clientX, e.clientY);
      const pick = this.pickAt(e.clientX, e.clientY);
      if (pick) this.onPick(pick);
    });
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  resize() {
    const w = this.container.clientWidth || 600, h = this.container.clientHeight || 420;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }
  render() { this.renderer.render(this.scene, this.camera); }

  /// Loads `entity` (a cell object): pose from the world model (`world`, its description, when the
  /// caller has it), tessellation, parts and features from CAD; without a CAD model, a box of the world
  /// model's size, which a click picks as the whole object ({entity, kind: 'object'}).
  /// `model`: another CAD model than the entity's own (an imported file's `sha256:<hex>`, drawn at
  /// `world.pose` before it is a cell object).
  async load(entity, world = null, model = `object:${entity}`) {
    const q = `model=${encodeURIComponent(model)}`;
    world = world || await api(`/api/world/entity/${encodeURIComponent(entity)}`);
    let glb, parts, features;
    try {
      [glb, parts, features] = await Promise.all([
        api(`/api/cad/model.glb?${q}`, { raw: true }).then((r) => r.arrayBuffer()),
        api(`/api/cad/parts?${q}`),
        api(`/api/cad/features?${q}`),
      ]);
    } catch (e) {
      if (!world.model?.size_m) throw e;
      return this.loadBox(entity, world);
    }
    const gltf = await new GLTFLoader().parseAsync(glb, '');
    const group = this.placed(world);
    group.add(gltf.scene);
    const faceOfPrimitive = new Map(parts.parts.map((x) => [x.primitive, x]));
    const meshes = [];
    // The straight edges (the paper's frame rule uses two of them) and the vertices, in the model frame.
    const edges = [], vertices = [];
    for (const e of features.edges || []) {
      if (e.signature?.type !== 'line' || !e.start_m || !e.end_m || isSeam(e, features)) continue;
      const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(...e.start_m), new THREE.Vector3(...e.end_m)]),
        new THREE.LineBasicMaterial({ color: EDGE }));
      group.add(line);
      edges.push({ edge: e, line });
    }
    // Only corners of straight edges: a hole's rim has a seam vertex next to the hole's opening.
    const corner = (pt) => edges.some(({ edge }) => [edge.start_m, edge.end_m].some((q) => Math.hypot(q[0] - pt[0], q[1] - pt[1], q[2] - pt[2]) < 1e-7));
    for (const v of features.vertices || []) {
      if (!v.point_m || !corner(v.point_m)) continue;
      const dot = new THREE.Mesh(new THREE.SphereGeometry(0.0025, 8, 6), new THREE.MeshBasicMaterial({ color: EDGE }));
      dot.position.set(...v.point_m);
      dot.visible = false;  // drawn when hovered or picked
      group.add(dot);
      vertices.push({ vertex: v, dot });
    }
    gltf.scene.traverse((o) => {
      if (!o.isMesh) return;
      const a = gltf.parser.associations.get(o);
      const part = a && faceOfPrimitive.get(a.primitives);
      if (!part) return;
      o.material = new THREE.MeshStandardMaterial({ color: PART, roughness: 0.7, metalness: 0.1, side: THREE.DoubleSide });
      o.userData = { entity, face: part.face, ref: part.ref };
      meshes.push({ mesh: o, face: part.face });
    });
    this.scene.add(group);
    group.updateMatrixWorld(true);
    this.parts.set(entity, { group, meshes, edges, vertices, features, parts: parts.parts, sha256: features.model_sha256, world });
    this.render();
    return this.parts.get(entity);
  }

  /// A group at the world model's pose of an object.
  placed(world) {
    const group = new THREE.Group();
    setPose(group, world.pose || world.world_pose || {});
    return group;
  }

  /// Moves the loaded part `entity` to `pose` ({position_m, quaternion_xyzw | rpy_deg}, world frame).
  place(entity, pose) {
    const part = this.parts.get(entity);
    if (!part) return;
    setPose(part.group, pose);
    part.group.updateMatrixWorld(true);
  }

  /// An object without a CAD model: a box of its model size (frame at the box's centre, or at the centre
  /// of its top face when the model says so).
  loadBox(entity, world) {
    const [x, y, z] = world.model.size_m;
    const group = this.placed(world);
    const mesh = new THREE.Mesh(new THREE.BoxGeometry(x, y, z),
      new THREE.MeshStandardMaterial({ color: PART, roughness: 0.8, metalness: 0.05, transparent: true, opacity: 0.85 }));
    if (/top/.test(world.model.frame || '')) mesh.position.z = -z / 2;
    mesh.userData = { entity, box: true };
    group.add(mesh);
    this.scene.add(group);
    group.updateMatrixWorld(true);
    const none = { holes: [], faces: [], edges: [], vertices: [] };
    this.parts.set(entity, { group, meshes: [{ mesh, face: -1 }], edges: [], vertices: [], features: none, parts: [], sha256: '', world, box: true });
    this.render();
    return this.parts.get(entity);
  }

  /// Takes every part out of the view (a new revision of the cell is drawn afresh).
  clear() {
    for (const part of this.parts.values()) this.scene.remove(part.group);
    this.parts.clear();
    this.render();
  }

  /// Shows or hides a part; a hidden part is not picked.
  setVisible(entity, visible) {
    const part = this.parts.get(entity);
    if (!part) return;
    part.group.visible = visible;
    this.render();
  }

  /// The parts shown, as [entity, part] pairs.
  shown() { return [...this.parts].filter(([, part]) => part.group.visible); }
  /// The parts a click may pick: shown and not drawn as a ghost.
  pickable() { return this.shown().filter(([, part]) => !part.ghost); }

  /// Draws `entity` faint and out of the picks (`ghost`), or as a part again.
  setGhost(entity, ghost) {
    const part = this.parts.get(entity);
    if (!part) return;
    part.ghost = ghost;
    for (const { mesh } of part.meshes) Object.assign(mesh.material, { transparent: ghost, opacity: ghost ? 0.18 : 1, depthWrite: !ghost });
    for (const { line } of part.edges) Object.assign(line.material, { transparent: ghost, opacity: ghost ? 0.25 : 1 });
    this.paint();
  }

  /// Draws `entity`'s faces in `color` (a hex number; null: the parts' colour).
  setColor(entity, color) {
    const part = this.parts.get(entity);
    if (part) part.color = color;
    this.paint();
  }

  /// Gives the loaded part `from` the id `to` (what a click on it picks).
  rename(from, to) {
    const part = this.parts.get(from);
    if (!part) return;
    this.parts.delete(from);
    for (const { mesh } of part.meshes) mesh.userData.entity = to;
    this.parts.set(to, part);
  }

  /// Takes the loaded part `entity` out of the view.
  remove(entity) {
    const part = this.parts.get(entity);
    if (!part) return;
    this.scene.remove(part.group);
    this.parts.delete(entity);
    this.render();
  }

  /// The world pose ({position_m, quaternion_xyzw}) of a frame given in `entity`'s frame as the CAD
  /// service gives frames ({position_m, rotation: rows}).
  worldPoseOf(entity, frame) {
    const part = this.parts.get(entity);
    const r = frame.rotation, p = frame.position_m;
    const local = new THREE.Matrix4().set(r[0][0], r[0][1], r[0][2], p[0], r[1][0], r[1][1], r[1][2], p[1],
      r[2][0], r[2][1], r[2][2], p[2], 0, 0, 0, 1);
    part.group.updateMatrixWorld(true);
    const position = new THREE.Vector3(), q = new THREE.Quaternion();
    part.group.matrixWorld.clone().multiply(local).decompose(position, q, new THREE.Vector3());
    return { position_m: position.toArray(), quaternion_xyzw: [q.x, q.y, q.z, q.w] };
  }

  /// Puts the camera above `entity`, looking down at its top.
  frame(entity) {
    const part = this.parts.get(entity);
    if (part) this.frameBox(new THREE.Box3().setFromObject(part.group));
  }

  /// Frames every part shown.
  frameAll() {
    const box = new THREE.Box3();
    for (const [, part] of this.shown()) box.expandByObject(part.group);
    if (!box.isEmpty()) this.frameBox(box);
  }

  frameBox(box) {
    const c = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3()).length();
    const look = new THREE.Vector3(c.x, c.y, box.max.z);
    this.camera.position.copy(look).add(new THREE.Vector3(0.25 * size, 0.55 * size, 0.9 * size));
    this.controls.target.copy(look);
    this.controls.update();
    this.render();
  }

  /// The hole of `entity` whose faces include `face`, or null.
  holeOfFace(entity, face) {
    const part = this.parts.get(entity);
    return part?.features.holes.find((h) => h.faces.includes(face)) || null;
  }

  /// What a click at client coordinates (x, y) picks: {entity, kind: "vertex"|"edge"|"face"|"hole",
  /// ref, …}: a vertex or straight edge within a few pixels, else a hole, else a face (with the point hit).
  pickAt(x, y) {
    const r = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((x - r.left) / r.width) * 2 - 1, -((y - r.top) / r.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    const ray = this.raycaster.ray;
    const meshes = this.pickable().flatMap(([, p]) => p.meshes.map((m) => m.mesh));
    const hit = this.raycaster.intersectObjects(meshes, false)[0] || null;
    const fine = this.pickFine(x, y, hit);
    if (fine) return fine;
    // The opening of a hole: the ray crosses its entry disk before it hits anything else.
    let best = null;
    for (const [entity, part] of this.pickable()) {
      for (const h of part.features.holes) {
        const entry = new THREE.Vector3(...h.entry_m).applyMatrix4(part.group.matrixWorld);
        const axis = new THREE.Vector3(...h.axis).transformDirection(part.group.matrixWorld);
        const t = ray.intersectPlane(new THREE.Plane().setFromNormalAndCoplanarPoint(axis, entry), new THREE.Vector3());
        if (!t) continue;
        const d = ray.origin.distanceTo(t);
        if (t.distanceTo(entry) <= h.diameter_m / 2 && (!hit || d <= hit.distance + 1e-4) && (!best || d < best.d)) best = { d, entity, hole: h };
      }
    }
    if (best) return this.describe(best.entity, best.hole.faces[0], best.hole);
    if (!hit) return null;
    if (hit.object.userData.box) return { entity: hit.object.userData.entity, kind: 'object' };
    const { entity, face } = hit.object.userData;
    const pick = this.describe(entity, face, this.holeOfFace(entity, face));
    if (pick.kind === 'face') {
      const local = hit.point.clone().applyMatrix4(this.parts.get(entity).group.matrixWorld.clone().invert());
      // To 0.1 mm: a click is not finer than that, and the same clicks then give the same bytes (the ray
      // through a pixel moves by nanometres with the view's orbit). The CAD service projects the point
      // onto the face.
      pick.point_m = [local.x, local.y, local.z].map((v) => Math.round(v * 1e4) / 1e4);
    }
    return pick;
  }

  /// The vertex (within VERTEX_PX) or straight edge (within EDGE_PX) nearest the click on the screen,
  /// unless a face hit lies in front of it. pickAt has set the raycaster for (x, y).
  pickFine(x, y, hit) {
    const visible = (world) => !hit || this.camera.position.distanceTo(world) <= hit.distance + OCCLUSION_M;
    const screen = (world) => {
      const v = world.clone().project(this.camera);
      const r = this.renderer.domElement.getBoundingClientRect();
      return new THREE.Vector2(r.left + (v.x + 1) / 2 * r.width, r.top + (1 - v.y) / 2 * r.height);
    };
    const click = new THREE.Vector2(x, y);
    let best = null;
    for (const [entity, part] of this.pickable()) {
      const m = part.group.matrixWorld;
      for (const { vertex } of part.vertices) {
        const w = new THREE.Vector3(...vertex.point_m).applyMatrix4(m);
        const d = screen(w).distanceTo(click);
        if (d <= VERTEX_PX && visible(w) && (!best || best.kind !== 'vertex' || d < best.d)) best = { d, kind: 'vertex', entity, vertex };
      }
      if (best?.kind === 'vertex') continue;
      for (const { edge } of part.edges) {
        const a = new THREE.Vector3(...edge.start_m).applyMatrix4(m), b = new THREE.Vector3(...edge.end_m).applyMatrix4(m);
        // The edge's point nearest the click's ray, in 3D (a lerp on the screen is not the same point
        // under perspective, and its depth would be off by centimetres on an oblique edge).
        const onEdge = new THREE.Vector3();
        this.raycaster.ray.distanceSqToSegment(a, b, undefined, onEdge);
        const d = screen(onEdge).distanceTo(click);
        if (d <= EDGE_PX && visible(onEdge) && (!best || d < best.d)) best = { d, kind: 'edge', entity, edge };
      }
    }
    if (!best) return null;
    const part = this.parts.get(best.entity);
    if (best.kind === 'vertex') {
      const v = best.vertex;
      return { entity: best.entity, kind: 'vertex', vertex: v.index, point_m: v.point_m,
        ref: { model_sha256: part.sha256, kind: 'vertex', index: v.index, signature: v.signature || { type: 'vertex', point_m: v.point_m } } };
    }
    const e = best.edge;
    return { entity: best.entity, kind: 'edge', edge: e.index, start_m: e.start_m, end_m: e.end_m,
      ref: { model_sha256: part.sha256, kind: 'edge', index: e.index, signature: e.signature } };
  }

  describe(entity, face, hole) {
    const part = this.parts.get(entity);
    // A face without triangles has no part: its reference from the features then.
    const ref = part.parts.find((x) => x.face === face)?.ref || { model_sha256: part.sha256, kind: 'face', index: face,
      signature: part.features.faces?.find((f) => f.index === face)?.signature || {} };
    return hole ? { entity, kind: 'hole', face, hole: hole.index, ref, diameter_m: hole.diameter_m, entry_m: hole.entry_m }
      : { entity, kind: 'face', face, ref };
  }

  hover(e) {
    if (this.overlay?.active) return this.overlay.hover(e ? e.clientX : null, e ? e.clientY : null);
    const pick = e ? this.pickAt(e.clientX, e.clientY) : null;
    const key = pick ? pickKey(pick) : null;
    if (key === this.hovered) return;
    this.hovered = key;
    this.hoveredPick = pick;
    this.paint();
  }

  /// Marks the picks (list of picks as from pickAt) and the hovered one.
  setPicked(picks) {
    this.picked = new Set();
    this.pickedFine = new Set(picks.filter((p) => p.kind === 'edge' || p.kind === 'vertex').map(pickKey));
    for (const p of picks) for (const f of this.facesOf(p)) this.picked.add(`${p.entity}:${f}`);
    this.paint();
  }
  facesOf(p) {
    if (p.kind === 'edge' || p.kind === 'vertex') return [];
    if (p.kind === 'object') return [-1];  // a box: the whole part
    if (p.kind !== 'hole') return [p.face];
    return this.parts.get(p.entity)?.features.holes[p.hole]?.faces || [p.face];
  }
  paint() {
    const hovered = new Set(this.hoveredPick ? this.facesOf(this.hoveredPick).map((f) => `${this.hoveredPick.entity}:${f}`) : []);
    for (const [entity, part] of this.parts) {
      for (const { mesh, face } of part.meshes) {
        const key = `${entity}:${face}`;
        mesh.material.color.setHex(hovered.has(key) ? HOVER : this.picked.has(key) ? PICKED : part.color ?? PART);
        mesh.material.emissive.setHex(hovered.has(key) ? 0x103050 : 0x000000);
      }
      const fine = (kind, index) => {
        const key = `${entity}:${kind}:${index}`;
        return key === this.hovered ? HOVER : this.pickedFine?.has(key) ? PICKED : null;
      };
      for (const { edge, line } of part.edges) line.material.color.setHex(fine('edge', edge.index) ?? EDGE);
      for (const { vertex, dot } of part.vertices) {
        const c = fine('vertex', vertex.index);
        dot.visible = c !== null;
        if (c !== null) dot.material.color.setHex(c);
      }
    }
    this.render();
  }

  /// Client (page) coordinates of a point given in `entity`'s model frame (for tests and labels).
  screenOf(entity, point) {
    const part = this.parts.get(entity);
    const v = new THREE.Vector3(...point).applyMatrix4(part.group.matrixWorld).project(this.camera);
    const r = this.renderer.domElement.getBoundingClientRect();
    return { x: r.left + (v.x + 1) / 2 * r.width, y: r.top + (1 - v.y) / 2 * r.height };
  }
}
