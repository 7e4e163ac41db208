// Feature picks (the planner, docs/console.md): a feature_ref parameter (AttachRobotToLoad's grasp and approach, Pick's
// grasp) is chosen from the named features the world model knows of the cell's parts — grasp frames,
// approach waypoints, screw holes, the rope attachment — which it derived at start-up from the STEP
// models by the cell file's references and signatures (docs/world-model.md, "CAD rules"). A field's
// "Pick a feature" opens a list of them (buttons, one per feature) and shows each as axes with its name
// in the 3D view (x red, y green, z blue, drawn over the parts); hovering either highlights it in both,
// clicking either fills the field with "object/feature" and keeps where it came from as the parameter's
// binding: {"rule": "feature", "feature", "kind", "pose" (the world model's, in the object's frame)}.
// No pose is computed here: the world model's are drawn and recorded. See docs/console.md, "Planner".
import * as THREE from 'three';
import { api, el } from './api.js';

const MARK = 0xffd166, HOVER = 0x4fa3ff, CHOSEN = 0xff9f1c;
const AXIS_M = 0.05;
const PICK_PX = 14;  // how near (screen pixels) a click must be to a feature's origin to pick it
// Features a feature_ref resolves (the world model's feature_pose_of): the list key and what it is.
const KINDS = [['grasp_frames', 'grasp frame'], ['approach_waypoints', 'approach waypoint'], ['screw_holes', 'screw hole']];
const MOVED_M = 1e-3, TURNED_DEG = 0.1;  // a binding farther from the world model's feature is stale

function rotationOf(pose) {
  const [r, p, y] = (pose.rpy_deg || [0, 0, 0]).map((a) => THREE.MathUtils.degToRad(a));
  return new THREE.Quaternion().setFromEuler(new THREE.Euler(r, p, y, 'ZYX'));  // R = Rz Ry Rx
}

/// The features of a world-model entity a feature_ref can name: [{ref, entity, id, kind, label, pose}].
export function namedFeatures(entity, world) {
  const f = world?.features || {};
  const out = [];
  for (const [key, label] of KINDS) {
    for (const x of f[key] || []) out.push({ ref: `${entity}/${x.id}`, entity, id: x.id, kind: key, label, pose: x.pose });
  }
  if (f.rope_attachment) {
    out.push({ ref: `${entity}/rope_attachment`, entity, id: 'rope_attachment', kind: 'rope_attachment', label: 'rope attachment', pose: f.rope_attachment });
  }
  return out;
}

/// Why a feature binding no longer matches the world model's feature, or '' when it does.
export function staleFeature(binding, features) {
  const now = features.find((x) => x.ref === binding.feature);
  if (!now) return `stale binding: the world model has no feature ${binding.feature}; pick again`;
  const d = Math.hypot(...now.pose.position_m.map((v, i) => v - binding.pose.position_m[i]));
  const a = THREE.MathUtils.radToDeg(rotationOf(now.pose).angleTo(rotationOf(binding.pose)));
  if (d > MOVED_M || a > TURNED_DEG) {
    return `stale binding: ${binding.feature} moved by ${(d * 1000).toFixed(2)} mm and ${a.toFixed(3)}° since it was picked; pick again`;
  }
  return '';
}

/// Millimetres for the list, without "-0.0".
const mm = (v) => (Math.abs(v) < 5e-5 ? 0 : v * 1000).toFixed(1);
/// Nanometres and micro-degrees: the world model's 1e-18 noise (and -0) stays out of the recipe text.
const tidy = (v, scale) => { const r = Math.round(v * scale) / scale; return r === 0 ? 0 : r; };

function label(text) {
  const font = 'bold 30px sans-serif';
  const c = document.createElement('canvas');
  const g0 = c.getContext('2d');
  g0.font = font;
  c.width = Math.ceil(g0.measureText(text).width) + 16; c.height = 48;
  const g = c.getContext('2d');  // resizing the canvas reset its state
  g.fillStyle = 'rgba(15,23,32,0.75)'; g.fillRect(0, 0, c.width, 48);
  g.fillStyle = '#ffffff'; g.font = font; g.textBaseline = 'middle';
  g.fillText(text, 8, 25);
  const s = new THREE.Sprite(new THREE.SpriteMaterial({ map: new THREE.CanvasTexture(c), depthTest: false }));
  s.scale.set(0.0225 * c.width / 48, 0.0225, 1);
  s.center.set(0, -0.4);
  s.renderOrder = 11;
  return s;
}

