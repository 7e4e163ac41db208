// The target part in 3D for a screw prompt: the CAD service's tessellation (GLB) when a CAD service
// answers, else a box of the world model's model size. The holes, their numbers and the highlight come
// from the world model's screw-hole features (poses in the target's frame) and the prompt's hole id,
// so the highlight is right with either geometry. Renders on demand (no animation loop).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { api } from './api.js';

const GREEN = 0x19c15a, GREY = 0x9aa5b1, PART = 0x5d7391;

function label(text, color) {
  const c = document.createElement('canvas');
  c.width = 128; c.height = 128;
  const g = c.getContext('2d');
  g.fillStyle = color; g.beginPath(); g.arc(64, 64, 56, 0, 2 * Math.PI); g.fill();
  g.fillStyle = '#ffffff'; g.font = 'bold 72px sans-serif'; g.textAlign = 'center'; g.textBaseline = 'middle';
  g.fillText(text, 64, 68);
  const s = new THREE.Sprite(new THREE.SpriteMaterial({ map: new THREE.CanvasTexture(c), depthTest: false }));
  s.scale.set(0.06, 0.06, 1);
  s.renderOrder = 10;
  return s;
}

function holePosition(h) {
  const p = h.pose?.position_m || h.position_m || [0, 0, 0];
  return new THREE.Vector3(p[0], p[1], p[2]);
}

export class TargetView {
  constructor(container) {
    this.container = container;
    this.state = { source: 'none', holes: [], highlighted: '', error: '' };
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    container.append(this.renderer.domElement);
    this.renderer.domElement.setAttribute('aria-hidden', 'true');
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x0f1720);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 50);
    this.camera.up.set(0, 0, 1);  // the cell's world: z up
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x334455, 2.0));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(1, -1.5, 2);
    this.scene.add(sun);
    this.part = new THREE.Group();
    this.scene.add(this.part);
    this.marks = new THREE.Group();
    this.scene.add(this.marks);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  resize() {
    const w = this.container.clientWidth || 600, h = this.container.clientHeight || 450;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }
  /// Renders; for tests, state.camera holds the view-projection (column-major) and the canvas's CSS size.
  render() {
    this.renderer.render(this.scene, this.camera);
    const vp = new THREE.Matrix4().multiplyMatrices(this.camera.projectionMatrix, this.camera.matrixWorldInverse);
    const c = this.renderer.domElement;
    this.state.camera = { view_projection: vp.elements.slice(), width: c.clientWidth, height: c.clientHeight };
  }

  /// Loads the part `entity` (e.g. "target"): its holes from the world model, its geometry from CAD or a box.
  async load(entity = 'target') {
    this.entity = await api(`/api/world/entity/${encodeURIComponent(entity)}`);
    this.holes = this.entity.features?.screw_holes || [];
    this.state.holes = this.holes.map((h) => h.id);
    this.part.clear();
    try {
      const res = await api(`/api/cad/model.glb?model=${encodeURIComponent('object:' + entity)}`, { raw: true });
      const gltf = await new GLTFLoader().parseAsync(await res.arrayBuffer(), '');
      this.part.add(gltf.scene);
      this.state.source = 'cad';
    } catch (e) {
      const size = this.entity.model?.size_m || [0.5, 0.4, 0.5];
      const box = new THREE.Mesh(new THREE.BoxGeometry(size[0], size[1], size[2]),
        new THREE.MeshStandardMaterial({ color: PART, roughness: 0.7, metalness: 0.2 }));
      // The world model's frame of a box is the centre of its top face.
      const top = (this.entity.model?.frame || '').includes('top');
      box.position.z = top ? -size[2] / 2 : 0;
      this.part.add(box);
      const edges = new THREE.LineSegments(new THREE.EdgesGeometry(box.geometry), new THREE.LineBasicMaterial({ color: 0xc8d3df }));
      edges.position.copy(box.position);
      this.part.add(edges);
      this.state.source = 'box';
      this.state.cad_error = e.message;
    }
    this.highlight(this.state.highlighted);
  }

  /// Marks every hole with its number; `holeId` green, ringed and framed, and the camera on it.
  highlight(holeId) {
    this.state.highlighted = '';
    this.marks.clear();
    if (!this.holes) return;
    let target = null;
    this.holes.forEach((h, i) => {
      const p = holePosition(h);
      const on = h.id === holeId;
      const color = on ? GREEN : GREY;
      const pin = new THREE.Mesh(new THREE.CylinderGeometry(0.012, 0.012, 0.004, 24), new THREE.MeshBasicMaterial({ color }));
      pin.rotation.x = Math.PI / 2;
      pin.position.copy(p).add(new THREE.Vector3(0, 0, 0.002));
      this.marks.add(pin);
      const num = label(String(i + 1), on ? '#128a3e' : '#4a5360');
      num.position.copy(p).add(new THREE.Vector3(0, 0, 0.05));
      this.marks.add(num);
      if (on) {
        const ring = new THREE.Mesh(new THREE.TorusGeometry(0.03, 0.005, 12, 48), new THREE.MeshBasicMaterial({ color }));
        ring.position.copy(p).add(new THREE.Vector3(0, 0, 0.004));
        this.marks.add(ring);
        const s = 0.05;
        const frame = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints([
          new THREE.Vector3(-s, -s, 0), new THREE.Vector3(s, -s, 0), new THREE.Vector3(s, s, 0), new THREE.Vector3(-s, s, 0)]),
        new THREE.LineBasicMaterial({ color }));
        frame.position.copy(p).add(new THREE.Vector3(0, 0, 0.005));
        this.marks.add(frame);
        target = p;
        this.state.highlighted = h.id;
        this.state.number = i + 1;
        this.state.hole_m = [p.x, p.y, p.z];
      }
    });
    const look = target || new THREE.Vector3(0, 0, 0);
    const dist = target ? 0.8 : 1.4;
    this.camera.position.copy(look).add(new THREE.Vector3(0.35 * dist, -0.8 * dist, 0.75 * dist));
    this.controls.target.copy(look);
    this.controls.update();
    this.render();
  }
}
