// The 3D cell of the Tasks and Replay pages: every object of the world model drawn as the Planner draws
// it (planner_view.js's PartsView: its STEP model through the CAD service, or its box), with the part
// list to show, hide or frame each (planner/objects.js), moved to the poses of a picture
// (cell_picture.js), and the robot's tool and the crane's hook as markers. A framed part's origin is
// marked green, drawn through whatever is in front of it. Renders on demand, a new picture at the next
// animation frame: a page in the background (no frames) spends nothing on the poses it is sent.
import * as THREE from 'three';
import { el, store } from './api.js';
import { ObjectPicker } from './planner/objects.js';
import { PartsView } from './planner_view.js';

const TOOL = 0xff9f1c, HOOK = 0xe9d34a, ORIGIN = 0x19c15a;

function marker(color, radius) {
  const m = new THREE.Mesh(new THREE.SphereGeometry(radius, 16, 12), new THREE.MeshBasicMaterial({ color }));
  m.visible = false;
  return m;
}

export class Cell3d {
  /// `box`: the element to draw in; `say(text, bad)`: the page's notice.
  constructor(box, say) {
    this.list = el('ul', { class: 'parts', 'aria-label': 'Parts of the cell' });
    const viewBox = el('div', { class: 'pview' });
    const legend = el('p', { class: 'muted' }, 'Orange: the robot\'s tool. Yellow: the crane\'s hook. Green: the framed part\'s origin.');
    box.replaceChildren(viewBox, legend, this.list);
    this.view = new PartsView(viewBox, () => {});
    this.view.renderer.domElement.setAttribute('aria-label', '3D view of the cell: its parts where the world model has them, the robot\'s tool and the crane\'s hook');
    this.say = say;
    this.objects = new ObjectPicker(this.view, say, this.list);
    this.tool = marker(TOOL, 0.04);
    this.hook = marker(HOOK, 0.06);
    this.rope = new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3(0, 0, 1.5)]),
      new THREE.LineBasicMaterial({ color: HOOK }));
    this.hook.add(this.rope);
    this.origin = marker(ORIGIN, 0.015);
    this.origin.material.depthTest = false;
    this.origin.renderOrder = 10;
    this.view.scene.add(this.tool, this.hook, this.origin);
    // For tests: the objects drawn, the picture shown, the framed part and the camera (as view3d.js).
    this.state = { loaded: false, objects: [], picture: {}, framed: '', camera: null, revision: store.revision?.cell_revision ?? null };
    const render = this.view.render.bind(this.view);
    this.view.render = () => { render(); this.noteCamera(); };
    this.list.addEventListener('click', (e) => {
      const id = e.target.closest('button[data-frame]')?.dataset.frame;
      if (id) this.frame(id);
    });
    this.picture = {};
  }

  noteCamera() {
    const { camera, renderer } = this.view;
    const vp = new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse);
    const c = renderer.domElement;
    this.state.camera = { view_projection: vp.elements.slice(), width: c.clientWidth, height: c.clientHeight };
  }

  /// Loads every object of the world model, then shows the picture it was given meanwhile. A world model
  /// that does not answer (503: starting, or its host busy) is asked again, five times in all.
  async load() {
    for (let attempt = 1; ; attempt++) {
      try {
        await this.objects.load();
        break;
      } catch (e) {
        if (attempt >= 5 || e.status !== 503) throw e;
        this.say(`The world model did not answer (${e.message}); asking again…`, true);
        await new Promise((ok) => setTimeout(ok, 2000));
      }
    }
    this.state.objects = [...this.view.parts.keys()];
    this.show(this.picture);
    this.view.frameAll();
    this.state.loaded = true;
  }

  /// A new revision of the cell: its objects drawn afresh (added, removed, other models), at the picture.
  async reload() {
    this.view.clear();
    await this.objects.load();
    this.state.objects = [...this.view.parts.keys()];
    this.state.revision = store.revision?.cell_revision ?? null;
    this.show(this.picture);
  }

  /// Moves everything to `picture` (cell_picture.js); what it does not name stays where it is.
  show(picture) {
    this.picture = picture;
    this.state.picture = picture;
    for (const [id, pose] of Object.entries(picture.objects || {})) this.view.place(id, pose);
    for (const [m, p] of [[this.tool, picture.tool], [this.hook, picture.hook]]) {
      m.visible = !!p;
      if (p) m.position.set(...p);
    }
    if (this.state.framed) this.markOrigin(this.state.framed);
    if (this.frameRequested) return;
    this.frameRequested = true;
    requestAnimationFrame(() => { this.frameRequested = false; this.view.render(); });
  }

  /// Frames the part `id` and marks its origin.
  frame(id) {
    this.state.framed = id;
    this.markOrigin(id);
    this.view.frame(id);
  }

  markOrigin(id) {
    const part = this.view.parts.get(id);
    this.origin.visible = !!part;
    if (part) this.origin.position.setFromMatrixPosition(part.group.matrixWorld);
  }

  dispose() { this.view.renderer.dispose(); }
}