/// The picker: the features of the parts, their markers in a PartsView (as its overlay: while a picker
/// is open, the view's hover and click go to the markers), and one open list at a time.
export class FeaturePicker {
  /// `onChoose(node, param, feature)` fills the parameter (the page's edit, with its undo step).
  constructor(view, onChoose) {
    this.view = view;
    this.onChoose = onChoose;
    this.features = [];
    this.markers = new Map();  // ref -> { group, dot, entity }
    this.open = null;  // { pointer, param, node } of the field whose list is shown
    this.hovered = '';
    this.list = null;
    this.shown = new Set();  // the features the selected node's fields name: drawn while no list is open
    view.overlay = this;
  }

  get active() { return Boolean(this.open && this.list?.isConnected); }

  /// Draws the named features of `objects` ([{id, world}]: each with the world model's description) as
  /// markers on the parts the view has loaded. `problem`: what the world model did not answer (said in
  /// the list when there is no feature).
  load(objects, problem = '') {
    this.features = objects.flatMap(({ id, world }) => namedFeatures(id, world));
    for (const f of this.features) {
      const part = this.view.parts.get(f.entity);
      if (!part) continue;
      const g = new THREE.Group();
      g.position.set(...f.pose.position_m);
      g.quaternion.copy(rotationOf(f.pose));
      const material = (color) => new THREE.LineBasicMaterial({ color, depthTest: false });
      [[1, 0, 0, 0xe63946], [0, 1, 0, 0x2a9d4b], [0, 0, 1, 0x3a86ff]].forEach(([x, y, z, color]) => {
        const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3(x, y, z).multiplyScalar(AXIS_M)]), material(color));
        line.renderOrder = 10;
        g.add(line);
      });
      const dot = new THREE.Mesh(new THREE.SphereGeometry(0.006, 12, 8), new THREE.MeshBasicMaterial({ color: MARK, depthTest: false }));
      dot.renderOrder = 10;
      g.add(dot, label(f.id));
      g.visible = false;
      part.group.add(g);
      this.markers.set(f.ref, { group: g, dot, entity: f.entity });
    }
    this.problem = problem;
  }

  /// Page coordinates of a feature's origin in the 3D view (tests click there, as a person would).
  screenOf(ref) {
    const f = this.features.find((x) => x.ref === ref);
    return f && this.view.parts.has(f.entity) ? this.view.screenOf(f.entity, f.pose.position_m) : null;
  }

  /// The feature whose marker is nearest (x, y) on the screen, within PICK_PX; markers are drawn over
  /// the parts, so none hides another.
  pickAt(x, y) {
    let best = null;
    for (const f of this.features) {
      const q = this.screenOf(f.ref);
      const d = q ? Math.hypot(q.x - x, q.y - y) : Infinity;
      if (d <= PICK_PX && (!best || d < best.d)) best = { d, f };
    }
    return best?.f || null;
  }
  /// The view's pointer, while a list is open.
  hover(x, y) { this.setHovered(x === null ? '' : this.pickAt(x, y)?.ref || ''); }
  click(x, y) {
    const f = this.pickAt(x, y);
    if (f) this.choose(f);
  }
  setHovered(ref) {
    if (ref === this.hovered) return;
    this.hovered = ref;
    for (const b of this.list?.querySelectorAll('button[data-feature]') || []) b.classList.toggle('hovered', b.dataset.feature === ref);
    this.paint();
  }
  choose(f) {
    const { node, param } = this.open;
    this.close();
    this.onChoose(node, param, f);
  }

  /// Every marker while a list is open, else those the selected node names; the hovered one and the
  /// fields' values stand out.
  paint() {
    const on = this.active;
    const value = on ? this.open.node.params?.[this.open.param] : '';
    for (const [ref, m] of this.markers) {
      const chosen = ref === value || this.shown.has(ref);
      m.group.visible = on || this.shown.has(ref);
      m.dot.material.color.setHex(ref === this.hovered ? HOVER : chosen ? CHOSEN : MARK);
      m.dot.scale.setScalar(ref === this.hovered || chosen ? 1.8 : 1);
    }
    this.view.render();
  }
  close() {
    this.open = null;
    this.hovered = '';
    this.list?.remove();
    this.list = null;
    this.paint();
  }
  /// The form was drawn for the node at `pointer`: a list open for another node is closed.
  formFor(pointer) {
    if (this.open && this.open.pointer !== pointer) this.close();
    const had = this.shown.size;
    this.shown = new Set();
    if (had) this.paint();
  }

  /// The picker of a feature_ref field: a button that opens the list (and the markers) under it. Typing
  /// in the field still works; a typed value other than the bound feature drops the binding.
  field(node, pointer, param, input) {
    input.addEventListener('input', () => {
      if (node.bindings?.[param] && node.bindings[param].feature !== input.value) delete node.bindings[param];
    }, { capture: true });
    const value = node.params?.[param];
    if (this.markers.has(value)) {
      this.shown.add(value);
      this.paint();
    }
    return this.box(node, pointer, param);
  }
  box(node, pointer, param) {
    const isOpen = this.open && this.open.pointer === pointer && this.open.param === param;
    const id = `planner-features-${param}`;
    const box = el('div', { class: 'binding' }, el('button', { id: `planner-pick-${param}`, 'aria-expanded': String(Boolean(isOpen)), 'aria-controls': id,
      onclick: () => {
        const other = !isOpen && this.open && this.openBox?.isConnected ? this.open : null;
        this.close();
        if (other) this.openBox.replaceWith(this.box(other.node, other.pointer, other.param));  // one list at a time
        if (!isOpen) {
          this.view.hover(null);  // a face highlighted before the list opened is not what a click picks now
          this.open = { pointer, param, node };
        }
        box.replaceWith(this.box(node, pointer, param));
        this.paint();
      } }, isOpen ? 'Close the features' : 'Pick a feature…'));
    const b = node.bindings?.[param];
    if (b?.rule === 'feature') {
      box.append(el('p', { class: 'muted small', 'data-feature-binding': param },
        `Bound to the world model's ${b.feature} (${b.label || b.kind}): origin ${b.pose.position_m.map((v) => v.toFixed(4)).join(', ')} m, `
        + `rpy ${b.pose.rpy_deg.map((v) => v.toFixed(2)).join(', ')}° in frame ${b.pose.frame}`));
    }
    if (!isOpen) return box;
    this.openBox = box;
    this.list?.remove();
    const value = node.params?.[param];
    const byEntity = [...new Set(this.features.map((f) => f.entity))];
    this.list = el('div', { id, class: 'feature-picker', role: 'group', 'aria-label': `Features of the parts for ${param}` },
      el('p', { class: 'muted small' }, this.features.length ? 'Click a feature, here or its axes in the 3D view:' : `No features: ${this.problem || 'the world model lists none for the parts'}`),
      ...byEntity.map((entity) => el('div', {}, el('h3', { class: 'small' }, entity),
        el('ul', { class: 'picks' }, ...this.features.filter((f) => f.entity === entity).map((f) => el('li', {},
          el('button', { class: 'link-button', 'data-feature': f.ref, 'aria-pressed': String(f.ref === value),
            onmouseenter: () => this.setHovered(f.ref), onmouseleave: () => this.setHovered(''),
            onfocus: () => this.setHovered(f.ref), onblur: () => this.setHovered(''),
            onclick: () => this.choose(f) }, f.id),
          ` ${f.label}, at ${f.pose.position_m.map(mm).join(', ')} mm`))))));
    box.append(this.list);
    return box;
  }

  /// The binding of a chosen feature, as kept in the recipe.
  static binding(f) {
    const pose = { position_m: f.pose.position_m.map((v) => tidy(v, 1e9)), rpy_deg: (f.pose.rpy_deg || [0, 0, 0]).map((v) => tidy(v, 1e6)) };
    return { rule: 'feature', feature: f.ref, kind: f.kind, label: f.label, pose: { ...pose, frame: f.entity } };
  }

  /// An opened recipe's feature binding against the world model now: '' or why it is stale.
  static async check(binding) {
    const entity = binding.feature.split('/')[0];
    try {
      return staleFeature(binding, namedFeatures(entity, await api(`/api/world/entity/${encodeURIComponent(entity)}`)));
    } catch (e) {
      return `stale binding: ${e.message}; pick again`;
    }
  }
}
